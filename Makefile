# The two set-up commands of the README:
#   make demo   create .venv, install slamtrials, run the main job (writes results/demo/)
#   make test   create .venv, install slamtrials with its test tools, run the whole test suite
#   make test-fast   the same without the tests marked slow: under 2 minutes on 2 idle cores with a warm numba
#                    cache (3,247 tests in 101 s, 2026-11-29); an unmarked test over 5 s fails (tests/conftest.py)
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.docs-installed
OUT    ?= results/demo

.PHONY: demo test test-fast bench docs clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "slamtrials needs Python >= 3.11"'
	@$(PYTHON) -m venv $(VENV) || { echo "error: '$(PYTHON) -m venv' failed; on Debian install it with: apt-get install python3-venv"; exit 1; }
	$(BIN)/pip install --quiet --disable-pip-version-check -e '.[test]'
	@touch $(STAMP)

demo: $(STAMP)
	$(BIN)/slamtrials demo --out $(OUT)

test: $(STAMP)
	$(BIN)/python -m pytest -q

test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

$(DOCS_STAMP): $(STAMP)
	$(BIN)/pip install --quiet --disable-pip-version-check -e '.[test,docs]'
	@touch $(DOCS_STAMP)

# the documentation site, built strictly (a broken link or a page left out of the nav fails): site/
docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

bench: $(STAMP)
	$(BIN)/python bench/run_all.py

clean:
	rm -rf $(VENV) results site
