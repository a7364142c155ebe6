"""Browser tests: Voila and the static site driven by Playwright through Debian's Chromium.

They are collected only when ``TUNNELKIT_BROWSER=1`` (``make browser`` sets it), so the unit run
``pytest tests`` leaves them out. Every request that is not to 127.0.0.1 is aborted; every server
runs on a free loopback port and is stopped by its process id; screenshots go to build/artifacts/.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

from _lecture import BUILD, CHROMIUM, HOST, free_port, serving  # noqa: E402

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


@pytest.fixture
def watched(browser):
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    try:
        yield Watched(context.new_page())
    finally:
        context.close()


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
