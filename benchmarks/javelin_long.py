"""``tunnelkit reproduce javelin-table1 --length L`` drive by drive, resumable.

The reproduce target runs all ``runs x 4`` drives in one call and reports at the end; a 120 m
drive takes minutes on a loaded machine, so 20 runs may not finish in one sitting. Here each drive
(run ``r``, condition ``c``: drive ``i = 4 r + c``, drawn from the ``i``-th child of the seed,
exactly as :func:`tunnelkit.runner.run_trials` draws it, with one BLAS thread as there) is simulated and scored alone and its
result saved to ``DIR/seed<S>/drive<i>.pkl``; ``--report`` assembles the table from the whole runs
saved so far. The table of ``k`` whole runs is the one ``tunnelkit reproduce javelin-table1
--length L --runs k --seed S`` prints (same drives, same aggregation).

    python benchmarks/javelin_long.py --seed 0 --runs 20 --dir /tmp/jl     # simulate (resumes)
    python benchmarks/javelin_long.py --seed 0 --report --dir /tmp/jl      # the table so far
"""

from __future__ import annotations

import argparse
import json
import pickle
import time
from pathlib import Path

from threadpoolctl import threadpool_limits

from tunnelkit.montecarlo import spawn_rngs
from tunnelkit.reproduce import javelin_tables as jt
from tunnelkit.simulation.drives import route_name

SCENARIO, REFERENCE = "italiano2026-straight", "italiano2026_table1"
CONDITIONS = ("L", "N@0.5", "N", "NoRRMs")
EXTRACTIONS = tuple(route_name(e) for e in ("paper", "ml"))


def drive(seed: int, i: int, length: float | None, n_epochs: int | None = None):
    """Drive ``i`` of ``seed`` (condition ``CONDITIONS[i % 4]``), scored: ``(scores, faults)``."""
    rng = spawn_rngs(seed, i + 1)[i]
    cond = CONDITIONS[i % len(CONDITIONS)]
    cols = jt.table_columns(EXTRACTIONS)
    with threadpool_limits(limits=1, user_api="blas"):  # as every trial of run_trials
        return cond, jt._simulate_and_score(
            SCENARIO, n_epochs, EXTRACTIONS, cols, cond, rng, length=length
        )


def simulate(seed: int, runs: int, length: float, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for i in range(runs * len(CONDITIONS)):
        f = out / f"drive{i}.pkl"
        if f.exists():
            continue
        t0, c0 = time.perf_counter(), time.process_time()
        res = drive(seed, i, length)
        tmp = f.with_suffix(".tmp")
        tmp.write_bytes(pickle.dumps(res))
        tmp.rename(f)
        print(
            f"seed {seed} drive {i} ({res[0]}): {time.perf_counter() - t0:.0f} s wall, "
            f"{time.process_time() - c0:.0f} s CPU, faults {res[1][1]}",
            flush=True,
        )


def report(seed: int, length: float, out: Path, fmt: str = "text") -> str:
    n = len(CONDITIONS)
    done = []
    i = 0
    while all((out / f"drive{j}.pkl").exists() for j in range(i, i + n)):
        done += [pickle.loads((out / f"drive{j}.pkl").read_bytes()) for j in range(i, i + n)]
        i += n
    if not done:
        return f"seed {seed}: no whole run saved yet in {out}"
    rep = jt._report(SCENARIO, REFERENCE, CONDITIONS, EXTRACTIONS, done, "image", None, length, {})
    rep.meta = {"target": "javelin-table1", "runs": i // n, "seed": seed, **rep.meta}
    return rep.to_json() if fmt == "json" else rep.to_table() + "\n" + json.dumps(rep.meta)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--length", type=float, default=120.0)
    ap.add_argument("--dir", default="javelin_long")
    ap.add_argument("--report", action="store_true")
    ap.add_argument("--format", default="text", choices=("text", "json"))
    a = ap.parse_args()
    d = Path(a.dir) / f"seed{a.seed}"
    if a.report:
        print(report(a.seed, a.length, d, a.format))
    else:
        simulate(a.seed, a.runs, a.length, d)
