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

.PHONY: help venv demo test test-slow coverage-kernels bench bench-convergence pdms agreement clean

help:
	@echo "make demo   - create .venv, install, run a small default sweep end to end"
	@echo "make test   - create/update .venv and run the test suite"
	@echo "make bench  - speed benchmarks (JSON in results/bench/)"
	@echo "make coverage-kernels - kernel tests with NUMBA_DISABLE_JIT=1 under coverage"
	@echo "make pdms   - PDMS pull-off vs unloading speed (results/pdms/)"

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

# The kernels run as plain Python (NUMBA_DISABLE_JIT=1) so that coverage sees their lines:
# the kernel-by-kernel tests and the engine against tests/naive.py on small meshes (~30 s).
KERNEL_TESTS := tests/test_history.py tests/test_fast_vs_naive.py tests/test_influence.py
coverage-kernels: $(STAMP)
	NUMBA_DISABLE_JIT=1 $(BIN)/python -m pytest -q -p no:cacheprovider --cov=kernels \
	  --cov-report=term-missing $(KERNEL_TESTS) -k "not uniform_pressure and not hertz"

bench: $(STAMP)
	$(BIN)/python -m sweep.benchmarks scene --out results/bench/scene.json
	$(BIN)/python -m sweep.benchmarks presets --out results/bench/presets.json
	$(BIN)/python -m sweep.benchmarks scheduler --out results/bench/scheduler.json
	$(BIN)/python -m sweep.benchmarks store --out results/bench/store.json

bench-convergence: $(STAMP)
	$(BIN)/python -m sweep.benchmarks convergence --mu 6 --out results/bench/convergence_mu6.json

pdms: $(STAMP)
	$(BIN)/python -m sweep.pdms --out results/pdms

agreement: $(STAMP)
	$(BIN)/python -m sweep.agreement --out results/agreement/agreement.json

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .coverage
