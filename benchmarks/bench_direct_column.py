"""The direct column of Tables 1-2 on the ray-traced channel, alone: the same drives as
``tunnelkit reproduce javelin-table1|2 --channel sionna --runs R --seed S`` gives that column.

The table's drive ``i`` (run ``i // n``, condition ``i % n`` of its ``n`` conditions) draws from
the ``i``-th child of the seed; a condition-L trial (condition 0 of both tables) runs the direct
column's drive from a generator spawned from its own
(:func:`tunnelkit.reproduce.javelin_direct.direct_scores`). This script draws the same
generators and runs only that drive, without the table's other columns (a third to a quarter of
the table's cost): per drive JAVELIN's and its dead reckoning's 2-D RMSE, their means (the
table's cells) and the ratio per drive with a 90 % bootstrap interval.

    python benchmarks/bench_direct_column.py --table 1 --seed 20261202 --runs 20
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from tunnelkit.montecarlo import spawn_rngs
from tunnelkit.reproduce.javelin_direct import direct_scores

#: the table -> (scenario, its number of conditions per run; condition L first)
TABLES = {1: ("italiano2026-straight", 4), 2: ("italiano2026-slalom", 3)}


def one(scenario: str, n_conditions: int, seed: int, run: int, n_epochs):
    trial = spawn_rngs(seed, n_conditions * run + 1)[-1]  # as run_trials draws drive i
    t0 = time.perf_counter()
    scores, (dropped, epochs) = direct_scores(scenario, n_epochs, trial.spawn(1)[0])
    return run, scores, dropped, epochs, time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--table", type=int, choices=sorted(TABLES), required=True)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--n-epochs", type=int, default=None)
    a = ap.parse_args(argv)
    scenario, n = TABLES[a.table]
    t0 = time.perf_counter()
    res = [None] * a.runs
    with ProcessPoolExecutor(a.workers) as ex:
        futs = [ex.submit(one, scenario, n, a.seed, i, a.n_epochs) for i in range(a.runs)]
        for f in futs:
            i, scores, dropped, epochs, sec = f.result()
            res[i] = (scores["JAVELIN"]["rmse_2d_m"], scores["dead reckoning"]["rmse_2d_m"])
            print(f"  run {i}: {sec:.0f} s, JAVELIN {res[i][0]:.3f} m, dead reckoning "
                  f"{res[i][1]:.3f} m, epochs without a fix {dropped} of {epochs}", flush=True)  # fmt: skip
    jav, dr = np.array(res).T
    ratio = jav / dr
    rng = np.random.default_rng(12345)
    boot = [np.mean(ratio[rng.integers(0, ratio.size, ratio.size)]) for _ in range(2000)]
    lo, hi = np.quantile(boot, [0.05, 0.95])
    print(f"\nTable {a.table} ({scenario}), seed {a.seed}, {a.runs} runs, the direct column's "
          f"JAVELIN-L: mean RMSE {jav.mean():.3f} m, its dead reckoning {dr.mean():.3f} m "
          f"(gain {dr.mean() / jav.mean():.2f}x); ratio per run {ratio.mean():.2f} "
          f"[{lo:.2f}, {hi:.2f}]; runs above 1: {int(np.sum(ratio > 1))}; "
          f"{time.perf_counter() - t0:.0f} s")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
