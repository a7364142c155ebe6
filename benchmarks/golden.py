"""Golden regression of the command line: every ``tunnelkit reproduce`` target and
``tunnelkit design --units 2`` (two units of two drives), on two seeds, written as JSON and compared byte for byte.

A refactor that must not change a number is checked like this::

    python benchmarks/golden.py --write /tmp/before     # on the commit before the change
    python benchmarks/golden.py --compare benchmarks/golden   # after: exit 1 on any difference

``benchmarks/golden/`` holds the files of the last accepted layout; ``--write`` without a
directory rewrites them. The cases are small (a few runs each) so the whole set takes minutes;
``--only SUBSTRING`` runs the matching cases alone.

Byte for byte holds on one machine; another CPU's BLAS kernels move the last digits (1e-14
relative, seen between two x86-64 CPUs with the same wheels). ``--rtol R`` then compares the JSON
as values: same keys, strings and shapes, numbers within ``R`` relative (and 1e-12 absolute, for
values that are zero on one side). The unit test uses ``--rtol 1e-9``; a refactor uses bytes.
"""

from __future__ import annotations

import argparse
import difflib
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SEEDS = (0, 20261202)

#: the design cases' Monte-Carlo: two units of two drives, one batch (no sequential rule)
DESIGN_UNITS = ["--units", "2", "--drives-per-unit", "2", "--max-units", "2"]

# (name, arguments after `tunnelkit`); seed appended per case
CASES = [
    ("jiang-crlb", ["reproduce", "jiang-crlb", "--runs", "300"]),
    ("jiang-table2", ["reproduce", "jiang-table2", "--runs", "2"]),
    ("jiang-table3", ["reproduce", "jiang-table3", "--runs", "2"]),
    ("halili", ["reproduce", "halili", "--runs", "3"]),
    ("javelin-table1", ["reproduce", "javelin-table1", "--runs", "2"]),
    ("javelin-table2", ["reproduce", "javelin-table2", "--runs", "2"]),
    (
        "design-28ghz",
        ["design", "example-rectangular-28ghz", "--arrays", "4x4", "8x8", *DESIGN_UNITS],
    ),
    (
        "design-paper",
        ["design", "italiano2026-straight", "--arrays", "4x4", "10x10", *DESIGN_UNITS],
    ),
]


def case_files(only: str | None):
    for name, args in CASES:
        for seed in SEEDS:
            key = f"{name}-seed{seed}"
            if only and only not in key:
                continue
            yield key, [*args, "--seed", str(seed), "--format", "json", "--no-progress"]


def same_values(a, b, rtol: float) -> bool:
    """``a`` and ``b`` (parsed JSON) equal up to ``rtol`` in their numbers."""
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return math.isclose(a, b, rel_tol=rtol, abs_tol=1e-12)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_values(a[k], b[k], rtol) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same_values(x, y, rtol) for x, y in zip(a, b))
    return a == b


def run_case(args: list[str]) -> str:
    env = dict(os.environ, PYTHONHASHSEED="0")
    # `python -m tunnelkit` from the repository root: the checkout's package, not an install
    out = subprocess.run(
        [sys.executable, "-m", "tunnelkit", *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if out.returncode != 0:
        raise SystemExit(f"tunnelkit {' '.join(args)} failed ({out.returncode}):\n{out.stderr}")
    return out.stdout


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--write", nargs="?", const=str(HERE / "golden"), metavar="DIR")
    g.add_argument("--compare", metavar="DIR")
    ap.add_argument("--only", default=None)
    ap.add_argument("--rtol", type=float, default=None, help="compare numbers within RTOL")
    a = ap.parse_args(argv)
    target = Path(a.write or a.compare)
    target.mkdir(parents=True, exist_ok=True)
    bad = 0
    for key, args in case_files(a.only):
        t0 = time.perf_counter()
        text = run_case(args)
        dt = time.perf_counter() - t0
        path = target / f"{key}.json"
        if a.write:
            path.write_text(text)
            print(f"wrote {path.name} ({dt:.1f} s)", flush=True)
            continue
        old = path.read_text() if path.exists() else ""
        if old == text:
            print(f"identical {key} ({dt:.1f} s)", flush=True)
        elif a.rtol is not None and old and same_values(json.loads(old), json.loads(text), a.rtol):
            print(f"identical {key} within rtol {a.rtol:g} ({dt:.1f} s)", flush=True)
        else:
            bad += 1
            print(f"DIFFERENT {key} ({dt:.1f} s)", flush=True)
            diff = difflib.unified_diff(old.splitlines(), text.splitlines(), "golden", "now", n=1)
            print("\n".join(list(diff)[:40]))
    if a.compare:
        print(f"{bad} case(s) differ" if bad else "all cases identical")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
