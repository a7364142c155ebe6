"""The traced design with one noise per kind of path, against the pooled noise (a negative result).

On the ray-traced channel the ML route's errors differ by kind of path: the stored record
(``data/rt/traced_errors.json``, straight drive, seed 0, condition L) has the LoS at 2.1 / 2.6 deg
and 0.20 m of TDoA, the road bounce at 12.8 / 16.0 deg and 1.6 m, pooled 9.4 / 8.5 deg and 1.09 m.
The traced design uses the pooled row. Here the tracker instead takes each path's row from the
kind of surface the geometry pre-filter assigned it
(:func:`tunnelkit.simulation.prefilter.geometry_labels`, ``PathMeasurements.kind``,
:class:`tunnelkit.tracking.javelin.KindNoise`, ``design_from_errors(per_kind=True)``), with the
rows measured on every epoch (the record) or on the epochs the pre-filter passes.

Prints how often the assigned kind is the true one (the measurement drives: children 0..2 of
seed 0, condition L, which the record was measured on) and the JAVELIN-L 2-D RMSE of the four
noise models on ``--runs`` held-out drives per table (seed 20261202, Tables 1 and 2, the drives
``bench_rt_javelin.py`` runs). Traced drives come from the ray-tracing cache (about 30 s each
with it, minutes without).

    nice python benchmarks/bench_rt_kind_noise.py --runs 4
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections import Counter
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.montecarlo import spawn_rngs
from tunnelkit.simulation.analysis import extraction_errors
from tunnelkit.simulation.prefilter import NUISANCE
from tunnelkit.simulation.scoring import evaluate
from tunnelkit.studies.traced import simulate_traced, traced_design, traced_errors
from tunnelkit.tracking.javelin import designs

TABLES = {"1": ("italiano2026-straight", 4), "2": ("italiano2026-slalom", 3)}  # conditions
HELD_OUT = 20261202


def _drive(scenario: str, seed: int, i: int):
    with threadpool_limits(limits=1, user_api="blas"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate_traced(
            scenario, spawn_rngs(seed, i + 1)[i], condition="L", channel="sionna",
            nuisance=NUISANCE,
        )["ml-traced"]  # fmt: skip


def label_counts(drives) -> Counter:
    """(true kind, assigned kind) of every matched measurement the pre-filter kept."""
    out: Counter = Counter()
    for d in drives:
        for k, m in enumerate(d.epochs):
            if m is None or m.kind is None:
                continue
            ti = np.asarray(d.truth_index[k])
            for j in np.flatnonzero(ti >= 0):
                out[(d.kinds[k][ti[j]], str(m.kind[j]))] += 1
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=4, help="held-out L drives per table")
    args = ap.parse_args(argv)
    sigma = [_drive("italiano2026-straight", 0, i) for i in range(3)]
    counts = label_counts(sigma)
    n = sum(counts.values())
    right = sum(v for (t, a), v in counts.items() if t == a)
    print(f"assigned kind = true kind: {right} of {n} ({100 * right / n:.0f} %)")
    for (t, a), v in counts.most_common():
        print(f"  true {t:8s} assigned {a:8s} {v}")
    rec = traced_errors()["rows"]
    _, kept_rows = extraction_errors(sigma)
    base = designs.ours_ml()
    models = {
        "pooled, every epoch (the traced design)": traced_design(),
        "per kind, every epoch": designs.design_from_errors(rec, base=base, per_kind=True),
        "pooled, pre-filtered": designs.design_from_errors(kept_rows, base=base),
        "per kind, pre-filtered": designs.design_from_errors(kept_rows, base=base, per_kind=True),
    }
    print(f"\nJAVELIN-L 2-D RMSE [m], seed {HELD_OUT}, {args.runs} drives per table")
    print(f"{'noise model':42s} {'Table 1':>8s} {'Table 2':>8s}")
    rmse: dict = {k: {} for k in models}
    for t, (scenario, n_cond) in TABLES.items():
        for r in range(args.runs):
            d = _drive(scenario, HELD_OUT, n_cond * r)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                for name, des in models.items():
                    rmse[name].setdefault(t, []).append(evaluate(d, des).metrics["rmse_2d_m"])
    for name, v in rmse.items():
        print(f"{name:42s} {np.mean(v['1']):8.3f} {np.mean(v['2']):8.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
