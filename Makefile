# Reproduction of classic comparator/plotter calibration papers by Monte-Carlo simulation.
# `make reproduce` and `make test` set everything up themselves (virtual environment, install).

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
SIM_SRC := $(filter-out sim/bench.py,$(shell find sim -name '*.py' 2>/dev/null))
STUDY_FILES := $(wildcard studies/*.toml)
STUDIES := $(basename $(notdir $(STUDY_FILES)))
CLAIMS := $(foreach s,$(STUDIES),results/$(s)/claims.parquet)

.DEFAULT_GOAL := help
.PHONY: help venv test reproduce rerun report bench clean

help: ## list the targets
	@grep -E '^[a-zA-Z_%/.-]+:.*## ' $(MAKEFILE_LIST) | sed -E 's/:.*## /\t/' | sort | \
	  awk -F'\t' '{printf "  %-22s %s\n", $$1, $$2}'

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[dev]"
	@touch $@

venv: $(STAMP) ## create the virtual environment and install the project

test: $(STAMP) ## run the test suite (sets up the environment first)
	$(PY) -m pytest

results/%/claims.parquet: studies/%.toml $(SIM_SRC) | $(STAMP)
	$(PY) -m sim run $< --out results/$* --overwrite

results/REPORT.md: $(CLAIMS) | $(STAMP)
	$(PY) -m sim report --results results

reproduce: results/REPORT.md ## run every study at full trial counts and rebuild results/REPORT.md

rerun: $(STAMP) ## re-run every study even if its results are up to date, then the report
	@for s in $(STUDIES); do $(PY) -m sim run studies/$$s.toml --out results/$$s --overwrite || exit 1; done
	$(PY) -m sim report --results results

report: $(STAMP) ## rebuild results/REPORT.md from the Parquet files alone
	$(PY) -m sim report --results results

results/bench/bench.parquet: sim/bench.py sim/multilateration.py | $(STAMP)
	$(PY) -m sim.bench --out results/bench

bench: $(STAMP) ## time the batched solver against a scipy loop (results/bench/)
	$(PY) -m sim.bench --out results/bench

clean: ## remove the virtual environment and caches (results/ is kept)
	rm -rf $(VENV) .pytest_cache sim.egg-info
