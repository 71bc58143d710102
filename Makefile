# hhscatter — `make help` lists the targets.
SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-stamp
RUNS := runs
WORKERS ?=
W := $(if $(WORKERS),--workers $(WORKERS),)

help: ## list the targets
	@awk 'BEGIN {FS = ":.*## "} /^[a-zA-Z0-9_.\/-]+:.*## / {printf "  \033[36m%-16s\033[0m %s\n", $$1, $$2}' $(MAKEFILE_LIST)

$(STAMP): pyproject.toml
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	@touch $@

venv: $(STAMP) ## create .venv and install hhscatter with its dev extra

test: $(STAMP) ## run the default test suite (creates .venv if missing)
	$(PY) -m pytest -q

test-slow: $(STAMP) ## run the slow accuracy/stress cases too
	$(PY) -m pytest -q -m "slow or not slow"

# -- demo: two real scenes end to end -----------------------------------------
$(RUNS)/demo/conservative/.done: studies/demo/conservative.toml $(STAMP)
	$(VENV)/bin/hhscatter simulate $< --out $(@D) --overwrite $(W)
	@touch $@

$(RUNS)/demo/dissipative/.done: studies/demo/dissipative.toml $(STAMP)
	$(VENV)/bin/hhscatter simulate $< --out $(@D) --overwrite $(W)
	@touch $@

$(RUNS)/demo/survival.png: $(RUNS)/demo/conservative/.done $(RUNS)/demo/dissipative/.done
	$(VENV)/bin/hhscatter survival $(RUNS)/demo/conservative $(RUNS)/demo/dissipative --png $@ \
	  --labels "E=0.27, γ=0" "E0=0.3, γ=0.01"

demo: $(RUNS)/demo/survival.png ## run two small real scenes (1e5 orbits each), write Parquet + P(t) PNG

bench-engine: $(STAMP) ## µs per orbit of the engine (1 and all workers), time inside heyoka
	$(PY) -m hhscatter.bench_engine $(BENCH_ARGS)

clean-runs: ## delete simulation outputs under runs/
	rm -rf $(RUNS)

.PHONY: help venv test test-slow demo bench-engine clean-runs
