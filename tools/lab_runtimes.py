"""How long Run All takes in JupyterLab itself: every notebook opened in a real JupyterLab in
Chromium, Run > Run All Cells clicked, the time until its last cell has run.

    python tools/lab_runtimes.py              # quick mode (TUNNELKIT_QUICK=1), every notebook
    python tools/lab_runtimes.py 05 06        # only these chapters
    python tools/lab_runtimes.py --markdown   # the table as markdown

``tools/runtimes.py`` runs the notebooks with nbclient (the same kernel messages as Run All); this
tool is the lecturer's view: JupyterLab (served on a free loopback port from a temporary copy of
the notebooks, stopped by its process id) renders every output, every plotly figure and widget,
in headless Chromium (``make chromium``). A copy of each notebook gets one extra last cell that
writes the wall-clock time and the kernel's CPU time to a file; the clock starts when "Run All
Cells" is clicked, after the kernel has reported Idle (the kernel's start-up is not included; the
page's rendering of outputs is). A cell that fails stops Run All, so a notebook whose last cell
never runs within ``--timeout`` is reported as failed (at once, when JupyterLab shows every cell
and Run All stopped before the last). Each notebook gets its own JupyterLab server, stopped before
the next one starts, so they run one after the other on an otherwise idle machine; the load
average before and after is printed beside each time.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _lecture import (
    CHROMIUM,
    ROOT,
    LectureError,
    die,
    kernel_env,
    lab_command,
    list_notebooks,
    render_table,
    resolve_notebook,
    serving_on_free_port,
)

# The stamp cell also says whether any earlier cell raised: IPython keeps the last exception it
# showed in sys.last_value. Run All does not always stop at a failing cell: the kernel aborts only
# the requests already queued when the error is raised (ipykernel's stop_on_error_timeout is 0 s),
# and on a loaded machine JupyterLab's requests for the later cells can arrive after that, so the
# stamp alone cannot tell a notebook that failed from one that ran.
STAMP = """import json as _json, resource as _resource, sys as _sys, time as _time
_s, _c = _resource.getrusage(_resource.RUSAGE_SELF), _resource.getrusage(_resource.RUSAGE_CHILDREN)
_e = getattr(_sys, "last_value", None)
open({path!r}, "w").write(_json.dumps({{"t": _time.time(), "cpu": _s.ru_utime + _s.ru_stime + _c.ru_utime + _c.ru_stime, "error": None if _e is None else f"{{type(_e).__name__}}: {{_e}}"}}))
"""
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-sync"]


def stamped_copy(src: Path, work: Path) -> tuple[Path, Path]:
    """A copy of ``src`` in ``work`` with the time-stamp cell appended; the stamp file's path."""
    import nbformat

    nb = nbformat.read(src, as_version=4)
    stamp = work / f"{src.stem}.done.json"
    nb.cells.append(nbformat.v4.new_code_cell(STAMP.format(path=str(stamp))))
    dest = work / src.name
    nbformat.write(nb, dest)
    return dest, stamp


@contextlib.contextmanager
def _own_lab(root: Path, stem: str, env: dict):
    """A JupyterLab of its own for one notebook (no restored tabs, no user settings): its URL."""
    workspaces = f"--LabApp.workspaces_dir={root / ('workspaces-' + stem)}"
    env = {**env, "JUPYTER_CONFIG_DIR": str(root / f"config-{stem}")}
    with serving_on_free_port(
        lambda port: lab_command(port, root, workspaces),
        env=env,
        log=root / f"{stem}.log",
        timeout=180,
    ) as (_, base):
        yield base


# True when Run All has ended without running the last cell: every cell is rendered (a short
# notebook: a long one renders the cells near the viewport only), none is queued or running ("[*]"),
# one has run ("[3]") and the last one has not ("[ ]"): its request was aborted after a failure
STOPPED = """n => {
  const prompts = [...document.querySelectorAll('.jp-Notebook .jp-Cell')].map(
    c => (c.querySelector('.jp-InputPrompt')?.innerText || '').replace(/\\s/g, ''));
  return prompts.length === n && prompts[n - 1] === '[]:' && !prompts.includes('[*]:')
    && prompts.some(p => /^\\[\\d+\\]:$/.test(p));
}"""


def _run_all(browser, url: str, nb_path: Path, stamp: Path, timeout: float) -> dict:
    """Open ``url`` (``nb_path`` in a running JupyterLab), click Run All, wait for ``stamp``.

    The wait ends early when Run All has visibly stopped before the stamp cell (``STOPPED``):
    its request was aborted because a cell before it failed."""
    import nbformat

    n_cells = len(nbformat.read(nb_path, as_version=4).cells)
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    stopped = False
    try:
        page.goto(url, timeout=180_000)
        page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=180_000)
        page.wait_for_function("document.body.innerText.includes('| Idle')", timeout=180_000)
        load0 = os.getloadavg()[0]
        page.get_by_role("menuitem", name="Run", exact=True).click()
        t0 = time.time()
        page.get_by_role("menuitem", name="Run All Cells", exact=True).click()
        while not stamp.exists() and time.time() - t0 < timeout:
            if page.evaluate(STOPPED, n_cells) and not stamp.exists():
                stopped = True
                break
            page.wait_for_timeout(200)
        _wait_written(stamp)
    finally:
        page.close()
    if not stamp.exists():
        why = (
            "a cell before it failed and Run All stopped there"
            if stopped
            else f"within {timeout:.0f} s (a failing cell stops Run All)"
        )
        raise LectureError(f"{nb_path.name}: Run All did not reach its last cell: {why}")
    done = read_stamp(stamp, nb_path.name)
    return {
        "notebook": nb_path.stem,
        "wall_s": done["t"] - t0,
        "cpu_s": done["cpu"],
        "load_before": load0,
        "load_after": os.getloadavg()[0],
    }


def _wait_written(stamp: Path, timeout: float = 10.0) -> None:
    """Until the stamp file, if there is one, holds its whole record (the kernel may still be
    writing it)."""
    end = time.monotonic() + timeout
    while stamp.exists() and time.monotonic() < end:
        try:
            json.loads(stamp.read_text())
            return
        except ValueError:
            time.sleep(0.05)


def read_stamp(stamp: Path, name: str) -> dict:
    """The stamp cell's record; a ``LectureError`` when a cell before it raised (Run All went on
    past a failing cell: see ``STAMP``), so a failed notebook is never timed as if it ran."""
    done = json.loads(stamp.read_text())
    if done.get("error") is not None:
        raise LectureError(
            f"{name}: a cell failed during Run All ({done['error']}); "
            "the later cells ran because the kernel did not abort them"
        )
    return done


def measure_all(
    books: list[Path], *, timeout: float, browser=None, lab: tuple[Path, str] | None = None
) -> list[dict]:
    """Run All of every notebook in ``books``, one after the other (a row each). ``browser``: a
    Playwright browser already running in this thread (a second ``sync_playwright`` cannot
    start beside it); default: Chromium started here and closed at the end. ``lab``: the root
    directory and URL of a JupyterLab already running with ``kernel_env(quick=True)`` and this
    checkout on PYTHONPATH (the browser tests'); default: a fresh one per notebook."""
    if browser is None:
        from playwright.sync_api import sync_playwright

        if not os.access(CHROMIUM, os.X_OK):
            raise LectureError(f"{CHROMIUM} is missing: run `make chromium`")
        with sync_playwright() as pw:
            own = pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
            try:
                return measure_all(books, timeout=timeout, browser=own, lab=lab)
            finally:
                own.close()
    root, base = lab if lab is not None else (None, None)
    tmp = Path(tempfile.mkdtemp(prefix="tunnelkit-lab-runtimes-", dir=root))
    try:
        copies = [stamped_copy(b, tmp) for b in books]
        env = kernel_env(quick=True)
        env["PYTHONPATH"] = str(ROOT)
        rows = []
        for nb_path, stamp in copies:
            if lab is None:  # a fresh server per notebook: nothing carried over
                with _own_lab(tmp, nb_path.stem, env) as own:
                    url = own + f"lab/tree/{nb_path.name}"
                    rows.append(_run_all(browser, url, nb_path, stamp, timeout))
            else:  # a workspace of its own in the given server: no tab restored
                rel = nb_path.relative_to(root).as_posix()
                url = base + f"lab/workspaces/{tmp.name}-{nb_path.stem}/tree/{rel}"
                rows.append(_run_all(browser, url, nb_path, stamp, timeout))
            r = rows[-1]
            print(
                f"  {r['notebook']}: Run All {r['wall_s']:.1f} s, kernel CPU "
                f"{r['cpu_s']:.1f} s (load {r['load_before']:.1f}-{r['load_after']:.1f})",
                flush=True,
            )
        return rows
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def table(rows: list[dict], markdown: bool) -> str:
    head = ("notebook", "Run All in JupyterLab [s]", "kernel CPU [s]", "load avg (1 min)")
    body = [
        (
            r["notebook"],
            f"{r['wall_s']:.1f}",
            f"{r['cpu_s']:.1f}",
            f"{r['load_before']:.1f}-{r['load_after']:.1f}",
        )
        for r in rows
    ]
    return render_table(head, body, markdown)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebooks", nargs="*", help="chapter numbers or names (default: all)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per notebook (600)")
    ap.add_argument("--markdown", action="store_true", help="print the table as markdown")
    ap.add_argument("--json", type=Path, default=None, help="also write the rows to this file")
    args = ap.parse_args(argv)
    if not args.timeout > 0:
        return die(f"--timeout must be > 0, got {args.timeout}")
    try:
        books = [resolve_notebook(n) for n in args.notebooks] or list_notebooks()
    except LectureError as exc:
        return die(str(exc))
    print(
        f"{len(books)} notebook(s), quick mode, JupyterLab in Chromium, {os.cpu_count()} CPU(s), "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}",
        flush=True,
    )
    try:
        rows = measure_all(books, timeout=args.timeout)
    except LectureError as exc:
        return die(str(exc), 1)
    print(table(rows, args.markdown))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
