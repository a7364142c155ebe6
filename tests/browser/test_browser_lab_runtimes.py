"""tools/lab_runtimes.py: Run All timed in JupyterLab itself.

Notebook 02 (the shortest) is run through the tool: one row, a positive wall time not shorter
than a tenth of the kernel's CPU time (the stamp cell ran after every other cell), and a notebook
whose second cell fails is reported as failed: either Run All stops there and the stamp never
comes, or (when the kernel did not abort the later requests in time) the stamp cell records the
exception. Both must raise; which one happens depends on timing, not on the tool.
Both run in the session's browser (a second Playwright cannot start beside it in one thread) and
its JupyterLab (conftest.py), each notebook in a workspace of its own.
"""

from __future__ import annotations

import nbformat
import pytest
from _lecture import LectureError, resolve_notebook
from lab_runtimes import measure_all


def test_run_all_of_notebook_02_is_timed(browser, lab):
    rows = measure_all([resolve_notebook("02")], timeout=300, browser=browser, lab=lab)
    assert [r["notebook"] for r in rows] == ["02-fresnel-bound-and-mmax"]
    r = rows[0]
    assert r["wall_s"] > 0 and r["cpu_s"] > 0, r
    assert r["wall_s"] > 0.1 * r["cpu_s"], r


def test_a_failing_cell_is_reported(tmp_path, browser, lab):
    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_code_cell("x = 1"),
        nbformat.v4.new_code_cell("raise RuntimeError('a failing cell')"),
        nbformat.v4.new_code_cell("y = 2"),
    ]
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    path = tmp_path / "failing.ipynb"
    nbformat.write(nb, path)
    with pytest.raises(LectureError, match=r"did not reach its last cell|a cell failed"):
        measure_all([path], timeout=20, browser=browser, lab=lab)
