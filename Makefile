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
	$(BIN)/pip install -q -e '.[test]' > $(VENV)/pip.log 2>&1 || (cat $(VENV)/pip.log && false)
	touch $(STAMP)

# Headless Chromium for the report test (Debian packages chromium and chromium-driver); apt's
# output goes to .venv/apt.log, one line is printed.
APT_INSTALL = ($(SUDO) apt-get update -qq && $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver) >> $(VENV)/apt.log 2>&1
browser:
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null || \
	  (echo "installing Debian's chromium and chromium-driver for the browser tests (log: $(VENV)/apt.log)" && \
	   ($(APT_INSTALL) || (sleep 10 && $(APT_INSTALL)) || (echo "apt failed; see $(VENV)/apt.log" && false)))

demo: $(STAMP)
	$(BIN)/hapticdesign demo

# pytest -n 2 compiles the rendering loop once in the controller before its two workers start
# (tests/conftest.py), so that they load it from numba's cache instead of each compiling it; --dist loadgroup
# keeps the tests of the shared smoke studies on one worker (tests/studies/conftest.py).
test: $(STAMP) browser
	$(BIN)/python -m pytest -n 2 --dist loadgroup

bench: $(STAMP)
	$(BIN)/python benchmarks/run_all.py

# docs/equations.md (seed equation -> code) and the API reference (docs/reference/) from docstrings.
docs: $(STAMP)
	$(BIN)/pip install -q -e '.[test,docs]'
	$(BIN)/python -m hapticdesign.interface.equation_index docs/equations.md
	$(BIN)/pdoc hapticdesign hapticdesign.model hapticdesign.devices hapticdesign.analysis hapticdesign.simulation hapticdesign.optimization hapticdesign.studies hapticdesign.interface -o docs/reference --docformat restructuredtext

clean:
	rm -rf $(VENV) build src/*.egg-info out
