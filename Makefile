# visco-sweep: the two set-up commands are `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# one thread per process for BLAS and Numba (joblib workers inherit this)
export OMP_NUM_THREADS ?= 1
export OPENBLAS_NUM_THREADS ?= 1
export MKL_NUM_THREADS ?= 1
export NUMBA_NUM_THREADS ?= 1

.PHONY: help venv demo test test-slow bench bench-detail bench-reference tradeoff bench-convergence clean

help:
	@echo "make demo   - create .venv, install, run a small default sweep end to end"
	@echo "make test   - create/update .venv and run the test suite"
	@echo "make bench  - speed benchmarks of issue 9 (results/bench.json, ~10 min)"
	@echo "make tradeoff [QUICK=1] - accuracy vs time over a grid of numerics (results/tradeoff/)"

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml constraints.txt | $(BIN)/python
	$(BIN)/python -m pip install --quiet -c constraints.txt -e ".[plot,cluster,test]"
	@touch $(STAMP)

venv: $(STAMP)

demo: $(STAMP)
	$(BIN)/sweep run configs/demo.yaml
	$(BIN)/sweep info results/demo.h5
	$(BIN)/sweep plot results/demo.h5 --out results/demo.png
	@echo "results: results/demo.h5 (read with: python -c 'import sweep; print(sweep.load(\"results/demo.h5\"))')"
	@echo "figure:  results/demo.png"

test: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow" tests

test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -m slow tests

bench: $(STAMP)
	$(BIN)/python -m sweep.benchmarks all --out results/bench.json

tradeoff: $(STAMP)
	$(BIN)/python -m sweep.benchmarks tradeoff $(if $(filter 1,$(QUICK)),--quick) --out results/tradeoff

# converged references of the tradeoff and vs-numpy scenes (configs/references.json; slow)
bench-reference: $(STAMP)
	$(BIN)/python -m sweep.benchmarks reference

bench-detail: $(STAMP)
	$(BIN)/python -m sweep.benchmarks scene --out results/bench/scene.json
	$(BIN)/python -m sweep.benchmarks presets --out results/bench/presets.json
	$(BIN)/python -m sweep.benchmarks scheduler --out results/bench/scheduler.json
	$(BIN)/python -m sweep.benchmarks store --out results/bench/store.json

bench-convergence: $(STAMP)
	$(BIN)/python -m sweep.benchmarks convergence --mu 6 --out results/bench/convergence_mu6.json

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
