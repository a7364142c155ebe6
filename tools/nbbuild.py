"""Write a notebook from a plain-text source with ``# %% [markdown]`` / ``# %%`` cell markers.

Authors keep the readable source under ``notebooks/src/NN-name.py`` and run
``python tools/nbbuild.py notebooks/src/NN-name.py`` to (re)write ``notebooks/NN-name.ipynb``
without outputs. ``make test`` checks that every notebook matches its source.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

KERNEL = {"display_name": "Python (tunnelkit)", "language": "python", "name": "python3"}


def parse(text: str) -> list[dict]:
    cells, kind, buf = [], None, []

    def flush():
        if kind is None:
            return
        src = "\n".join(buf).strip("\n")
        if kind == "markdown":
            src = "\n".join(
                line[2:] if line.startswith("# ") else line.lstrip("#") for line in src.splitlines()
            )
        if src.strip():
            cell = {"cell_type": kind, "metadata": {}, "source": src.splitlines(keepends=True)}
            if kind == "code":
                cell.update(outputs=[], execution_count=None)
            cells.append(cell)

    for line in text.splitlines():
        if line.startswith("# %%"):
            flush()
            kind, buf = ("markdown" if "[markdown]" in line else "code"), []
        else:
            buf.append(line)
    flush()
    return cells


def build(src: Path) -> str:
    nb = {
        "cells": parse(src.read_text()),
        "metadata": {"kernelspec": KERNEL, "language_info": {"name": "python"}},
        "nbformat": 4,
        "nbformat_minor": 5,
    }
    for i, c in enumerate(nb["cells"]):
        c["id"] = f"{src.stem[:2]}-{i:03d}"
    return json.dumps(nb, indent=1, ensure_ascii=False) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sources", nargs="*", type=Path)
    ap.add_argument(
        "--check", action="store_true", help="fail if a notebook differs from its source"
    )
    args = ap.parse_args(argv)
    srcs = args.sources or sorted(Path("notebooks/src").glob("*.py"))
    bad = 0
    for s in srcs:
        target = s.parent.parent / f"{s.stem}.ipynb"
        text = build(s)
        if args.check:
            if not target.exists() or target.read_text() != text:
                print(f"{target}: out of date with {s} (run python tools/nbbuild.py {s})")
                bad += 1
        else:
            target.write_text(text)
            print(f"wrote {target}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
