"""Check (or with --strip / --build, enforce) the notebook conventions.

* every ``notebooks/NN-name.ipynb`` is paired (jupytext, ``notebooks/.jupytext.toml``) with its
  percent-format source ``notebooks/.src/NN-name.py`` and agrees with it;
* committed without outputs or execution counts;
* the kernelspec is the one ``make lab`` registers (``python3``, "Python (tunnelkit)");
* the first code cell imports tunnelkit and calls ``tk.setup_notebook()``;
* a markdown cell headed "Checks" followed by code that asserts;
* one exercise format: every code cell between the "Exercises" heading and "Checks" is a
  solution (tag ``solution``, cell metadata ``jupyter.source_hidden`` and
  ``jupyter.outputs_hidden`` true) whose first line is the magic ``%%solution NN.E`` (the
  notebook's number and the exercise's; ``tunnelkit.solutions``): Run All does not run it, the
  student asks for it, CI runs it with ``TUNNELKIT_SOLUTIONS=1``. A solution is code, not a
  markdown code block, every numbered exercise has one, and no other cell starts with the magic;
* the lesson does not depend on its solutions: a solution runs in a copy of the notebook's
  namespace, and perhaps never, so no other cell (the Checks included) reads a name that only
  solution cells assign, and no solution reads a name that only another solution assigns
  (names found by ``ast``; a solution asserts on its own results).

The committed notebook is what is checked. In a clone where ``make lab`` installed the output
filter (``git config filter.nbstrip.clean``), that is the notebook as the filter cleans it, so
JupyterLab's autosaved outputs in the working tree do not fail ``make lint``;
``--clean-filter`` is the filter itself (a notebook on stdin, the committed form on stdout).

``--build`` rewrites each notebook from its source (cell ids and tags kept; outputs, execution
counts and the metadata JupyterLab adds on save dropped);
``--strip`` only removes outputs. Files are replaced whole (written to a temporary file, then
renamed), so an interrupted run leaves no half-written notebook. Exit status 1 with one line per
problem.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import tempfile
from pathlib import Path

SOURCES = ".src"
SOLUTION_TAG = "solution"
#: a numbered exercise in the Exercises section's markdown ("1. ..." at the start of a line)
EXERCISE = re.compile(r"^(\d+)\. ", re.MULTILINE)
FILTER = "nbstrip"
KERNELSPEC = {"display_name": "Python (tunnelkit)", "language": "python", "name": "python3"}


def source_of(notebook: Path) -> Path:
    """The paired percent-format source of a notebook."""
    return notebook.parent / SOURCES / f"{notebook.stem}.py"


def notebook_of(source: Path) -> Path:
    """The paired notebook of a source in ``notebooks/.src/``."""
    return source.parent.parent / f"{source.stem}.ipynb"


def _config(path: Path):
    from jupytext.config import load_jupytext_config

    return load_jupytext_config(str(path.resolve()))


def _fmt() -> dict:
    return {"extension": ".py", "format_name": "percent"}


def _atomic_write(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _dump(nb: dict) -> str:
    return json.dumps(nb, indent=1, sort_keys=True, ensure_ascii=False) + "\n"


def sync_problems(path: Path) -> list[str]:
    """Whether a notebook and its source say the same thing (the notebook written as its source)."""
    import jupytext

    src = source_of(path)
    if not src.exists():
        return [f"{path}: no paired source {src} (see notebooks/.jupytext.toml)"]
    nb = jupytext.read(path)
    written = jupytext.writes(nb, fmt=_fmt(), config=_config(path))
    text = src.read_text()
    if written == text:
        return []
    for n, (a, b) in enumerate(zip(text.splitlines(), written.splitlines(), strict=False), 1):
        if a != b:
            where = f"source line {n}: {a.strip()[:60]!r} vs notebook {b.strip()[:60]!r}"
            break
    else:
        n_src, n_nb = len(text.splitlines()), len(written.splitlines())
        where = f"the source has {n_src} lines, the notebook {n_nb}"
    return [
        f"{path}: disagrees with its source {src} ({where}); "
        f"run `make format` to rebuild the notebook from the source"
    ]


def build(src: Path) -> Path:
    """Rewrite the notebook paired with ``src`` from it: outputs dropped, ids/metadata kept."""
    import jupytext
    import nbformat
    from jupytext.combine import combine_inputs_with_outputs

    target = notebook_of(src)
    nb = jupytext.read(src, fmt=_fmt(), config=_config(src))
    if target.exists():
        nb = combine_inputs_with_outputs(nb, jupytext.read(target), fmt=_fmt())
    # what JupyterLab adds on save (language_info details, widget state) is dropped: the
    # committed notebook carries only the kernel it runs on
    nb.metadata = nbformat.from_dict(
        {"kernelspec": dict(KERNELSPEC), "language_info": {"name": "python"}}
    )
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
    nbformat.validate(nb)
    text = nbformat.writes(nb) + "\n"
    if not target.exists() or target.read_text() != text:
        _atomic_write(target, text)
        print(f"wrote {target}")
    return target


def clean(nb: dict) -> dict:
    """The committed form of a notebook: no outputs, no execution counts, the notebook metadata
    reduced to the kernel (what ``--build`` writes), JupyterLab's per-cell timing dropped."""
    nb = dict(nb)
    nb["metadata"] = {"kernelspec": dict(KERNELSPEC), "language_info": {"name": "python"}}
    cells = []
    for c in nb.get("cells", []):
        c = dict(c)
        meta = {
            k: v for k, v in c.get("metadata", {}).items() if k not in ("execution", "scrolled")
        }
        c["metadata"] = meta
        if c.get("cell_type") == "code":
            c["outputs"], c["execution_count"] = [], None
        cells.append(c)
    nb["cells"] = cells
    return nb


def clean_filter(stdin=sys.stdin, stdout=sys.stdout) -> int:
    """git's clean filter: the notebook on stdin, its committed form on stdout."""
    text = stdin.read()
    try:
        nb = json.loads(text)
    except json.JSONDecodeError:
        stdout.write(text)  # not a notebook git can parse as one: leave it alone
        return 0
    stdout.write(_dump(clean(nb)))
    return 0


def _filter_installed(path: Path) -> bool:
    import subprocess

    r = subprocess.run(
        ["git", "-C", str(path.parent), "config", "--get", f"filter.{FILTER}.clean"],
        capture_output=True,
        text=True,
        check=False,
    )
    return r.returncode == 0 and bool(r.stdout.strip())


def _heading_index(cells: list[dict], word: str) -> int | None:
    for i, c in enumerate(cells):
        if c.get("cell_type") != "markdown":
            continue
        src = "".join(c["source"]) if isinstance(c["source"], list) else c["source"]
        if any(
            line.startswith("#") and line.lstrip("# ").lower().startswith(word)
            for line in src.splitlines()
        ):
            return i
    return None


def _source(cell: dict) -> str:
    return "".join(cell["source"]) if isinstance(cell["source"], list) else cell["source"]


def _tagged(cell: dict) -> bool:
    return SOLUTION_TAG in cell.get("metadata", {}).get("tags", [])


def exercise_problems(path: Path, cells: list[dict]) -> list[str]:
    """The one exercise format (see the module docstring)."""
    from tunnelkit.solutions import exercise_of, solution_id

    out = []
    number = path.stem.split("-", 1)[0]
    seen: dict[str, int] = {}
    for i, c in enumerate(cells):
        meta = c.get("metadata", {})
        hidden = meta.get("jupyter", {})
        sid = solution_id(_source(c)) if c.get("cell_type") == "code" else None
        if _tagged(c) and sid is None:
            out.append(
                f"{path}: cell {i} is a solution but does not start with the magic "
                f"'%%solution {number}.N' (N: its exercise), so Run All would run it"
            )
        if sid is not None and not _tagged(c):
            out.append(f"{path}: cell {i} starts with %%solution but is not tagged 'solution'")
        if sid is not None and exercise_of(sid)[0] != number:
            out.append(f"{path}: cell {i}: solution {sid} is not of notebook {number}")
        if sid is not None and sid in seen:
            out.append(f"{path}: cell {i}: solution {sid} again (first in cell {seen[sid]})")
        if sid is not None:
            seen.setdefault(sid, i)
        if _tagged(c) and not (hidden.get("source_hidden") and hidden.get("outputs_hidden")):
            out.append(
                f"{path}: cell {i} is a solution but does not hide its source and outputs "
                "(jupyter.source_hidden and jupyter.outputs_hidden)"
            )
    start, end = _heading_index(cells, "exercises"), _heading_index(cells, "checks")
    if start is None:
        return out
    section = cells[start : end if end is not None and end > start else len(cells)]
    n_solutions = 0
    for j, c in enumerate(section):
        i = start + j
        src = "".join(c["source"]) if isinstance(c["source"], list) else c["source"]
        if c.get("cell_type") == "code":
            if SOLUTION_TAG not in c.get("metadata", {}).get("tags", []):
                out.append(f"{path}: cell {i} is code in the exercises but not tagged 'solution'")
            n_solutions += 1
        elif "```" in src:
            out.append(
                f"{path}: cell {i}: a solution in a markdown code block; make it a solution cell"
            )
    if n_solutions == 0:
        out.append(f"{path}: an Exercises section without a solution cell")
    asked, answered = set(), set()
    for c in section:
        src = "".join(c["source"]) if isinstance(c["source"], list) else c["source"]
        if c.get("cell_type") == "markdown":
            text = src.split("<details", 1)[0]  # what follows is a reading, not an exercise
            asked |= {int(m) for m in EXERCISE.findall(text)}
        elif c.get("cell_type") == "code" and solution_id(src) is not None:
            answered.add(exercise_of(solution_id(src))[1])
    for n in sorted(asked - answered):
        out.append(
            f"{path}: exercise {n} has no solution cell (its first line: '%%solution {number}.{n}')"
        )
    return out


def _names(tree) -> tuple[set[str], set[str]]:
    """(names a statement binds, names it reads that it does not bind itself)."""
    import ast

    bound, read = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            (read if isinstance(node.ctx, ast.Load) else bound).add(node.id)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
        elif isinstance(node, ast.ExceptHandler) and node.name:
            bound.add(node.name)
    return bound, read - bound


def cell_names(source: str) -> tuple[set[str], set[str]]:
    """(names a cell assigns, names it reads before assigning them), statement by statement; a
    solution cell without its magic line, IPython syntax turned into Python first."""
    import ast

    from IPython.core.inputtransformer2 import TransformerManager

    from tunnelkit.solutions import is_solution

    if is_solution(source):
        source = source.lstrip().split("\n", 1)[1] if "\n" in source.lstrip() else ""
    tree = ast.parse(TransformerManager().transform_cell(source))
    assigned, free = set(), set()
    for stmt in tree.body:
        bound, read = _names(stmt)
        free |= read - assigned
        assigned |= bound
    return assigned, free


def namespace_problems(path: Path, cells: list[dict]) -> list[str]:
    """No cell depends on a name only solutions assign (see the module docstring)."""
    from tunnelkit.solutions import solution_id

    code = [(i, c) for i, c in enumerate(cells) if c.get("cell_type") == "code"]
    names = {}
    for i, c in code:
        try:
            names[i] = cell_names(_source(c))
        except SyntaxError as exc:
            return [f"{path}: cell {i} does not parse: {exc}"]
    sol = {i for i, c in code if solution_id(_source(c)) is not None}
    lesson = set().union(*(names[i][0] for i, _ in code if i not in sol))
    out = []
    for i, _ in code:
        others = set().union(*(names[j][0] for j in sol if j != i)) - lesson
        for name in sorted(names[i][1] & others):
            whose = "another solution assigns" if i in sol else "solution cells assign"
            out.append(
                f"{path}: cell {i} reads {name!r}, which only {whose}; a solution runs "
                "alone, in a copy of the namespace, and not on Run All (assert on a solution's "
                "result in its own cell)"
            )
    return out


def problems(path: Path, strip: bool) -> list[str]:
    nb = json.loads(path.read_text())
    if not strip and _filter_installed(path):
        nb = clean(nb)  # what git commits from this clone
    out = []
    changed = False
    cells = nb.get("cells", [])
    for i, c in enumerate(cells):
        if c.get("cell_type") != "code":
            continue
        if c.get("outputs") or c.get("execution_count") is not None:
            if strip:
                c["outputs"], c["execution_count"] = [], None
                changed = True
            else:
                out.append(
                    f"{path}: cell {i} has outputs or an execution count (run `make format`)"
                )
    spec = nb.get("metadata", {}).get("kernelspec", {})
    if spec.get("name") != KERNELSPEC["name"]:
        out.append(
            f"{path}: kernelspec name {spec.get('name')!r}, expected {KERNELSPEC['name']!r} "
            "(the kernel `make lab` registers; run `make format`)"
        )
    code = [
        "".join(c["source"]) if isinstance(c["source"], list) else c["source"]
        for c in cells
        if c.get("cell_type") == "code"
    ]
    if not code or "import tunnelkit as tk" not in code[0] or "tk.setup_notebook(" not in code[0]:
        out.append(
            f"{path}: the first code cell must `import tunnelkit as tk` and call `tk.setup_notebook()`"
        )
    heads = [
        i
        for i, c in enumerate(cells)
        if c.get("cell_type") == "markdown"
        and any(
            line.lstrip("# ").lower().startswith("checks")
            for line in "".join(c["source"]).splitlines()
            if line.startswith("#")
        )
    ]
    out += exercise_problems(path, cells)
    out += namespace_problems(path, cells)
    if not heads:
        out.append(f"{path}: no markdown cell headed 'Checks'")
    elif not any(
        "assert" in "".join(c["source"]) for c in cells[heads[-1] :] if c.get("cell_type") == "code"
    ):
        out.append(f"{path}: the Checks section has no assert")
    if changed:
        _atomic_write(path, _dump(nb))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="*", type=Path, help="notebooks or directories of notebooks")
    ap.add_argument(
        "--clean-filter",
        action="store_true",
        help="act as git's clean filter: a notebook on stdin, its committed form on stdout",
    )
    ap.add_argument("--strip", action="store_true", help="remove outputs in place")
    ap.add_argument(
        "--build", action="store_true", help="rebuild each notebook from its .src/ source first"
    )
    args = ap.parse_args(argv)
    if args.clean_filter:
        return clean_filter()
    if not args.paths:
        ap.error("give notebooks or directories of notebooks")
    files = [f for p in args.paths for f in (sorted(p.glob("*.ipynb")) if p.is_dir() else [p])]
    if args.build:
        sources = {
            s
            for p in args.paths
            for s in (sorted((p / SOURCES).glob("*.py")) if p.is_dir() else [source_of(p)])
        }
        missing = [s for s in sorted(sources) if not s.exists()]
        for s in missing:
            print(f"{s}: no such source")
        if missing:
            return 1
        files = sorted(set(files) | {build(s) for s in sorted(sources)})
    orphans = [
        f"{s}: a source without its notebook {notebook_of(s)} (run `make format`)"
        for p in args.paths
        if p.is_dir()
        for s in sorted((p / SOURCES).glob("*.py"))
        if not notebook_of(s).exists()
    ]
    errs = orphans + [e for f in files for e in sync_problems(f) + problems(f, args.strip)]
    for e in errs:
        print(e)
    print(f"checked {len(files)} notebook(s): {'ok' if not errs else f'{len(errs)} problem(s)'}")
    return 1 if errs else 0


if __name__ == "__main__":
    sys.exit(main())
