# Lecture mode: a notebook as a live dashboard, the workbook as a static site, figures for slides,
# and the browser tests of both. Included from the Makefile, whose $(PY), $(VENV) and $(STAMP) it uses.
#
#   make present NB=02 [PORT=8866] [QUICK=1]   Voila on 127.0.0.1 (code hidden, widgets live)
#   make present NB=02 VIEW=explorers          only the explorers (cells tagged "explorer")
#   make site [QUICK=1]                         execute every notebook -> build/site/index.html
#   make figures [QUICK=1]                      headline figures -> build/figures/<notebook>/*.png|svg
#   make browser                                Playwright + Chromium tests of Voila and the site
#   make chromium                               install Debian's chromium if /usr/bin/chromium is missing
#
# QUICK=1 sets TUNNELKIT_QUICK=1 (small Monte-Carlo counts); without it site and figures run the
# notebooks in full mode (the papers' counts). The browser tests always use quick mode.

NB ?= 02
PORT ?=
VIEW ?= all
QUICK ?=
CHROMIUM := /usr/bin/chromium
LECTURE_QUICK = $(if $(filter-out 0,$(QUICK)),--quick)

.PHONY: present site figures browser chromium

present: install
	$(PY) tools/present.py $(NB) --view '$(VIEW)' $(if $(PORT),--port $(PORT)) $(LECTURE_QUICK)

site: install
	$(PY) tools/site.py $(LECTURE_QUICK)

figures: install chromium
	$(PY) tools/figures.py $(LECTURE_QUICK)

browser: install chromium
	TUNNELKIT_BROWSER=1 $(PY) -m pytest -q -p no:xdist -p no:cacheprovider tests/browser

chromium:
	@if [ -x $(CHROMIUM) ]; then \
	  echo "chromium: $(CHROMIUM) is present"; \
	else \
	  echo "chromium: $(CHROMIUM) is missing; installing Debian's chromium with apt-get"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; \
	  elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then SUDO="sudo -n"; \
	  else echo "chromium: cannot install: not root and no password-less sudo." \
	            "Install it yourself: apt-get install chromium" >&2; exit 1; fi; \
	  if ! command -v apt-get >/dev/null; then \
	    echo "chromium: cannot install: apt-get not found (not Debian/Ubuntu)." \
	         "Install Chromium so that $(CHROMIUM) exists." >&2; exit 1; fi; \
	  export DEBIAN_FRONTEND=noninteractive; \
	  timeout 600 $$SUDO $(APT_LOCKED) update -qq \
	    && timeout 1200 $$SUDO $(APT_LOCKED) install -y -qq chromium >/dev/null \
	    || { echo "chromium: apt-get could not install Debian's chromium (see above)" >&2; exit 1; }; \
	  test -x $(CHROMIUM) || { echo "chromium: installed, but $(CHROMIUM) is still missing" >&2; exit 1; }; \
	  echo "chromium: installed $$($(CHROMIUM) --version 2>/dev/null)"; \
	fi
