"""Errors the tracker can trust on the ray-traced channel: the traced design told RMS sigmas
against one told robust sigmas, beside dead reckoning (:mod:`tunnelkit.studies.robust_errors`).

1. **Measure** (design seed): the traced design's own procedure
   (:func:`tunnelkit.studies.traced.measure_traced_errors`: ``--measure-runs`` condition-L drives
   of the straight preset on the ray-traced channel, seed 0, every epoch's ML measurements), its
   samples summarised twice: the RMS per quantity (what ``data/rt/traced_errors.json`` stores;
   checked equal here) and the robust sigma (``1.4826 MAD``), with the gross errors (beyond three
   robust sigmas) counted apart.
2. **Track**: Tables 1 and 2 (straight, slalom), condition L, ``--runs`` drives per seed (drive
   ``i`` from the ``i``-th child of the seed): seed 0, the design seed (its first straight
   drives share their draws with the measured ones), and the held-out seed, never used to
   measure or choose; the ``"ml-traced"`` measurements (the tables' traced column): JAVELIN with the RMS design, with the robust design, and dead reckoning (the same
   JAVELIN with every measurement dropped). 2-D RMSE per drive, mean over drives.
3. **Do the told sigmas match?** On the tracked drives' own matched errors: the robust sigma and
   the share of gross errors, beside the sigmas the designs were told.

    python benchmarks/bench_rt_robust.py --measure-runs 3 --runs 4
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.runner import run_trials
from tunnelkit.simulation import (
    HELD_OUT_SEED,
    error_correlations,
    error_samples,
    evaluate,
    without_radio,
)
from tunnelkit.simulation.analysis import extraction_errors
from tunnelkit.simulation.prefilter import NUISANCE, SIGMA_SCENARIO
from tunnelkit.studies.robust_errors import robust_design, robust_rows
from tunnelkit.studies.traced import simulate_traced, traced_errors
from tunnelkit.tracking.javelin import designs
from tunnelkit.tracking.javelin.measured import design_from_errors

TABLES = {"straight": "italiano2026-straight", "slalom": "italiano2026-slalom"}


def _measure_drive(cond, rng):
    return simulate_traced(
        SIGMA_SCENARIO, rng, condition=cond, channel="sionna", nuisance=NUISANCE
    )["ml-all"]


def _table_drive(scenario, cond, rng):
    return simulate_traced(scenario, rng, condition=cond, channel="sionna")["ml-traced"]


def _sigmas(design) -> str:
    c = design.config
    return (
        f"phi {np.degrees(c.sigma_phi):.3g} deg, psi {np.degrees(c.sigma_psi):.3g} deg, "
        f"kappa {c.sigma_kappa:.3g} m, Delta d {c.sigma_delta_d:.3g} m"
    )


def _print_rows(cols, rows):
    print("  " + " | ".join(cols))
    for r in rows:
        print("  " + " | ".join(f"{x:.3g}" if isinstance(x, float) else str(x) for x in r))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--measure-runs", type=int, default=3)
    ap.add_argument("--runs", type=int, default=4)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, HELD_OUT_SEED])
    ap.add_argument("--tables", nargs="+", default=list(TABLES), choices=list(TABLES))
    a = ap.parse_args(argv)

    t0 = time.perf_counter()
    measured = run_trials(_measure_drive, a.measure_runs, 0, inputs=["L"] * a.measure_runs)
    samples = error_samples(measured)
    corr = error_correlations(measured)
    cols, rms_rows = extraction_errors(measured)
    stored = {r[0]: r for r in traced_errors()["rows"]}
    gap = max(
        (
            abs(x - y) / max(abs(y), 1e-300)
            for r in rms_rows
            for x, y in zip(r[1:], stored.get(r[0], [None] * len(r))[1:], strict=True)
            if x is not None and y is not None
        ),
        default=float("inf"),
    )
    if set(stored) != {r[0] for r in rms_rows}:
        gap = float("inf")
    print(f"measured: {a.measure_runs} traced drives, seed 0 ({time.perf_counter() - t0:.0f} s)")
    print(f"RMS rows (largest relative difference from the stored record: {gap:.2g}):")
    _print_rows(cols, rms_rows)
    rcols, rrows, _ = robust_rows(samples)
    print("robust rows (median, robust sigma = 1.4826 MAD, gross beyond 3 sigma, RMS of the rest):")
    _print_rows(rcols, rrows)
    rms_design = design_from_errors(rms_rows, base=designs.ours_ml(), correlation=corr)
    rob_design = robust_design(samples, correlation=corr)
    print(f"told, RMS design   : {_sigmas(rms_design)}")
    print(f"told, robust design: {_sigmas(rob_design)}")

    print("\nJAVELIN-L, traced column (ML route, geometry test), 2-D RMSE [m], mean over drives:")
    print(
        "  table | seed | drives | RMS design | robust design | dead reckoning | gain RMS | gain robust"
    )
    held = []
    for table in a.tables:
        for seed in a.seeds:
            t1 = time.perf_counter()
            drives = run_trials(
                lambda c, rng, s=TABLES[table]: _table_drive(s, c, rng),
                a.runs,
                seed,
                inputs=["L"] * a.runs,
            )
            res = {"rms": [], "robust": [], "dr": []}
            for d in drives:
                res["rms"].append(evaluate(d, rms_design).metrics["rmse_2d_m"])
                res["robust"].append(evaluate(d, rob_design).metrics["rmse_2d_m"])
                none = without_radio(d)
                res["dr"].append(evaluate(none, rms_design).metrics["rmse_2d_m"])
            m = {k: float(np.mean(v)) for k, v in res.items()}
            print(
                f"  {table} | {seed} | {a.runs} | {m['rms']:.3f} | {m['robust']:.3f} | "
                f"{m['dr']:.3f} | {m['dr'] / m['rms']:.2f}x | {m['dr'] / m['robust']:.2f}x "
                f"({time.perf_counter() - t1:.0f} s)"
            )
            if seed != 0:
                held += drives
    if held:
        hc, hrows, _ = robust_rows(error_samples(held))
        print("\nthe tracked held-out drives' own errors (after the geometry test):")
        _print_rows(hc, [hrows[-1]])
    print(f"\nwall {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
