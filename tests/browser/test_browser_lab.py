"""Test 5: in JupyterLab, Run All leaves every exercise's solution collapsed.

A copy of notebook 01 (as committed: no outputs) is opened in JupyterLab, served on a free loopback
port from a temporary directory, and run with Run > Run All Cells in quick mode. When the Checks
cell has printed, each solution cell (tag ``solution``, metadata ``jupyter.source_hidden`` and
``jupyter.outputs_hidden``) must show only its collapsed first line and, below it, the one-line
summary of its collapsed output (tunnelkit.solutions: JupyterLab itself shows the outputs of a
cell again once it runs): it ran, but nothing it printed is on screen until the student opens it.

Artefacts in build/artifacts/: lab-01-solutions.png (the exercises after Run All) and lab-01.log.
"""

from __future__ import annotations

import shutil

import nbformat
from _lecture import ROOT, kernel_env, lab_command, resolve_notebook, serving_on_free_port

from tunnelkit.solutions import SUMMARY

NOTEBOOK = "01"

# What a cell shows: whether its source is collapsed, all the text of its outputs, and the text of
# its outputs that is on screen (innerText leaves out what a closed <details> hides)
CELL = """idx => {
  const c = document.querySelector(`.jp-Cell[data-windowed-list-index="${idx}"]`);
  if (!c) return null;
  const seen = e => { const r = e.getBoundingClientRect(); return e.checkVisibility() && r.height > 0; };
  const outs = [...c.querySelectorAll('.jp-OutputArea-output, .jp-OutputPlaceholder')];
  return {
    input_collapsed: [...c.querySelectorAll('.jp-InputPlaceholder')].some(seen),
    output_text: outs.map(e => e.textContent).join(' ').trim(),
    shown: outs.filter(seen).map(e => e.innerText.trim()).filter(Boolean),
  };
}"""


def test_run_all_keeps_solutions_collapsed(tmp_path, watched, artifacts):
    src = resolve_notebook(NOTEBOOK)
    work = tmp_path / "lab"
    work.mkdir()
    shutil.copy(src, work / src.name)
    nb = nbformat.read(src, as_version=4)
    sols = [i for i, c in enumerate(nb.cells) if "solution" in c.metadata.get("tags", [])]
    assert sols, f"{src.name} has no solution cell"

    env = kernel_env(quick=True)
    env["PYTHONPATH"] = str(ROOT)
    env["JUPYTER_CONFIG_DIR"] = str(tmp_path / "config")  # no user settings, no news prompt
    with serving_on_free_port(
        lambda port: lab_command(port, work), env=env, log=artifacts / "lab-01.log", timeout=180
    ) as (_, url):
        page = watched.page
        page.goto(url + f"lab/tree/{src.name}", timeout=180_000)
        page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=180_000)
        # the kernel is up when the status bar says so
        page.wait_for_function("document.body.innerText.includes('| Idle')", timeout=180_000)
        page.get_by_role("menuitem", name="Run", exact=True).click()
        page.get_by_role("menuitem", name="Run All Cells", exact=True).click()
        page.mouse.move(700, 500)
        last = len(nb.cells) - 1
        for idx in [*sols, last]:  # the notebook renders the cells near the viewport only
            cell = page.locator(f'.jp-Cell[data-windowed-list-index="{idx}"]')
            for _ in range(200):
                if cell.count():
                    break
                page.mouse.wheel(0, 600)
                page.wait_for_timeout(100)
            cell.scroll_into_view_if_needed()
        # the Checks cell prints (in its output, not its source) when Run All has reached the end
        page.wait_for_function(
            "idx => (document.querySelector("
            '`.jp-Cell[data-windowed-list-index="${idx}"] .jp-OutputArea`'
            ")?.innerText || '').includes('all checks passed')",
            arg=last,
            timeout=600_000,
        )
        states = {}
        for idx in sols:
            page.locator(f'.jp-Cell[data-windowed-list-index="{idx}"]').scroll_into_view_if_needed()
            states[idx] = page.evaluate(CELL, idx)
        page.locator(f'.jp-Cell[data-windowed-list-index="{sols[0]}"]').scroll_into_view_if_needed()
        page.screenshot(path=str(artifacts / "lab-01-solutions.png"))
    for idx, s in states.items():
        assert s is not None, f"cell {idx} was not rendered"
        assert s["input_collapsed"], f"cell {idx}: its source is not collapsed"
        assert s["output_text"], f"cell {idx}: no output after Run All (did it run?)"
        assert all(t == SUMMARY for t in s["shown"]), f"cell {idx} shows unasked: {s['shown']}"
        assert len(s["output_text"]) > len(SUMMARY), f"cell {idx}: the collapsed output is empty"
