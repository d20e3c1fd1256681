# rmtkit — `make run` (the main job), `make test` (and `make test-slow`), `make lint`, `make bench`.  Each creates .venv when missing
# and installs the project into it, so a fresh machine needs only Python 3.11 and the package index.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)

.PHONY: run test test-slow lint bench install clean timor-venv

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e ".[test]"
	@rm -f $(VENV)/.installed-* && touch $@

install: $(STAMP)

run: $(STAMP)
	$(BIN)/rmt study

# pytest's exit code is kept in .venv/.pytest-exit for .ci/run (make itself exits 2 on failure).
# `make test` runs everything but the end-to-end tests marked slow (bundled studies, browsers,
# sweeps with worker processes, long CLI examples); `make test-slow` runs those; CI runs both.
test: $(STAMP)
	@$(BIN)/python -m pytest -q -m "not slow" -n auto --maxprocesses 4 --dist loadfile; rc=$$?; echo $$rc > $(VENV)/.pytest-exit; exit $$rc

test-slow: $(STAMP)
	@$(MAKE) --no-print-directory timor-venv || echo "timor-python did not install: tests/kin/modules/test_timor.py is skipped"
	@$(BIN)/python -m pytest -q -m slow; rc=$$?; echo $$rc > $(VENV)/.pytest-exit; exit $$rc

lint: $(STAMP)
	$(BIN)/ruff check .

bench: $(STAMP)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e ".[bench]"
	$(BIN)/python -m studies.benchmarks.bench_kin
	$(BIN)/python -m studies.benchmarks.bench_ik
	$(BIN)/python -m studies.benchmarks.bench_plan
	$(BIN)/python -m studies.benchmarks.bench_collision
	$(BIN)/python -m studies.benchmarks.bench_cell_plan
	$(BIN)/python -m studies.benchmarks.bench_mbm
	$(BIN)/python -m studies.benchmarks.bench_startup
	$(BIN)/python -m studies.benchmarks.bench_timing
	$(BIN)/python -m studies.benchmarks.bench_waypoints
	$(BIN)/python -m studies.benchmarks.bench_torque
	$(BIN)/python -m studies.benchmarks.bench_design
	$(BIN)/python -m studies.benchmarks.bench_sweep
	$(BIN)/python -m studies.benchmarks.bench_reach
	$(BIN)/python -m studies.benchmarks.bench_dynamics

# timor-python (TUM) for tests/kin/modules/test_timor.py, in a venv of its own: it pins pinocchio < 3 and
# numpy 1.x, which .venv (pinocchio 4, numpy 2) cannot hold.  The test finds .venv-timor (or the interpreter
# named by RMT_TIMOR_PYTHON) and is skipped without it; `make test-slow` (so CI) makes it first.
timor-venv:
	@test -x .venv-timor/bin/python || $(PYTHON) -m venv .venv-timor
	.venv-timor/bin/python -m pip install --quiet --disable-pip-version-check "timor-python==1.1.1"

clean:
	rm -rf $(VENV) .venv-timor out build *.egg-info
