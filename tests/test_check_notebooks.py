"""tools/check_notebooks.py: the one exercise format, and the clean filter that keeps outputs out
of commits (installed by `make lab`)."""

from __future__ import annotations

import importlib.util
import io
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location(
    "check_notebooks", ROOT / "tools" / "check_notebooks.py"
)
cn = importlib.util.module_from_spec(spec)
spec.loader.exec_module(cn)


def _md(text):
    return {"cell_type": "markdown", "metadata": {}, "source": text}


def _code(text, **meta):
    return {
        "cell_type": "code",
        "metadata": meta,
        "source": text,
        "outputs": [],
        "execution_count": None,
    }


HIDDEN = {"jupyter": {"source_hidden": True, "outputs_hidden": True}, "tags": ["solution"]}


def test_the_one_exercise_format_passes():
    cells = [
        _md("## Exercises\n1. Do it.\n2. And this."),
        _code("# Solution 1: it\nprint(1)", **HIDDEN),
        _code("# Exercise 2, solution (a): this\nprint(2)", **HIDDEN),
        _md("<details><summary>What to read</summary>\n\n1. One.\n3. A reading, not an exercise."),
        _md("## Checks"),
    ]
    assert cn.exercise_problems(Path("09-x.ipynb"), cells) == []


@pytest.mark.parametrize(
    ("cells", "message"),
    [
        ([_md("## Exercises"), _code("print(1)"), _md("## Checks")], "not tagged 'solution'"),
        ([_md("## Exercises"), _code("x", tags=["solution"])], "does not hide its source"),
        ([_md("## Exercises\n<details>\n```python\nx\n```"), _md("## Checks")], "markdown code"),
        ([_md("## Exercises\n<details>answer</details>"), _md("## Checks")], "without a solution"),
        (
            [
                _md("## Exercises\n1. Do it.\n2. And this.\n<details>\n2. answer in prose"),
                _code("# Solution 1: it\nprint(1)", **HIDDEN),
                _md("## Checks"),
            ],
            "exercise 2 has no solution cell",
        ),
    ],
)
def test_other_formats_are_refused(cells, message):
    found = cn.exercise_problems(Path("09-x.ipynb"), cells)
    assert any(message in p for p in found), found


def test_clean_drops_outputs_counts_and_lab_metadata_and_keeps_the_solution_metadata():
    nb = json.loads((ROOT / "notebooks" / "04-javelin-tracking.ipynb").read_text())
    committed = cn._dump(nb)
    dirty = json.loads(committed)
    dirty["metadata"]["widgets"] = {"state": {}}
    for c in dirty["cells"]:
        if c["cell_type"] == "code":
            c["outputs"] = [{"output_type": "stream", "name": "stdout", "text": "x\n"}]
            c["execution_count"] = 3
            c["metadata"]["execution"] = {"iopub.status.busy": "2026"}
    out = io.StringIO()
    cn.clean_filter(io.StringIO(json.dumps(dirty)), out)
    assert out.getvalue() == committed  # byte for byte what the repository holds
    assert any(
        "solution" in c["metadata"].get("tags", []) for c in json.loads(out.getvalue())["cells"]
    )


@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_git_commits_a_notebook_without_the_outputs_in_its_working_copy(tmp_path):
    def git(*args):
        return subprocess.run(
            ["git", "-C", str(tmp_path), *args], check=True, capture_output=True, text=True
        ).stdout

    git("init", "-q")
    git("config", "user.email", "a@b.c")
    git("config", "user.name", "a")
    tool = ROOT / "tools" / "check_notebooks.py"
    git("config", "filter.nbstrip.clean", f"{sys.executable} {tool} --clean-filter")
    (tmp_path / ".gitattributes").write_text("*.ipynb filter=nbstrip\n")
    src = ROOT / "notebooks" / "01-virtual-stations-and-crlb.ipynb"
    nb = json.loads(src.read_text())
    nb["cells"][1]["outputs"] = [{"output_type": "stream", "name": "stdout", "text": "autosaved\n"}]
    nb["cells"][1]["execution_count"] = 1
    (tmp_path / "nb.ipynb").write_text(json.dumps(nb))
    git("add", "-A")
    git("commit", "-qm", "x")
    assert git("show", "HEAD:nb.ipynb") == src.read_text()
    assert "autosaved" in (tmp_path / "nb.ipynb").read_text()  # the working copy keeps them
    assert git("status", "--porcelain") == ""


def test_every_glossary_link_of_the_notebooks_has_its_entry():
    import re

    glossary = (ROOT / "notebooks" / "GLOSSARY.md").read_text()
    anchors = set(re.findall(r'<a id="([\w-]+)"></a>', glossary))
    links = {
        (src.name, a)
        for src in (ROOT / "notebooks" / ".src").glob("*.py")
        for a in re.findall(r"GLOSSARY\.md#([\w-]+)", src.read_text())
    }
    assert links, "no notebook links a glossary entry"
    assert {a for _, a in links} <= anchors, sorted(links)
