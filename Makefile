# hhscatter — `make help` lists the targets.
SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-stamp
BENCH_STAMP := $(VENV)/.bench-stamp
DOCS_STAMP := $(VENV)/.docs-stamp
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

test: $(STAMP) $(BENCH_STAMP) $(DOCS_STAMP) chromium ## run the default test suite, then `make lint` (creates .venv with the dev, bench and docs extras)
	$(PY) -m pytest -q
	@$(MAKE) --no-print-directory lint

lint: $(DOCS_STAMP) ## ruff: lint and formatting of the whole tree (configuration in pyproject.toml [tool.ruff])
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

# the docs' browser tests (tests/docs/test_docs_browser.py) open the built site in Debian's Chromium, driven by the
# playwright package of the docs extra (never `playwright install`: its browser downloads are not used). Installed
# here when missing (as root, with apt); where it cannot be, those tests skip and say why.
CHROMIUM := /usr/bin/chromium
chromium: ## install Debian's chromium for the docs' browser tests when missing (root + apt-get)
	@test -x $(CHROMIUM) || { command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] \
	  && (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	  || echo "make chromium: could not install Debian's chromium (needs root and apt-get): the browser tests of the docs will be skipped"; }

test-slow: $(STAMP) $(BENCH_STAMP) $(DOCS_STAMP) ## run the slow accuracy/stress cases too
	$(PY) -m pytest -q -m "slow or not slow"

# the floors of pyproject.toml, tested: every dependency (core, dev, bench) at the lowest version allowed
MIN_VENV := .venv-min
test-min: ## run the test suite against the lowest dependency versions pyproject.toml allows (in .venv-min)
	@test -x $(MIN_VENV)/bin/python || $(PYTHON) -m venv $(MIN_VENV)
	$(MIN_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(PYTHON) tools/min_requirements.py dev bench > $(MIN_VENV)/constraints.txt
	$(MIN_VENV)/bin/python -m pip install --quiet -c $(MIN_VENV)/constraints.txt -e '.[dev,bench,docs]'
	$(MIN_VENV)/bin/python -m pip list --format=freeze | grep -iE '^(numpy|scipy|pandas|pyarrow|matplotlib|heyoka|duckdb|polars)=='
	$(MIN_VENV)/bin/python -m pytest -q -p no:cacheprovider

# -- demo: two real scenes end to end -----------------------------------------
$(RUNS)/demo/conservative/.done: examples/conservative.toml $(STAMP)
	$(VENV)/bin/hhscatter simulate $< --out $(@D) --overwrite $(W)
	@touch $@

$(RUNS)/demo/dissipative/.done: examples/dissipative.toml $(STAMP)
	$(VENV)/bin/hhscatter simulate $< --out $(@D) --overwrite $(W)
	@touch $@

$(RUNS)/demo/survival.png: $(RUNS)/demo/conservative/.done $(RUNS)/demo/dissipative/.done
	$(VENV)/bin/hhscatter survival $(RUNS)/demo/conservative $(RUNS)/demo/dissipative --png $@ \
	  --labels "E=0.27, γ=0" "E0=0.3, γ=0.01"

demo: $(RUNS)/demo/survival.png ## run two small real scenes (1e5 orbits each), write Parquet + P(t) PNG

# -- studies: raw runs → derived tables + <name>.json → <name>.png ------------
# `make fig2` (quick scale, minutes on 2 cores) or `make fig2 SCALE=paper` (the paper's N).
# The studies and their dependencies are the folders studies/<name>/ (study.toml: [about], [needs]);
# hhscatter/studies/graph.py turns them into the rules below (build/studies.mk), nothing lists them here.
SCALE ?= quick
HH := $(VENV)/bin/hhscatter
# the library code an analysis or a plot runs, subpackages included (an edit there makes the outputs out of date)
ANALYSIS_SRC := $(shell find hhscatter/analysis hhscatter/reproduction hhscatter/data hhscatter/model hhscatter/scene hhscatter/studies -name '*.py')
PLOT_SRC := $(shell find hhscatter/publish -name '*.py')
so = studies/$(1)/out/$(SCALE)
study_code = $(wildcard studies/$(1)/*.py)
CONVENTIONS := $(wildcard studies/conventions.toml)  # scene keys the figure studies share (convention = "paper")

# $(1): study name; $(2): the studies it needs (their numbers JSON are inputs of its analysis)
define study_rules
$(call so,$(1))/raw/done.json: studies/$(1)/study.toml $(CONVENTIONS) $(call study_code,$(1)) $(STAMP)
	$(HH) study $(1) simulate --scale $(SCALE) $(W)
$(call so,$(1))/$(1).json: $(call so,$(1))/raw/done.json $(ANALYSIS_SRC) $(call study_code,$(1)) $(foreach u,$(2),$(call so,$(u))/$(u).json)
	$(HH) study $(1) analyze --scale $(SCALE)
$(call so,$(1))/$(1).png: $(call so,$(1))/$(1).json $(call study_code,$(1)) $(PLOT_SRC)
	$(HH) study $(1) plot --scale $(SCALE)
endef

STUDIES_MK := build/studies.mk
STUDY_TOMLS := $(sort $(wildcard studies/*/study.toml))
$(STUDIES_MK): $(STUDY_TOMLS) hhscatter/studies/graph.py
	@mkdir -p $(@D)
	$(PYTHON) hhscatter/studies/graph.py make > $@.tmp && mv $@.tmp $@
include $(STUDIES_MK)
# a study folder added or removed: regenerate (the file records the study.toml files it was made from)
ifneq ($(STUDIES_MK_TOMLS),$(STUDY_TOMLS))
$(STUDIES_MK): FORCE
endif
FORCE:

studies: $(STUDY_NAMES) ## all studies at SCALE (default quick), each after the studies it needs

BENCH_SUMMARY := benchmarks/out/bench/full/summary.md
STRESS_SUMMARY := benchmarks/out/stress/full/summary.md
# The report reads, per study, studies/<name>/out/<SCALE>/{<name>.json,<name>.png,cost.json} where they exist, else
# the committed copies in docs/studies/assets/<SCALE>/ (hhscatter/publish/report.py), and verifies each numbers
# JSON against its study.toml and upstream numbers (so those are inputs too). A scale with committed results
# (paper: make docs-assets SCALE=paper copies them there) is built from what is there and never starts a
# simulation; quick and any other declared scale (tiny) run the studies that are missing or out of date.
COMMITTED := docs/studies/assets/$(SCALE)
either = $(or $(wildcard $(1)),$(wildcard $(2)))
BENCH_READ := $(foreach b,bench stress,$(call either,benchmarks/out/$(b)/full/summary.md,docs/benchmarks/assets/$(b)/summary.md))
ifeq ($(filter $(SCALE),$(STUDY_SCALES)),)
REPORT_INPUTS := report-unknown-scale
else ifeq ($(SCALE),quick)
REPORT_INPUTS := $(foreach s,$(STUDY_NAMES),$(call so,$(s))/$(s).png) $(BENCH_SUMMARY) $(STRESS_SUMMARY)
else ifneq ($(wildcard $(COMMITTED)/*.json),)
REPORT_INPUTS := $(foreach s,$(STUDY_NAMES),$(foreach f,$(s).json $(s).png,$(call either,$(call so,$(s))/$(f),$(COMMITTED)/$(f))) \
                   $(call either,$(call so,$(s))/cost.json,$(COMMITTED)/$(s).cost.json)) $(BENCH_READ)
else
REPORT_INPUTS := $(foreach s,$(STUDY_NAMES),$(call so,$(s))/$(s).png) $(BENCH_READ)
endif
reports/$(SCALE)/report.html: $(REPORT_INPUTS) $(STUDY_TOMLS) $(CONVENTIONS) hhscatter/publish/report.py $(STAMP)
	$(PY) -m hhscatter.publish.report --scale $(SCALE)

report-unknown-scale:
	@echo "make report: SCALE=$(SCALE) is not a scale of the studies (one of: $(STUDY_SCALES))" >&2; exit 2

report: reports/$(SCALE)/report.html ## reproduction report (HTML + Markdown): quick runs what is missing; SCALE=paper reads the committed results

# `make report` says what it will run and roughly how long (the committed cost records) before anything starts
ifneq ($(filter report,$(MAKECMDGOALS)),)
ifneq ($(filter $(SCALE),$(STUDY_SCALES)),)
$(info $(shell $(PY) -m hhscatter.publish.report --plan --scale $(SCALE)))
endif
endif

bench-engine: $(BENCH_STAMP) ## engine targets as ratios in one run (yardstick, DOP853, recording) → benchmarks/out/engine/full/
	$(PY) -m benchmarks.engine $(ENGINE_ARGS)

bench-memory: $(STAMP) ## peak RSS of simulate + P(t) at E=0.27, N=1e5,1e6,1e7, 1 worker (1e7: ~5-10 CPU-min)
	$(PY) -m benchmarks.memory $(MEMORY_ARGS)

$(BENCH_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -e '.[bench]'
	@touch $@

bench: $(BENCH_STAMP) ## work–precision vs KahanLi8/DOP853/SciPy + throughput + engine targets + the cost of noise and the escape rate's work–precision with noise → benchmarks/out/{bench,engine,noise}/
	$(PY) -m benchmarks $(BENCH_ARGS)
	$(PY) -m benchmarks.engine -n 30000 --repeat 2
	$(PY) -m benchmarks.noise
	$(PY) -m benchmarks.noise_rate

# the report runs the benchmarks only when their summaries are missing or their code changed
$(BENCH_SUMMARY): $(wildcard benchmarks/*.py) benchmarks/bench.toml | $(BENCH_STAMP)
	$(PY) -m benchmarks
$(STRESS_SUMMARY): $(wildcard benchmarks/*.py) benchmarks/stress.toml | $(BENCH_STAMP)
	$(PY) -m benchmarks.stress

stress: $(BENCH_STAMP) ## numerical stress tests (drift, threshold, grazing events, γ extremes, KS) → benchmarks/out/stress/
	$(PY) -m benchmarks.stress $(STRESS_ARGS)

clean-runs: ## delete simulation outputs under runs/
	rm -rf $(RUNS)

# -- documentation: mkdocs --strict, offline (docs/, mkdocs.yml) ----------------
MKDOCS := NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs

$(DOCS_STAMP): $(STAMP) pyproject.toml
	$(PY) -m pip install --quiet -e '.[docs]'
	@touch $@

docs: $(DOCS_STAMP) ## build the documentation site into site/ (mkdocs --strict: warnings are errors)
	$(MKDOCS) build --strict --clean --site-dir site

docs-serve: $(DOCS_STAMP) ## serve the docs with live reload at http://127.0.0.1:8000
	$(MKDOCS) serve --strict

tutorial: $(DOCS_STAMP) ## re-execute docs/tutorial.ipynb (about 2 min on 2 cores) and store its outputs, which the docs page shows
	$(PY) tools/execute_notebook.py docs/tutorial.ipynb

docs-assets: ## copy the studies' figures/numbers/costs at SCALE (quick: with the bench summaries) into docs/
	$(PYTHON) docs/gen_studies.py --scale $(SCALE)

.PHONY: docs docs-serve docs-assets tutorial

.PHONY: help venv test lint chromium test-min test-slow demo bench-engine bench-memory bench stress clean-runs report studies \
	report-unknown-scale
