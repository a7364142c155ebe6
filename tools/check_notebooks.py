"""Check (or with --strip, enforce) the notebook conventions.

* committed without outputs or execution counts;
* the first code cell imports tunnelkit and calls ``tk.setup_notebook()``;
* a markdown cell headed "Checks" followed by code that asserts.
Exit status 1 with one line per problem.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def problems(path: Path, strip: bool) -> list[str]:
    nb = json.loads(path.read_text())
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
    if not heads:
        out.append(f"{path}: no markdown cell headed 'Checks'")
    elif not any(
        "assert" in "".join(c["source"]) for c in cells[heads[-1] :] if c.get("cell_type") == "code"
    ):
        out.append(f"{path}: the Checks section has no assert")
    if changed:
        path.write_text(json.dumps(nb, indent=1, ensure_ascii=False) + "\n")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="+", type=Path)
    ap.add_argument("--strip", action="store_true", help="remove outputs in place")
    args = ap.parse_args(argv)
    files = [f for p in args.paths for f in (sorted(p.glob("*.ipynb")) if p.is_dir() else [p])]
    errs = [e for f in files for e in problems(f, args.strip)]
    for e in errs:
        print(e)
    print(f"checked {len(files)} notebook(s): {'ok' if not errs else f'{len(errs)} problem(s)'}")
    return 1 if errs else 0


if __name__ == "__main__":
    sys.exit(main())
