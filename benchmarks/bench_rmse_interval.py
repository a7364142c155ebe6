"""Do the design's RMSE intervals over units cover? The RMSE's own (``rmse_ci95_m``), the radio's
gain over dead reckoning and an array's RMSE over a smaller one's on the same drives
(``tunnelkit.design.intervals``), against the percentile bootstrap over units the report gave
before.

On the bound route of ``example-rectangular-28ghz`` (the design's default impairments,
``"calibrated"``), two arrays on the same drives with dead reckoning beside them: a long
reference run (``--ref-units`` units x 2 drives, seed ``--ref-seed``) gives the reference RMSE of
each array, dead reckoning's, and their ratios; ``--blocks`` disjoint blocks of ``--units`` units
(one run on seed ``--seed``: different units, so independent blocks) give the intervals, and we
count how often each holds its reference. Each coverage with its Wilson 95 % interval (the blocks
are Bernoulli trials). The reference is itself an estimate (its own interval printed beside it).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_rmse_interval.py --units 4 6 12

A study script (no ``cases()``): nothing here is timed.
"""

from __future__ import annotations

import argparse
import time
from functools import partial

import numpy as np

SCENARIO = "example-rectangular-28ghz"
ARRAYS = ("4x4", "8x8")


def _boot(ms_num, ms_den, rng, n_boot: int) -> list[float]:
    """The percentile bootstrap over units of ``sqrt(mean ms_num / mean ms_den)`` (the same
    resampled units in both: paired), as the report computed the RMSE's interval before."""
    idx = rng.integers(0, ms_num.size, size=(n_boot, ms_num.size))
    r = np.sqrt(ms_num[idx].mean(axis=1) / ms_den[idx].mean(axis=1))
    return [float(v) for v in np.quantile(r, [0.025, 0.975], method="inverted_cdf")]


def study(units=(4, 6, 12), blocks=200, ref_units=1000, drives=2, ref_seed=9001, seed=1,
          n_boot=2000, workers=None) -> list[dict]:  # fmt: skip
    from tunnelkit.design import DesignSetup, path_error_model, preset_impairments, sweep_montecarlo
    from tunnelkit.design.intervals import paired_rmse_ratio, rmse_ci
    from tunnelkit.design.setup import parse_array
    from tunnelkit.design.units import unit_rmse, wilson_interval
    from tunnelkit.runner import trial_pool

    setup = DesignSetup.from_scenario(SCENARIO)
    imp = preset_impairments("calibrated", setup, [parse_array(a) for a in ARRAYS])
    kw = {"impairments": imp, "error_models": partial(path_error_model, impairments=imp),
          "mode": "bound", "dead_reckoning": True, "drives_per_unit": drives}  # fmt: skip
    big, small = ARRAYS[1], ARRAYS[0]
    out = []
    with trial_pool(workers) as pool:
        t0 = time.perf_counter()
        ref = sweep_montecarlo(setup, list(ARRAYS), ref_units * drives, ref_seed, pool=pool, **kw)
        runs = max(units) * blocks * drives
        run = sweep_montecarlo(setup, list(ARRAYS), runs, seed, pool=pool, **kw)
        print(f"Monte-Carlo: {time.perf_counter() - t0:.0f} s", flush=True)
    k = ref[big].settled

    def per_unit(res, block=None, n=None):
        u = {a: unit_rmse(res[a].errors, drives, k) for a in ARRAYS}
        u["dr"] = unit_rmse(res[big].dead_reckoning, drives, k)
        if block is not None:
            u = {a: v[block * n : (block + 1) * n] for a, v in u.items()}
        return u

    r = per_unit(ref)
    what = {  # name: (numerator, denominator), per-unit RMSEs
        f"RMSE {big}": (big, None),
        f"radio gain {big} (dead reckoning / tracker)": ("dr", big),
        f"{big} / {small} on the same drives": (big, small),
    }
    rng = np.random.default_rng([0xC1, seed])
    for name, (num, den) in what.items():
        one = np.ones(ref_units)
        ref_val, ref_ci = paired_rmse_ratio(r[num], one if den is None else r[den])
        for n in units:
            hits = {"t (reported)": 0, "percentile bootstrap": 0}
            for b in range(blocks):
                u = per_unit(run, b, n)
                d = np.ones(n) if den is None else u[den]
                ci_t = rmse_ci(u[num]) if den is None else paired_rmse_ratio(u[num], d)[1]
                ci_b = _boot(u[num] ** 2, d**2, rng, n_boot)
                hits["t (reported)"] += ci_t is not None and ci_t[0] <= ref_val <= ci_t[1]
                hits["percentile bootstrap"] += ci_b[0] <= ref_val <= ci_b[1]
            for how, h in hits.items():
                out.append({"what": name, "reference": ref_val, "reference_ci": ref_ci,
                            "units": n, "interval": how, "coverage": h / blocks,
                            "coverage_ci": wilson_interval(h, blocks)})  # fmt: skip
    return out


def table(rows, blocks: int, ref_units: int) -> str:
    lines = [
        f"| quantity | reference ({ref_units} units) | units per block | interval | coverage of "
        f"{blocks} blocks [Wilson 95 %] |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        lo, hi = r["reference_ci"]
        c0, c1 = r["coverage_ci"]
        lines.append(
            f"| {r['what']} | {r['reference']:.4g} [{lo:.4g}, {hi:.4g}] | {r['units']} | "
            f"{r['interval']} | {r['coverage']:.3f} [{c0:.3f}, {c1:.3f}] |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--units", type=int, nargs="+", default=[4, 6, 12])
    ap.add_argument("--blocks", type=int, default=200)
    ap.add_argument("--ref-units", type=int, default=1000)
    ap.add_argument("--ref-seed", type=int, default=9001)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=None)
    a = ap.parse_args(argv)
    rows = study(tuple(a.units), a.blocks, a.ref_units, ref_seed=a.ref_seed, seed=a.seed,
                 workers=a.workers)  # fmt: skip
    print(table(rows, a.blocks, a.ref_units))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
