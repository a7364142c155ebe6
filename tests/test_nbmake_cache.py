"""tools/nbmake_cache.py: a notebook nbmake ran (``make notebooks``) is the site build's run.

A passing run lands in ``execute``'s cache under the digest ``execute`` computes, so the site build
(``execute``) takes it without starting a kernel; a failing run is never stored; a run without the
solutions (``TUNNELKIT_SOLUTIONS`` unset) is not the site's run and is not stored either.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import _lecture as lec  # noqa: E402

nb_run = pytest.importorskip("nbmake.nb_run")


def _notebook(path: Path, *sources: str) -> Path:
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(s) for s in sources]
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    nbformat.write(nb, path)
    return path


@pytest.fixture
def plugged(tmp_path, monkeypatch):
    """nbmake's NotebookRun with the plugin applied (undone after the test), kernels over IPC as
    notebooks/conftest.py starts them, and a cache of the test's own."""
    monkeypatch.setattr(lec, "EXECUTED", tmp_path / "executed")
    monkeypatch.setattr(nb_run.NotebookRun, "execute", nb_run.NotebookRun.execute)
    monkeypatch.setattr(nb_run, "NotebookClient", lec.notebook_client)
    spec = importlib.util.spec_from_file_location(
        "nbmake_cache", ROOT / "tools" / "nbmake_cache.py"
    )
    plugin = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(plugin)
    plugin.pytest_configure(None)
    monkeypatch.setenv("TUNNELKIT_QUICK", "1")
    return tmp_path


def test_a_passing_run_is_the_site_builds_and_a_failing_one_is_not_kept(plugged, monkeypatch):
    monkeypatch.setenv("TUNNELKIT_SOLUTIONS", "1")
    good = _notebook(plugged / "good.ipynb", "import os\nx = os.environ['PLOTLY_RENDERER']", "x")
    bad = _notebook(plugged / "bad.ipynb", "x = 1", "raise RuntimeError('a failing cell')")
    assert nb_run.NotebookRun(good, 60).execute().error is None
    assert nb_run.NotebookRun(bad, 60).execute().error is not None
    assert not lec.executed_path(bad, True).exists(), "a failing run was kept"

    kept = nbformat.read(lec.executed_path(good, True), as_version=4)
    assert kept.metadata["tunnelkit_lecture"]["digest"] == lec.inputs_digest(good, True)
    assert len(kept.cells) == 2, "the widget dump cell was left in"
    # the kernel ran with execute's environment: plotly figures as JSON
    assert kept.cells[1].outputs[0]["data"]["text/plain"] == "'plotly_mimetype'"

    def no_kernel(*_a, **_k):
        raise AssertionError("execute started a kernel: the kept run was not taken")

    monkeypatch.setattr(lec, "notebook_client", no_kernel)
    assert lec.execute(good, quick=True).cells[1].outputs == kept.cells[1].outputs


def test_a_run_without_the_solutions_is_not_kept(plugged, monkeypatch):
    monkeypatch.delenv("TUNNELKIT_SOLUTIONS", raising=False)
    good = _notebook(plugged / "student.ipynb", "x = 1")
    assert nb_run.NotebookRun(good, 60).execute().error is None
    assert not lec.executed_path(good, True).exists()
