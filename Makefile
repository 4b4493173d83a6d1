# The two commands: `make demo` (main job on the built-in default device) and `make test`.
# Each creates .venv when missing and installs the package with what it needs.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)

.PHONY: demo test bench docs browser clean

$(STAMP): pyproject.toml
	test -d $(VENV) || $(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[test]'
	touch $(STAMP)

# Headless Chromium for the report test (Debian packages chromium and chromium-driver).
APT_INSTALL = $(SUDO) apt-get update -qq && $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver
browser:
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null || \
	  ($(APT_INSTALL)) || (sleep 10 && $(APT_INSTALL))

demo: $(STAMP)
	$(BIN)/hapticdesign demo

test: $(STAMP) browser
	$(BIN)/python -m pytest -n 2

bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py

# docs/equations.md (seed equation -> code) and the API reference (docs/reference/) from docstrings.
docs: $(STAMP)
	$(BIN)/pip install -q -e '.[test,docs]'
	$(BIN)/python -m hapticdesign.interface.equation_index docs/equations.md
	$(BIN)/pdoc hapticdesign hapticdesign.model hapticdesign.devices hapticdesign.analysis hapticdesign.simulation hapticdesign.optimization hapticdesign.studies hapticdesign.interface -o docs/reference --docformat restructuredtext

clean:
	rm -rf $(VENV) build src/*.egg-info out
