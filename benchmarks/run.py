"""Benchmark runner: ``make bench`` (or ``python benchmarks/run.py [-k PATTERN] [--json FILE]``).

Every timed ``benchmarks/bench_*.py`` defines ``cases() -> list[Case]`` (and may define
``report() -> str``, an accuracy table printed after the timings). A ``bench_*.py`` without
``cases()`` is a study script run on its own (``python benchmarks/bench_rt_track.py --help``): the
runner lists it and does not import it. Each case is timed with
``timeit`` (repeats after a warm-up); we report the median and the interquartile range, and within
a ``group`` the ratio of every case to the group's ``baseline`` case, all measured in the same run.
Benchmarks are not tests: nothing here asserts a time.
"""

from __future__ import annotations

import argparse
import ast
import importlib.util
import json
import statistics
import sys
import timeit
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent


@dataclass
class Case:
    """One timed callable. ``number`` calls per repeat; ``goal_s`` is informational only;
    ``warmup=False`` skips the untimed first call (for whole commands run in a fresh process)."""

    name: str
    fn: Callable[[], object]
    group: str = ""
    baseline: bool = False
    repeat: int = 15
    number: int = 1
    goal_s: float | None = None
    warmup: bool = True


def is_timed(path: Path) -> bool:
    """True when the module at ``path`` defines a top-level ``cases()`` (a study script does not)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return any(isinstance(n, ast.FunctionDef) and n.name == "cases" for n in tree.body)


def _load_cases(pattern: str | None, where: Path = HERE) -> list[Case]:
    cases: list[Case] = []
    for path in sorted(where.glob("bench_*.py")):
        if not is_timed(path):
            continue
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[path.stem] = mod
        spec.loader.exec_module(mod)
        for c in mod.cases():
            c.group = c.group or path.stem.removeprefix("bench_")
            if pattern is None or pattern in c.name or pattern in c.group:
                cases.append(c)
    return cases


def study_scripts(where: Path = HERE) -> list[str]:
    """The ``bench_*.py`` study scripts (no ``cases()``), run on their own."""
    return [p.name for p in sorted(where.glob("bench_*.py")) if not is_timed(p)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "-k", dest="pattern", default=None, help="only cases whose name or group contains this"
    )
    ap.add_argument("--json", default="build/bench.json", help="where to write the results")
    args = ap.parse_args(argv)
    results = []
    for c in _load_cases(args.pattern):
        if c.warmup:
            c.fn()  # warm-up (imports, caches, JIT of BLAS paths)
        times = [t / c.number for t in timeit.repeat(c.fn, repeat=c.repeat, number=c.number)]
        q = statistics.quantiles(times, n=4) if len(times) >= 4 else [min(times), 0, max(times)]
        results.append(
            {
                "group": c.group,
                "name": c.name,
                "median_s": statistics.median(times),
                "q1_s": q[0],
                "q3_s": q[2],
                "repeat": c.repeat,
                "baseline": c.baseline,
                "goal_s": c.goal_s,
            }
        )
    base = {r["group"]: r["median_s"] for r in results if r["baseline"]}
    print(f"{'group':18s} {'case':46s} {'median':>11s} {'IQR':>19s} {'ratio':>8s}  goal")
    for r in results:
        ratio = r["median_s"] / base[r["group"]] if r["group"] in base else None
        r["ratio_to_baseline"] = ratio
        iqr = f"{r['q1_s'] * 1e3:8.3f}-{r['q3_s'] * 1e3:8.3f} ms"
        goal = (
            ""
            if r["goal_s"] is None
            else f"< {r['goal_s'] * 1e3:g} ms "
            + ("met" if r["median_s"] < r["goal_s"] else "MISSED")
        )
        rs = f"{ratio:8.3f}" if ratio is not None else " " * 8
        print(f"{r['group']:18s} {r['name']:46s} {r['median_s'] * 1e3:8.3f} ms {iqr} {rs}  {goal}")
    for rep in _load_reports(args.pattern):
        print()
        print(rep())
    out = Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(results, indent=2))
    print(f"\nwritten {out}")
    studies = study_scripts()
    if studies:
        print(f"study scripts, not timed here (run each on its own): {', '.join(studies)}")
    return 0


def _load_reports(pattern: str | None) -> list[Callable[[], str]]:
    """``report() -> str`` of the benchmark modules that define one (accuracy tables measured
    alongside the timings, e.g. estimator error over its bound); filtered like the cases."""
    out = []
    for path in sorted(HERE.glob("bench_*.py")):
        mod = sys.modules.get(path.stem)
        group = path.stem.removeprefix("bench_")
        if mod is not None and hasattr(mod, "report") and (pattern is None or pattern in group):
            out.append(mod.report)
    return out


if __name__ == "__main__":
    sys.exit(main())
