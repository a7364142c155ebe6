"""A model that absorbs what eq. 1 misses: first-order pseudo-true bias on the ray-traced channel
under eq. 1, an amplitude profile across the aperture and second-order nuisance atoms, and what
the profile costs on eq. 1's own tensor (:mod:`tunnelkit.studies.nuisance`).

    python benchmarks/bench_traced_models.py --array 8x8 --epochs 0 5 10 15 20 25 --traced-draws 2
    python benchmarks/bench_traced_models.py --array 4x4 --only eq1-cost --draws 20 --seed 7
"""

from __future__ import annotations

import argparse
import dataclasses
import shlex
import sys
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.studies.nuisance import MODELS, eq1_cost, traced_bias


def _table(rows) -> str:
    if not rows:
        return ""
    names = [f.name for f in dataclasses.fields(rows[0])]
    out = ["| " + " | ".join(names) + " |", "|" + " --- |" * len(names)]
    for r in rows:
        cells = [f"{v:.3g}" if isinstance(v, float) else str(v) for v in dataclasses.astuple(r)]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--array", default="8x8")
    ap.add_argument("--epochs", type=int, nargs="+", default=[0, 5, 10, 15, 20, 25])
    ap.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    ap.add_argument("--only", choices=("traced", "eq1-cost"), default=None)
    ap.add_argument("--draws", type=int, default=20, help="noisy snapshots per epoch (eq1-cost)")
    ap.add_argument("--traced-draws", type=int, default=2,
                    help="noisy snapshots per epoch on the traced channel (0: the bias alone)")  # fmt: skip
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--predicted-sigma", type=float, default=0.1,
                    help="visibility models: the noisy fit starts every atom at the model of a "
                    "position drawn this far [m] from the truth (a tracker's prediction)")  # fmt: skip
    ap.add_argument("--cache-dir", default=None)
    a = ap.parse_args(argv)
    shape = tuple(int(x) for x in a.array.lower().split("x"))
    print("command: python benchmarks/bench_traced_models.py " + shlex.join(argv or sys.argv[1:]))
    with threadpool_limits(limits=1, user_api="blas"):
        if a.only in (None, "traced"):
            t0 = time.perf_counter()
            rows = traced_bias(a.scenario, array=shape, epochs=a.epochs, models=a.models,
                               draws=a.traced_draws, rng=np.random.default_rng(a.seed),
                               cache_dir=a.cache_dir, progress=True,
                               predicted_sigma=a.predicted_sigma)  # fmt: skip
            print(f"\n## traced channel, {a.array}, epochs {a.epochs} "
                  f"({time.perf_counter() - t0:.0f} s)\n\n{_table(rows)}\n")  # fmt: skip
        if a.only in (None, "eq1-cost"):
            t0 = time.perf_counter()
            rows = eq1_cost(a.scenario, array=shape, epochs=a.epochs, draws=a.draws,
                            rng=np.random.default_rng(a.seed))  # fmt: skip
            print(f"\n## eq. 1's tensor, {a.array}, epochs {a.epochs}, {a.draws} draws, seed "
                  f"{a.seed} ({time.perf_counter() - t0:.0f} s)\n\n{_table(rows)}\n")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
