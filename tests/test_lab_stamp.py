"""tools/lab_runtimes.py's stamp cell, run by a real kernel without a browser.

Run All in JupyterLab does not always stop at a failing cell (the kernel aborts only the requests
already queued when the error is raised), so the stamp cell itself records whether an earlier cell
raised. Here nbclient plays the late-request case deterministically: with ``allow_errors`` every
cell runs after the failure, the stamp is written, and reading it must still report the failure.
"""

from __future__ import annotations

import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

TOOLS = Path(__file__).resolve().parents[1] / "tools"
sys.path.insert(0, str(TOOLS))

from _lecture import LectureError  # noqa: E402
from lab_runtimes import read_stamp, stamped_copy  # noqa: E402


def _run_stamped(tmp_path: Path, sources: list[str]) -> Path:
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(s) for s in sources]
    src = tmp_path / "book.ipynb"
    nbformat.write(nb, src)
    work = tmp_path / "work"
    work.mkdir()
    copy, stamp = stamped_copy(src, work)
    client = NotebookClient(
        nbformat.read(copy, as_version=4), timeout=120, kernel_name="python3", allow_errors=True
    )
    client.execute(cwd=str(work))
    assert stamp.exists(), "the stamp cell did not run"
    return stamp


def test_a_failure_before_the_stamp_is_reported_even_when_later_cells_ran(tmp_path):
    stamp = _run_stamped(tmp_path, ["x = 1", "raise RuntimeError('a failing cell')", "y = 2"])
    with pytest.raises(
        LectureError, match=r"a cell failed during Run All.*RuntimeError: a failing"
    ):
        read_stamp(stamp, "book.ipynb")


def test_a_clean_run_is_timed(tmp_path):
    stamp = _run_stamped(tmp_path, ["x = 1", "y = x + 1"])
    done = read_stamp(stamp, "book.ipynb")
    assert done["error"] is None
    assert done["t"] > 0 and done["cpu"] > 0
