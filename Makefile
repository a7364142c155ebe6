# tunnelkit — every command a newcomer needs. `make lab` and `make test` work from a fresh clone.
SHELL := /bin/bash
.SHELLFLAGS := -o pipefail -c
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-stamp
# One kernel name everywhere: the notebooks declare `python3`, which inside .venv is this venv's
# Python; `make lab` registers it in .venv with the display name the notebooks carry, so saving in
# JupyterLab writes back the same kernelspec (tools/check_notebooks.py checks it).
KERNEL := python3
KERNEL_DISPLAY := Python (tunnelkit)
# JupyterLab refuses to start as root unless told; pass --allow-root only then.
LAB_ROOT := $(if $(filter 0,$(shell id -u)),--allow-root)
export PIP_DISABLE_PIP_VERSION_CHECK := 1
# Two `make test` side by side on one machine both reach apt-get: ours wait for each other on one
# lock file (flock), and for any other apt client on dpkg's own lock, instead of failing at once.
APT_LOCK_FILE ?= /var/lock/tunnelkit-apt.lock
APT_LOCKED = flock -w 1800 $(APT_LOCK_FILE) apt-get -o DPkg::Lock::Timeout=600
# pip --quiet still relays setuptools' build warnings and a site-wide config's "is ignored" notes
PIP_FILTER := sed '/is ignored\|BuildBackendWarning\|^ *!!\|^ *\*\*\*\|^ *$$\|Please be careful\|name as your package\|take precedence during\|with strategy, WheelFile\|warnings.warn(/d'

.PHONY: help install hooks lab test lint format unit notebooks bench clean

.DEFAULT_GOAL := help
include make/lecture.mk
include make/rt.mk

help:
	@echo "make lab     create .venv if needed, install, register the kernel, open JupyterLab on notebooks/"
	@echo "             (installs the git filter that keeps notebook outputs out of commits: make hooks)"
	@echo "             QUICK=1 make lab: quick mode (small Monte-Carlo counts); PYTHON=python3.12: another Python"
	@echo "make test    the CI check: lint, unit tests, every notebook in quick mode, browser tests"
	@echo "make present NB=02   one notebook as a Voila dashboard on 127.0.0.1 (code hidden)"
	@echo "             VIEW=explorers: only its interactive explorers"
	@echo "make site    execute every notebook into a static HTML site in build/site/ (QUICK=1 for quick mode)"
	@echo "make figures headline figures as PNG and SVG in build/figures/ (QUICK=1 for quick mode)"
	@echo "make browser Playwright + Chromium tests of the dashboard and the site (part of make test)"
	@echo "make rt-deps Sionna RT extra and Debian's libllvm19, needed by notebooks 07 and 08 (part of make test)"
	@echo "make bench   benchmarks (medians and ratios measured in one run)"
	@echo "make format  ruff formatting; rebuild notebooks/*.ipynb from notebooks/.src/*.py without outputs"
	@echo "make clean   remove .venv and caches"

$(STAMP): pyproject.toml
	@test -x $(PY) || $(PYTHON) -c 'import sys; sys.exit(not (3, 11) <= sys.version_info[:2] <= (3, 13))' \
	  || { echo "tunnelkit needs Python 3.11-3.13; $(PYTHON) is $$($(PYTHON) -V 2>&1)." \
	       "Point make at another one: PYTHON=python3.12 make lab" >&2; exit 1; }
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip 2>&1 | sed '/is ignored/d'
	$(PY) -m pip install --quiet -e '.[lab,dev,lecture]' 2>&1 | $(PIP_FILTER)
	touch $(STAMP)

install: $(STAMP)

# allow_hidden: the notebooks' sources live in notebooks/.src/ (hidden in the file browser) and
# jupytext must be allowed to write them when a notebook is saved.
lab: install hooks
	$(PY) -m ipykernel install --sys-prefix --name $(KERNEL) --display-name "$(KERNEL_DISPLAY)" >/dev/null
	@echo "JupyterLab on notebooks/ in $(if $(filter-out 0,$(QUICK)),quick mode (QUICK=1),full mode (QUICK=1 for quick mode))"
	$(if $(filter-out 0,$(QUICK)),TUNNELKIT_QUICK=1) $(VENV)/bin/jupyter lab $(LAB_ROOT) \
	  --ContentsManager.allow_hidden=True notebooks/

# The clean filter named in .gitattributes: a notebook's outputs (what JupyterLab autosaves) stay
# in the working tree and never reach a commit; `make lint` checks the notebook as committed.
hooks:
	@if git rev-parse --git-dir >/dev/null 2>&1; then \
	  git config filter.nbstrip.clean "$(abspath $(PY)) tools/check_notebooks.py --clean-filter" && \
	  echo "git filter nbstrip installed: notebooks are committed without outputs"; fi

LINTED := tunnelkit tests benchmarks tools notebooks/.src notebooks/conftest.py

lint: install
	$(VENV)/bin/ruff check $(LINTED)
	$(VENV)/bin/ruff format --check $(LINTED)
	$(PY) tools/check_notebooks.py notebooks

# --dist loadfile: whole test files to each worker, the longest first (tests/conftest.py); the
# ten slowest tests are listed at the end
unit: install rt-deps
	$(PY) -m pytest -q -n 2 --dist loadfile --no-loadscope-reorder --durations=10 tests

# tools/nbmake_cache.py keeps each passing run in build/executed/, where the browser tests' site
# build finds it: `make test` executes every notebook once
notebooks: install rt-deps
	TUNNELKIT_QUICK=1 TUNNELKIT_SOLUTIONS=1 $(PY) -m pytest -q -n 2 -p tools.nbmake_cache \
	  --nbmake --nbmake-timeout=900 notebooks

# One stage after the other: running the unit tests beside the lessons measured no faster on an
# idle machine (521-530 s against 510-538 s) and slower beside a second `make test` (1,194 /
# 1,205 s against 929 / 1,026 s): the unit tests keep both cores busy (docs/runtimes.md).
test: lint unit notebooks browser

# One BLAS thread per process in the test stages: two pytest workers (or notebook kernels) on two
# cores, each with OpenBLAS's default two threads, spin four threads on two cores. Measured beside
# other work: three unit-test files took 222 s with the default threads, 24 s with one
# (docs/runtimes.md). A value set in the environment wins.
unit notebooks browser: export OMP_NUM_THREADS ?= 1
unit notebooks browser: export OPENBLAS_NUM_THREADS ?= 1
unit notebooks browser: export MKL_NUM_THREADS ?= 1

bench: install
	$(PY) benchmarks/run.py

format: install
	$(VENV)/bin/ruff format $(LINTED)
	$(VENV)/bin/ruff check --fix $(LINTED)
	$(PY) tools/check_notebooks.py --build --strip notebooks

clean:
	rm -rf $(VENV) build .pytest_cache .ruff_cache
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
