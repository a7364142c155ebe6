"""Test 5: in JupyterLab, Run All leaves every exercise's solution un-run, until asked for.

A copy of notebook 01 (as committed: no outputs) is opened in the session's JupyterLab (conftest.py:
a free loopback port, a temporary directory, a workspace of the test's own), and run with Run >
Run All Cells in quick mode (the kernel without ``TUNNELKIT_SOLUTIONS``, as a student's). When
the Checks cell has printed (so the Checks pass without the solutions), each solution cell (tag
``solution``, magic ``%%solution 01.N``, metadata ``jupyter.source_hidden``) must show its
collapsed source and, below it, only the line
"Solution 01.N ...: run it when you have tried" and its "Run solution 01.N" button
(tunnelkit.solutions): nothing the solution prints, nor its collapsed output of a run at once.
One click on the first solution's button then runs it and shows what it prints.

Artefacts in build/artifacts/: lab-01-solutions.png (the exercises after Run All),
lab-01-solution-run.png (after the click); JupyterLab's log is lab.log.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import nbformat
from _lecture import resolve_notebook

from tunnelkit.solutions import ASK, SUMMARY, solution_id

NOTEBOOK = "01"
#: what the solutions of 01 print (their first words), none of which Run All may show
PRINTED = ("smallest bound", "median bound at", "TOA-only bound above")

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


def test_run_all_leaves_solutions_unrun_until_asked(lab, watched, artifacts):
    root, url = lab  # the kernel as a student's: solutions wait to be asked for
    src = resolve_notebook(NOTEBOOK)
    work = Path(tempfile.mkdtemp(prefix="lab-01-", dir=root))
    shutil.copy(src, work / src.name)
    nb = nbformat.read(src, as_version=4)
    sols = [i for i, c in enumerate(nb.cells) if "solution" in c.metadata.get("tags", [])]
    assert sols, f"{src.name} has no solution cell"
    sids = {i: solution_id(nb.cells[i].source) for i in sols}
    assert all(sids.values()), sids

    page = watched.page
    rel = (work / src.name).relative_to(root).as_posix()
    page.goto(url + f"lab/workspaces/{work.name}/tree/{rel}", timeout=180_000)
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
    first = page.locator(f'.jp-Cell[data-windowed-list-index="{sols[0]}"]')
    first.scroll_into_view_if_needed()
    page.screenshot(path=str(artifacts / "lab-01-solutions.png"))
    # asked for: the button runs the solution and its output appears under it
    first.get_by_role("button", name=f"Run solution {sids[sols[0]]}").click()
    page.wait_for_function(
        "([idx, text]) => (document.querySelector("
        '`.jp-Cell[data-windowed-list-index="${idx}"] .jp-OutputArea`'
        ")?.innerText || '').includes(text)",
        arg=[sols[0], PRINTED[0]],
        timeout=120_000,
    )
    after = page.evaluate(CELL, sols[0])
    page.screenshot(path=str(artifacts / "lab-01-solution-run.png"))
    for idx, s in states.items():
        assert s is not None, f"cell {idx} was not rendered"
        assert s["input_collapsed"], f"cell {idx}: its source is not collapsed"
        assert s["output_text"], f"cell {idx}: no output after Run All (did its cell run?)"
        text = " ".join(s["shown"])
        assert ASK in text and f"Run solution {sids[idx]}" in text, f"cell {idx} shows: {text}"
        assert SUMMARY not in s["output_text"], f"cell {idx}: the solution ran on Run All"
        for words in PRINTED:
            assert words not in s["output_text"], f"cell {idx} shows its answer unasked: {words}"
    assert any(PRINTED[0] in t for t in after["shown"]), after["shown"]
