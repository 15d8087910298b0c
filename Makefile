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

.PHONY: help venv demo test test-slow test-other-blas coverage-kernels bench bench-detail bench-reference bench-accurate held-tip \
        tradeoff bench-convergence clean threshold vr fig3 figures report reproduce pdms pdms-bem pdms-protocol \
        agreement agreement-high-mu extremes tip-convergence elastic-table calibrate-demo \
        model-errors error-coverage extrapolation crack-speed random-sample docs-check docs

help:
	@echo "make demo   - create .venv, install, run a small default sweep end to end"
	@echo "make test   - create/update .venv and run the test suite"
	@echo "make test-slow - the tests marked slow (long campaigns' checks, not in make test)"
	@echo "make test-other-blas [CORETYPE=Sandybridge] - the suite as another processor runs it:"
	@echo "               another OpenBLAS kernel set, an empty disk cache (no test may depend on it)"
	@echo "make docs   - build the site into docs/_build/html (warnings are errors; runs the gallery)"
	@echo "make docs-check [QUICK=1] - run every command and snippet of README.md and docs/"
	@echo "               (QUICK=1: the quick form that make test runs, tests/test_docs_run.py)"
	@echo "make bench  - speed benchmarks of issues 9 and 24 (results/bench.json, ~5 min)"
	@echo "make bench-detail - the scene, presets and scheduler benchmarks apart (results/bench/)"
	@echo "make bench-reference - converged references of the tradeoff and vs-numpy scenes (configs/references.json, ~3 min)"
	@echo "make held-tip - accuracy requests where the nodes may hold the crack tip, relaxed starts and protocols (results/error_coverage/held_tip.json, ~5 min)"
	@echo "make bench-accurate - the engine against the plain numpy solver at the accurate preset (results/bench/vs_numpy_accurate.json, ~10 min)"
	@echo "make bench-convergence - the BEM's pull-off against the node count at mu = 6 (results/bench/)"
	@echo "make tradeoff [QUICK=1] - accuracy vs time over a grid of numerics (results/tradeoff/)"
	@echo "make coverage-kernels - kernel tests with NUMBA_DISABLE_JIT=1 under coverage"
	@echo "make reproduce - the paper's campaigns, fits, figures and results/REPORT.md"
	@echo "               (make threshold | vr | fig3 | figures | report; QUICK=1: thinned grids)"
	@echo "make pdms   - PDMS pull-off vs unloading speed (results/pdms/; uses results/pdms/bem.json)"
	@echo "make pdms-bem - the PDMS's linear BEM pull-off curve (results/pdms/bem.json, ~30 min), then make pdms"
	@echo "make pdms-protocol - the PDMS as run (approach, 60 s dwell, retraction) vs relaxed (results/pdms/protocol.json, ~3 min), then make pdms"
	@echo "make agreement - BEM vs crack-front model vs PB estimate (results/agreement/)"
	@echo "make agreement-high-mu - its mu = 15 point (about 35 min), merged by make agreement"
	@echo "make extremes [QUICK=1] [MODEL='bem auto'] - stability at the extremes of (n, k, rate, a0, mu)"
	@echo "               (results/extremes/: ok / physically refused / failed / wrong per model)"
	@echo "make tip-convergence - tip-following BEM: pull-off vs spacing and window, mu = 30, 100 (k = 0.5) and 30 (k = 0.1, rate 10^2.5)"
	@echo "make elastic-table - elastic pull-off vs mu (0.01 ... 100), quasi-static branch"
	@echo "make calibrate-demo - fit a synthetic PDMS-like pull-off curve (results/calibrate/)"
	@echo "make calibrate-pz-demo - fit a process zone to synthetic PDMS data, bulk from DMA (results/calibrate/pdms-pz/, ~1 min)"
	@echo "make model-errors - crack-front model and PB estimate vs the BEM over mu (the table auto reads)"
	@echo "make pz-check - the BEM's process zone vs the crack-front model, and its cost (results/process_zone/)"
	@echo "make protocol-cost - a protocol scene's wall time against its relaxed start (results/protocol/)"
	@echo "make hysteresis-coverage - a protocol's hysteresis_error against a finer run (results/protocol/, ~5 min)"
	@echo "make pz-map - the process zone's map from crack speed to opening rate (the table the BEM reads, ~1 min)"
	@echo "make random-sample - 60 random scenes across the declared ranges, auto and bem, 80 with a test protocol, 40 with a protocol and a process zone, 40 with a protocol at mu 6-30 (results/random/)"
	@echo "make error-coverage [QUICK=1] - does error_estimate cover the true error? per preset (results/error_coverage/)"
	@echo "make extrapolation - the estimate's pair as a Richardson pair and the crossing check, on two samples' references (~1 min)"
	@echo "make crack-speed [QUICK=1] - the crack speed at pull-off per preset against a fine reference, per fit window (results/crack_speed/, ~6 min)"

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml constraints.txt | $(BIN)/python
	$(BIN)/python -m pip install --quiet -c constraints.txt -e ".[plot,cluster,test]"
	@touch $(STAMP)

# the site's own packages (the docs extra), only for `make docs`: `make test` never waits for them
DOCS_STAMP := $(VENV)/.installed-docs
$(DOCS_STAMP): pyproject.toml constraints.txt | $(STAMP)
	$(BIN)/python -m pip install --quiet -c constraints.txt -e ".[plot,cluster,test,docs]"
	@touch $(DOCS_STAMP)

venv: $(STAMP)

demo: $(STAMP)
	$(BIN)/sweep run configs/demo.yaml
	$(BIN)/sweep info results/demo.h5
	$(BIN)/sweep plot results/demo.h5 --out results/demo.png
	@echo "results: results/demo.h5 (read with: .venv/bin/python -c 'import sweep; print(sweep.load(\"results/demo.h5\"))')"
	@echo "figure:  results/demo.png"
	@echo "the sweep command is in .venv/bin, not on PATH: run .venv/bin/sweep --help, or"
	@echo "         source .venv/bin/activate   (then: sweep --help; python -c 'import sweep')"

test: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow" tests

test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -m slow tests

# the suite as another processor runs it: OpenBLAS's kernels of another processor (their
# last bits differ: a Prony fit, a relaxed start's branch) and an empty disk cache, so that
# the cached Prony series are fitted again with them. Session 37 found with it two tests that
# passed or failed with the machine (CHANGELOG); the processors' names: OpenBLAS's
# OPENBLAS_CORETYPE (Haswell, Sandybridge, Nehalem, Prescott; SkylakeX where AVX-512 is)
CORETYPE ?= Sandybridge
test-other-blas: $(STAMP)
	@cache=$$(mktemp -d); \
	OPENBLAS_CORETYPE=$(CORETYPE) SWEEP_CACHE_DIR=$$cache $(BIN)/python -m pytest -q -m "not slow" tests; \
	rc=$$?; rm -rf $$cache; exit $$rc

# issue 34: the documentation site (docs/conf.py): the Markdown pages of docs/, the API
# reference from the docstrings, the CLI reference from the click commands and the gallery
# of docs/examples/, each example executed (sphinx-gallery skips one unchanged since the last
# build). -W: a warning fails the build (Sphinx reports them all, then exits 1); -E: every
# page is read again, so a warning is never hidden by an earlier build. Offline: no
# intersphinx, no link check. .ci/run runs it after make test.
docs: $(DOCS_STAMP)
	$(BIN)/python -m sphinx -W -E -b html docs docs/_build/html
	@echo "site: docs/_build/html/index.html"

# issue 25: every shell command and Python snippet of README.md and docs/*.md runs
# (tests/docs_check.py: what runs as written, what maps to a quick equivalent and why, the
# blocks marked <!-- docs-check: skip (why) -->). QUICK=1 is the form `make test` runs
# (tests/test_docs_run.py: about 70 s of make test's 332 s, one run, 2026-11-25); the full
# form runs the campaigns the docs name (README.md: 701 s in one run, 2026-11-25, load 5).
docs-check: $(STAMP)
	$(BIN)/python tests/docs_check.py $(if $(filter 1,$(QUICK)),--quick)

# The kernels run as plain Python (NUMBA_DISABLE_JIT=1) so that coverage sees their lines:
# the kernel-by-kernel tests and the engine against tests/naive.py on small meshes (~30 s).
KERNEL_TESTS := tests/kernels/test_history.py tests/engine/test_fast_vs_naive.py tests/kernels/test_influence.py
coverage-kernels: $(STAMP)
	NUMBA_DISABLE_JIT=1 $(BIN)/python -m pytest -q -p no:cacheprovider --cov=kernels \
	  --cov-report=term-missing $(KERNEL_TESTS) -k "not uniform_pressure and not hertz"

bench: $(STAMP)
	$(BIN)/python -m sweep.bench.benchmarks all --out results/bench.json

tradeoff: $(STAMP)
	$(BIN)/python -m sweep.bench.benchmarks tradeoff $(if $(filter 1,$(QUICK)),--quick) --out results/tradeoff

# converged references of the tradeoff and vs-numpy scenes (configs/references.json; slow)
bench-reference: $(STAMP)
	$(BIN)/python -m sweep.bench.benchmarks reference

bench-accurate: $(STAMP)
	$(BIN)/python -m sweep.bench.benchmarks vs-numpy-accurate --out results/bench/vs_numpy_accurate.json

bench-detail: $(STAMP)
	$(BIN)/python -m sweep.bench.benchmarks scene --out results/bench/scene.json
	$(BIN)/python -m sweep.bench.benchmarks presets --out results/bench/presets.json
	$(BIN)/python -m sweep.bench.benchmarks scheduler --out results/bench/scheduler.json
	$(BIN)/python -m sweep.bench.benchmarks store --out results/bench/store.json

# issue 10: the whole Tabor range. Stability at the extremes of (n, k, rate, a0, mu) (144
# scenes per model, MODEL="bem auto" by default, into results/extremes/; QUICK=1 the covering
# subset, into results/quick/extremes/), the tip-following mesh's convergence at mu = 30 and
# 100, the elastic pull-off against mu (quasi-static branch)
extremes: $(STAMP)
	$(BIN)/python -m sweep.bench.extremes $(if $(filter 1,$(QUICK)),--quick) $(if $(MODEL),--model $(MODEL))

tip-convergence: $(STAMP)
	$(BIN)/python -m sweep.engine.tip_following --mu 30 100
	$(BIN)/python -m sweep.engine.tip_following --mu 30 --k 0.1 --a0 3 --rate 316.227766

elastic-table: $(STAMP)
	$(BIN)/python -m sweep.engine.quasistatic

bench-convergence: $(STAMP)
	$(BIN)/python -m sweep.bench.benchmarks convergence --mu 6 --out results/bench/convergence_mu6.json

# -- reproduction of the paper (results/REPORT.md) ----------------------------------------
# Each campaign target runs (or resumes) its sweep, then writes fit.json/figures with
# `python -m sweep.paper.reproduce`, and records its own wall time in <dir>/make_wall_s.txt.
# QUICK=1 runs the thinned grids of configs/quick/ into results/quick/ (a smoke run, never
# the committed report).
ifeq ($(QUICK),1)
CFG := configs/quick
OUT := results/quick
else
CFG := configs
OUT := results
endif
REPRO := $(BIN)/sweep reproduce
# worker processes of the campaigns (default: the scheduler's; JOBS=1 on a shared machine)
JOBS ?=
# run a sweep and its analysis, timing the whole: $(call campaign,config,dir,reproduce-cmd)
define campaign
	@mkdir -p $(OUT)/$(2)
	@start=$$(date +%s); \
	$(BIN)/sweep run $(CFG)/$(1).yaml --out $(OUT)/$(2)/runs.h5 --progress none $(if $(JOBS),-j $(JOBS)) && \
	$(REPRO) $(3) $(OUT)/$(2)/runs.h5 $(OUT)/$(2) && \
	echo "$$(( $$(date +%s) - start )) s: make $@ $(if $(QUICK),QUICK=$(QUICK)) $(if $(JOBS),JOBS=$(JOBS))" > $(OUT)/$(2)/make_wall_s.txt && \
	cat $(OUT)/$(2)/make_wall_s.txt
endef

threshold: $(STAMP)
	$(call campaign,threshold,threshold,threshold)

vr: $(STAMP)
	$(call campaign,v_vs_r,vr,vr)

fig3: $(STAMP)
	$(call campaign,fig3,fig3,fig3)

figures: fig3 $(STAMP)
	$(call campaign,aconv,aconv,aconv)
	@test -f $(OUT)/vr/runs.h5 || $(MAKE) --no-print-directory vr
	$(REPRO) theory $(OUT)/theory --vr $(OUT)/vr/runs.h5

report: $(STAMP)
	$(REPRO) report --results $(OUT)

reproduce: threshold vr figures
	@$(MAKE) --no-print-directory report

pdms: $(STAMP)
	$(BIN)/python -m sweep.paper.pdms --out results/pdms

# the linear BEM pull-off curve of the PDMS (results/pdms/bem.json, resumed; one core, about
# 30 min on a loaded 2-core machine), then the PDMS report with it
pdms-bem: $(STAMP)
	$(BIN)/python -m sweep.paper.pdms --out results/pdms --bem

# the experiment as run against the relaxed start, by the BEM at mu 3-8 (results/pdms/
# protocol.json, resumed; a few minutes), then the PDMS report with it
pdms-protocol: $(STAMP)
	$(BIN)/python -m sweep.paper.pdms_protocol --out results/pdms
	$(BIN)/python -m sweep.paper.pdms --out results/pdms

agreement: $(STAMP)
	$(BIN)/python -m sweep.bench.agreement --out results/agreement/agreement.json

# the costly high-mu point of the agreement (about 35 min on a loaded 2-core machine); make
# agreement merges its rows into results/agreement/agreement.md
agreement-high-mu: $(STAMP)
	$(BIN)/python -m sweep.bench.agreement --mus 15 --no-a0-scan --out results/agreement/agreement_mu15.json

# issue 23: `sweep calibrate` on synthetic PDMS-like data with a known answer; the CSV was
# written by the command in the header of configs/calibrate/pdms-lens.yaml
calibrate-demo: $(STAMP)
	$(BIN)/sweep calibrate configs/calibrate/pdms-lens.yaml --out results/calibrate

# issue 35 item 5: the process zone's pz_v0, pz_xi (and dg) fitted with the PDMS bulk fixed;
# the CSV was written by the command in the header of configs/calibrate/pdms-pz.yaml
# issue 35: the map from the process zone's crack speed to its opening rate, written into the
# package (sweep/engine/process_zone_map.json) for the BEM's rate-dependent interface law
.PHONY: pz-map
pz-map: $(STAMP)
	$(BIN)/python -m sweep.bench.process_zone_map

# issue 35: the BEM's process zone against the crack-front model, and its cost
.PHONY: pz-check
pz-check: $(STAMP)
	$(BIN)/python -m sweep.bench.process_zone_check

# issue 36: what the test as run costs against its relaxed start
.PHONY: protocol-cost
protocol-cost: $(STAMP)
	$(BIN)/python -m sweep.bench.protocol_cost

# a test protocol's hysteresis_error against a finer run (results/protocol/hysteresis_coverage.json)
.PHONY: hysteresis-coverage
hysteresis-coverage: $(STAMP)
	$(BIN)/python -m sweep.bench.hysteresis_coverage

.PHONY: calibrate-pz-demo
calibrate-pz-demo: $(STAMP)
	$(BIN)/sweep calibrate configs/calibrate/pdms-pz.yaml --out results/calibrate/pdms-pz

# issue 21: the crack-front model's and the PB estimate's error against the BEM at each mu,
# written into the package (sweep/engine/model_errors.json) for the model chooser
model-errors: $(STAMP)
	$(BIN)/python -m sweep.bench.model_errors

# issue 21: coverage and looseness of the per-row error estimate against a much finer run,
# per preset, on a seeded random sample (QUICK=1: 6 scenes)
# then the accuracy asked for (Numerics.for_tolerance) at three tolerances on the same scenes
# against the same references (issue 33 item 6)
# the error estimate's pair as an extrapolation pair, on the scenes and references of
# results/error_coverage/coverage.json (issue 33 item 2)
# and on a second sample (seed 11), whose references are made once (about 25 min on 2 cores)
SEED11 := results/error_coverage/references_seed11.json
extrapolation: $(STAMP)
	$(BIN)/python -m sweep.bench.extrapolation
	test -f $(SEED11) || $(BIN)/python -m sweep.bench.extrapolation --references 40 --seed 11 --coverage $(SEED11)
	$(BIN)/python -m sweep.bench.extrapolation --coverage $(SEED11) --out results/error_coverage/extrapolation_seed11.json

# requests where the nodes may hold the crack tip (relaxed starts and protocols; ~5 min)
held-tip: $(STAMP)
	$(BIN)/python -m sweep.bench.held_tip --out results/error_coverage/held_tip.json

error-coverage: $(STAMP)
	$(BIN)/python -m sweep.bench.error_coverage $(if $(filter 1,$(QUICK)),--scenes 6 --out results/quick/error_coverage)
	$(BIN)/python -m sweep.bench.error_coverage --tolerance 3e-2 --tolerance 1e-2 --tolerance 1e-3 $(if $(filter 1,$(QUICK)),--out results/quick/error_coverage)

# the crack speed's accuracy and its fit's window (sweep/bench/crack_speed.py)
crack-speed: $(STAMP)
	$(BIN)/python -m sweep.bench.crack_speed $(if $(filter 1,$(QUICK)),--quick --out results/quick/crack_speed)

# issue 21: a random sample across the declared ranges through `sweep run`, model auto and the
# default bem (configs/random/, written by `python -m sweep.bench.random_sample configs`),
# 24 process-zone scenes on the BEM (configs/random/process_zone.yaml, issue 35), 80 scenes
# with a test protocol, 40 with a protocol and a process zone and 40 with a protocol at mu 6-30
# (on the tip-following mesh) (configs/random/protocol*.yaml, issue 36);
# the summary counts ok / physically refused / failed / internal errors and draws the map
random-sample: $(STAMP)
	-$(BIN)/sweep run configs/random/auto.yaml -j 2
	-$(BIN)/sweep run configs/random/bem.yaml -j 2
	-$(BIN)/sweep run configs/random/process_zone.yaml -j 2
	-$(BIN)/sweep run configs/random/protocol.yaml -j 2
	-$(BIN)/sweep run configs/random/protocol_pz.yaml -j 2
	-$(BIN)/sweep run configs/random/protocol_tabor.yaml -j 2
	$(BIN)/python -m sweep.bench.random_sample summary

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .coverage
