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
        _code("%%solution 09.1\n# Solution 1: it\nprint(1)", **HIDDEN),
        _code("%%solution 09.2a\n# Exercise 2, solution (a): this\nprint(2)", **HIDDEN),
        _md("<details><summary>What to read</summary>\n\n1. One.\n3. A reading, not an exercise."),
        _md("## Checks"),
    ]
    assert cn.exercise_problems(Path("09-x.ipynb"), cells) == []


@pytest.mark.parametrize(
    ("cells", "message"),
    [
        ([_md("## Exercises"), _code("print(1)"), _md("## Checks")], "not tagged 'solution'"),
        ([_md("## Exercises"), _code("x", tags=["solution"])], "does not hide its source"),
        ([_md("## Exercises"), _code("# Solution 1: it\nx", **HIDDEN)], "start with the magic"),
        ([_code("%%solution 09.1\nx")], "not tagged 'solution'"),
        ([_code("%%solution 08.1\nx", **HIDDEN)], "not of notebook 09"),
        ([_code("%%solution 09.1\nx", **HIDDEN)] * 2, "solution 09.1 again"),
        ([_md("## Exercises\n<details>\n```python\nx\n```"), _md("## Checks")], "markdown code"),
        ([_md("## Exercises\n<details>answer</details>"), _md("## Checks")], "without a solution"),
        (
            [
                _md("## Exercises\n1. Do it.\n2. And this.\n<details>\n2. answer in prose"),
                _code("%%solution 09.1\n# Solution 2: the comment does not count\nx", **HIDDEN),
                _md("## Checks"),
            ],
            "exercise 2 has no solution cell",
        ),
    ],
)
def test_other_formats_are_refused(cells, message):
    found = cn.exercise_problems(Path("09-x.ipynb"), cells)
    assert any(message in p for p in found), found


def test_names_a_cell_assigns_and_reads_before_assigning():
    assigned, free = cn.cell_names(
        "%%solution 09.1\nimport numpy as np\nfrom a.b import c as d\ny = np.sin(x)\n"
        "def f(t):\n    return t + z\nfor k in range(3):\n    w = [j for j in y] + d\n"
        "try:\n    pass\nexcept ValueError as err:\n    print(err)\n"
    )
    assert {"np", "d", "y", "f", "k", "w", "err"} <= assigned
    assert free == {"x", "z", "range", "ValueError", "print"}
    assert cn.cell_names("%timeit x = 1\ny = v")[1] >= {"v"}  # IPython syntax parses


@pytest.mark.parametrize(
    ("cells", "message"),
    [
        (  # the Checks read a solution's result
            [_code("x = 1"), _code("%%solution 09.1\nans = x + 1", **HIDDEN), _code("assert ans")],
            "cell 2 reads 'ans', which only solution cells assign",
        ),
        (  # a solution reads another solution's result
            [
                _code("%%solution 09.1\nZp = 1", **HIDDEN),
                _code("%%solution 09.2\nZ = Zp", **HIDDEN),
            ],
            "cell 1 reads 'Zp', which only another solution assigns",
        ),
    ],
)
def test_the_lesson_does_not_depend_on_its_solutions(cells, message):
    found = cn.namespace_problems(Path("09-x.ipynb"), cells)
    assert len(found) == 1 and message in found[0], found


def test_a_solution_may_rebind_a_lesson_name_and_use_its_own():
    cells = [
        _code("route = 1\ncfg = 2"),
        _code("%%solution 09.1\nroute = 3\nans = route + cfg\nassert ans", **HIDDEN),
        _code("%%solution 09.2\nans = 4\nprint(ans)", **HIDDEN),
        _code("assert route == 1"),
    ]
    assert cn.namespace_problems(Path("09-x.ipynb"), cells) == []


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
