"""How much of the package a use of it loads: the lines of every ``tunnelkit`` module imported.

    python tools/loaded_lines.py readme          # the README's examples (its doctests)
    python tools/loaded_lines.py notebook 05     # notebook 05's code, in quick mode
    python tools/loaded_lines.py readme --json   # the measurement as JSON

Each measurement runs in a fresh Python process with this checkout first on the path: ``readme``
runs the README's doctests as ``tests/test_readme.py`` does; ``notebook NN`` runs the code cells of
``notebooks/.src/NN-*.py`` one after the other in an IPython shell (cell magics included, so the
exercise solutions stay on demand as in Run All), from ``notebooks/``, with ``TUNNELKIT_QUICK=1``.
Then every module in ``sys.modules`` whose name is ``tunnelkit`` or starts with ``tunnelkit.`` is
counted by the lines of its source file. Printed: the total lines, the number of modules and the
largest modules loaded.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "tunnelkit"

#: the child's last step: the loaded modules of the package with their source files, as JSON
_REPORT = f"""
import json as _json, sys as _sys
_mods = {{n: getattr(m, "__file__", None) for n, m in list(_sys.modules.items())
          if n == {PACKAGE!r} or n.startswith({PACKAGE + "."!r})}}
print("\\nLOADED-MODULES " + _json.dumps({{"modules": _mods, "extra": _extra}}))
"""

_README = f"""
import doctest
_res = doctest.testfile({str(ROOT / "README.md")!r}, module_relative=False,
                        optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
_extra = {{"attempted": _res.attempted, "failed": _res.failed}}
"""

_NOTEBOOK = """
import jupytext
from IPython.core.interactiveshell import InteractiveShell

_nb = jupytext.read({src!r})
_shell = InteractiveShell.instance()
_failed = []
for _i, _cell in enumerate(c for c in _nb.cells if c.cell_type == "code"):
    _r = _shell.run_cell(_cell.source, store_history=False)
    if not _r.success:
        _failed.append(_i)
        break
_extra = {{"cells_failed": _failed}}
"""


def _run(code: str, *, cwd: Path, env: dict[str, str]) -> dict:
    full = dict(os.environ, **env)
    full["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    proc = subprocess.run(
        [sys.executable, "-c", code + _REPORT], cwd=cwd, env=full, capture_output=True, text=True
    )
    line = next(
        (ln for ln in reversed(proc.stdout.splitlines()) if ln.startswith("LOADED-MODULES ")), None
    )
    if proc.returncode != 0 or line is None:
        raise RuntimeError(
            f"the measured run failed (exit {proc.returncode}):\n{proc.stdout[-3000:]}\n"
            f"{proc.stderr[-3000:]}"
        )
    return json.loads(line.split(" ", 1)[1])


def _count(modules: dict[str, str | None]) -> dict:
    sizes = {}
    for name, file in modules.items():
        if file and file.endswith(".py") and Path(file).is_file():
            sizes[name] = len(Path(file).read_text().splitlines())
    outside = sorted(n for n, f in modules.items() if f and not f.startswith(str(ROOT)))
    if outside:
        raise RuntimeError(f"modules loaded from outside {ROOT}: {outside[:5]}")
    return {
        "lines": sum(sizes.values()),
        "modules": len(sizes),
        "sizes": dict(sorted(sizes.items(), key=lambda kv: (-kv[1], kv[0]))),
    }


def measure_readme() -> dict:
    """The README's doctests in a fresh process: the package's lines they load."""
    out = _run(_README, cwd=ROOT, env={})
    return {**_count(out["modules"]), **out["extra"]}


def notebook_source(nn: str) -> Path:
    found = sorted((ROOT / "notebooks" / ".src").glob(f"{nn}-*.py"))
    if len(found) != 1:
        raise SystemExit(f"notebook {nn!r}: expected one notebooks/.src/{nn}-*.py, found {found}")
    return found[0]


def measure_notebook(nn: str) -> dict:
    """A notebook's code cells in quick mode in a fresh process: the package's lines they load."""
    src = notebook_source(nn)
    code = _NOTEBOOK.format(src=str(src))
    out = _run(code, cwd=ROOT / "notebooks", env={"TUNNELKIT_QUICK": "1", "MPLBACKEND": "Agg"})
    if out["extra"]["cells_failed"]:
        raise RuntimeError(f"{src.name}: code cell {out['extra']['cells_failed'][0]} failed")
    return {**_count(out["modules"]), "notebook": src.name}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=["readme", "notebook"])
    ap.add_argument("nn", nargs="?", help="the notebook's number (notebook): 01, 04b, ...")
    ap.add_argument("--top", type=int, default=15, help="how many of the largest modules to list")
    ap.add_argument("--json", action="store_true", help="print the measurement as JSON")
    a = ap.parse_args(argv)
    if a.what == "notebook" and not a.nn:
        ap.error("notebook: give its number, e.g. 05")
    r = measure_readme() if a.what == "readme" else measure_notebook(a.nn)
    if a.json:
        print(json.dumps(r, indent=2))
        return 0
    label = "README examples" if a.what == "readme" else r["notebook"]
    print(f"{label}: {r['lines']} lines in {r['modules']} tunnelkit modules")
    if a.what == "readme":
        print(f"doctests: {r['attempted']} run, {r['failed']} failed")
    for name, n in list(r["sizes"].items())[: a.top]:
        print(f"  {n:6d}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
