"""Browser tests: Voila and the static site driven by Playwright through Debian's Chromium.

They are collected only when ``TUNNELKIT_BROWSER=1`` (``make browser`` sets it), so the unit run
``pytest tests`` leaves them out. Every request that is not to 127.0.0.1 is aborted; every server
runs on a free loopback port and is stopped by its process id; screenshots go to build/artifacts/.

One Chromium serves the whole session, and so do one JupyterLab (each test opens its notebook in
a workspace of its own), the static site (built once; each chapter page opened once per width,
pages.py) and the Voila dashboard of notebook 02 (one server, one page: its kernel runs the
notebook once for the tests of its explorer and of its solutions).
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

from _lecture import (  # noqa: E402
    BUILD,
    CHROMIUM,
    HOST,
    ROOT,
    alive,
    child_pids,
    free_port,
    kernel_env,
    lab_command,
    list_notebooks,
    resolve_notebook,
    serving,
    serving_on_free_port,
)

if os.environ.get("TUNNELKIT_BROWSER") != "1":
    collect_ignore_glob = ["test_*.py"]

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
ARTIFACTS = BUILD / "artifacts"
LOOPBACK = ("http://127.0.0.1:", "ws://127.0.0.1:", "data:", "blob:", "about:")


@pytest.fixture(scope="session")
def artifacts() -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    return ARTIFACTS


@pytest.fixture(scope="session")
def browser():
    if not os.access(CHROMIUM, os.X_OK):
        pytest.fail(f"{CHROMIUM} is missing: run `make chromium` (installs Debian's chromium)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_FLAGS)
        try:
            yield b
        finally:
            b.close()


class Watched:
    """A page whose off-machine requests are aborted and whose console errors are recorded."""

    def __init__(self, page) -> None:
        self.page = page
        self.blocked: list[str] = []
        self.errors: list[str] = []
        page.route("**/*", self._route)
        page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: self.errors.append(f"page error: {e}"))
        page.on("response", self._response)

    def _response(self, response) -> None:
        if response.status >= 400:
            self.errors.append(f"HTTP {response.status} for {response.url}")

    def _route(self, route) -> None:
        url = route.request.url
        if url.startswith(LOOPBACK):
            route.continue_()
        else:
            self.blocked.append(url)
            route.abort()


@contextlib.contextmanager
def watched_page(browser):
    """A Watched page in a browser context of its own (closed on exit)."""
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    try:
        yield Watched(context.new_page())
    finally:
        context.close()


@pytest.fixture
def watched(browser):
    with watched_page(browser) as w:
        yield w


@pytest.fixture(scope="session")
def lab(tmp_path_factory, artifacts):
    """One JupyterLab for the session, as a student's (quick mode, the solutions left to be asked
    for: no ``TUNNELKIT_SOLUTIONS``), serving an empty temporary directory: ``(root, URL)``."""
    root = tmp_path_factory.mktemp("lab")
    env = kernel_env(quick=True)
    env["PYTHONPATH"] = str(ROOT)
    env["JUPYTER_CONFIG_DIR"] = str(tmp_path_factory.mktemp("lab-config"))  # no user settings
    with serving_on_free_port(
        lambda port: lab_command(port, root), env=env, log=artifacts / "lab.log", timeout=180
    ) as (_, url):
        yield root, url


#: the notebook the Voila tests serve
VOILA_NOTEBOOK = "02"


@contextlib.contextmanager
def presenting(view: str):
    """``tools/present.py`` serving notebook 02 in quick mode with Voila, ``view`` ("all" or
    "explorers"), on a free loopback port: yields ``(notebook, url)``. On exit present.py is
    stopped by its process id and must take Voila and every kernel with it."""
    nb = resolve_notebook(VOILA_NOTEBOOK)
    log = BUILD / "artifacts" / f"voila-{nb.stem[:2]}-{view}.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    present = [sys.executable, str(ROOT / "tools" / "present.py"), str(nb), "--quick"]
    with serving_on_free_port(
        lambda port: [*present, f"--port={port}", f"--view={view}"], log=log, timeout=120
    ) as (proc, url):
        assert child_pids(proc.pid), "present.py started no Voila"
        yield nb, url
        spawned = [*child_pids(proc.pid)]  # Voila (its own process group) and its kernels
        for pid in spawned:
            spawned += child_pids(pid)
    assert proc.poll() is not None, "present.py still runs"
    left = [pid for pid in spawned if alive(pid, wait=15.0)]
    assert not left, f"left running after the test: pids {left}"


@pytest.fixture(scope="session")
def voila_all(browser):
    """Notebook 02 whole in Voila, opened once: ``(notebook, url, Watched page)``. The tests that
    use it read and move different widgets (the Mmax explorer, the solutions' buttons)."""
    with presenting("all") as (nb, url), watched_page(browser) as w:
        w.page.goto(url, timeout=300_000)
        yield nb, url, w


SITE = BUILD / "browser-site"


@pytest.fixture(scope="session")
def site_url():
    """The static site built in quick mode (tools/site.py, as ``make site QUICK=1``), served locally.

    ``TUNNELKIT_SITE_DIR=<dir>`` serves an already built site instead of building one.
    """
    given = os.environ.get("TUNNELKIT_SITE_DIR")
    site = Path(given).resolve() if given else SITE
    if not given:
        t0 = time.perf_counter()
        run = subprocess.run(
            [sys.executable, str(ROOT / "tools" / "site.py"), "--quick", "--out", str(SITE)],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=1800,
        )
        assert run.returncode == 0, f"tools/site.py failed:\n{run.stdout}\n{run.stderr}"
        print(f"site built in {time.perf_counter() - t0:.0f} s")
    port = free_port()
    url = f"http://{HOST}:{port}/"
    cmd = [sys.executable, "-m", "http.server", str(port), "--bind", HOST, "--directory", str(site)]
    with serving(cmd, url, timeout=30):
        yield url


@pytest.fixture(scope="session")
def chapter_pages(browser, site_url, artifacts):
    """Every chapter page of the site, opened once per width and recorded (pages.py)."""
    from .pages import ChapterPages

    pages = ChapterPages(browser, site_url, artifacts, list_notebooks())
    try:
        yield pages
    finally:
        pages.close()
