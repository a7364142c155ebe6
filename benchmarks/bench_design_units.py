"""The design's Monte-Carlo by manufactured units: are the bounds below the tracker, and do the
reported intervals cover?

Two studies on the bound route of ``example-rectangular-28ghz`` (8 x 6 m tunnel, 28 GHz), each
unit one calibration draw shared by its drives (:mod:`tunnelkit.design.units`):

1. **Bounds vs the tracker** (:func:`bound_matrix`): arrays 4x4, 8x8, 16x16 x phase error
   {0.5, 2} deg x gain error {0, 0.2} dB and the design's default
   (``"calibrated"``: 1.5 deg, 0.25 dB, diffuse power, spatial wideband), on seeds the design was never tuned on (101, 202),
   ``--units`` units x ``--drives`` drives each in one batch (``design_sweep`` with
   ``max_units = units``: no sequential rule), optionally on moved mounts too (``--tunnels``,
   e.g. ``mount_height=5.0`` or ``tilt_deg=10``). Per cell the tracker's pooled settled RMSE,
   RMSE / hybrid bound (posterior CRLB pooled over units, the bound of the pooled RMSE) and
   RMSE / PCRLB (every unit's posterior CRLB, a bound of each unit's expected mean-square error,
   hence of the pooled one), each with the 95 % interval of the RMSE bootstrapped over units;
   the smallest unit's RMSE / PCRLB from its two drives (a sample: it can fall below 1 by
   chance, part 3 measures units on many drives) and RMSE / predicted drive error (a
   first-order prediction, not a bound: either side of 1 is allowed). A bound is beaten where
   its ratio's interval lies below 1. The failures are listed after the table.
2. **Coverage of the reported intervals** (:func:`coverage`): for 8x8 and 16x16 x impairment
   level (``--levels``: a phase error alone in deg, or the design's default ``calibrated``) at
   target 0.1 m, a long reference run (``--ref-units`` units x 2 drives, seed ``--ref-seed``)
   gives the reference pooled p90 and unit yield; ``--blocks`` short runs of ``--block-units``
   units x 2 drives (disjoint blocks of one ``sweep_montecarlo`` call on seed ``--seed``:
   different units, so independent runs) count how often the reported 95 % interval of the
   pooled p90 (Woodruff's over units, ``design.cluster_quantile_ci``), the percentile bootstrap
   over units, and the Wilson interval of the unit yield hold the reference. With ``--old`` also
   the intervals reported before: drives with a calibration draw each, bootstrapped over drives
   (against that setting's own long run), and the D=2 blocks bootstrapped over drives (ignoring
   the unit). Each measured coverage with its Wilson 95 % interval (the blocks are Bernoulli
   trials), and how many intervals missed low (below the reference) or high.

3. **Each unit against the PCRLB** (:func:`unit_bounds`): 12 units x 25 drives of the 8x8 under
   the calibrated default: each unit's RMSE over its own drives / PCRLB, beside the two-drive
   and single-drive figures.

The tables are printed and written to ``--out`` (``units_bounds[_TAG].md``,
``units_coverage[_TAG].md``); ``--quick`` is a smoke test (one impairment, 10 units, 5 blocks),
not a measurement. Serial, a drive costs about 0.1 s of one core (40 epochs): part 1 is about
1,800 drives per tunnel, part 2 about ``2 * ref_units + 40 * blocks`` drives per array and level
(twice with ``--old``); two serial processes, one per ``--levels``, use both cores:

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_design_units.py --quick
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_design_units.py --part 1 --tunnels base \
        mount_height=5.0
    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_design_units.py --part 2 --levels 2 \
        --ref-units 1000 --blocks 60 --seed 1 --tag ph2
"""

from __future__ import annotations

import argparse
import itertools
import time
from functools import partial
from pathlib import Path

import numpy as np

SCENARIO = "example-rectangular-28ghz"
ARRAYS = ("4x4", "8x8", "16x16")
PHASES_DEG = (0.5, 2.0)
GAINS_DB = (0.0, 0.2)
SEEDS = (101, 202)
COVERAGE_ARRAYS = ("8x8", "16x16")
TARGET_M = 0.1
SHARE = 0.9


def _setup(tunnel: str):
    """The design setup of ``tunnel``: ``"base"`` or ``"key=value"`` of ``from_scenario``."""
    from tunnelkit.design import DesignSetup

    if tunnel == "base":
        return DesignSetup.from_scenario(SCENARIO)
    key, value = tunnel.split("=")
    return DesignSetup.from_scenario(SCENARIO, **{key: float(value)})


def bound_matrix(
    tunnels=("base",),
    arrays=ARRAYS,
    phases=PHASES_DEG,
    gains=GAINS_DB,
    seeds=SEEDS,
    units: int = 30,
    drives: int = 2,
    workers: int | None = None,
    calibrated: bool = True,
) -> list[dict]:
    """Part 1: one ``design_sweep`` per tunnel x impairment x seed (every array in it); with
    ``calibrated`` also the design's default impairment set (``"calibrated"``: phase, gain,
    diffuse power and the spatial-wideband term), shown with phase ``cal``."""
    from tunnelkit.design import design_sweep

    imps = [({"phase_error_deg": ph, "gain_error_db": g}, ph, g) for ph in phases for g in gains]
    if calibrated:
        imps.append(("calibrated", "cal", "cal"))
    out = []
    for tunnel, (imp, ph, g), seed in itertools.product(tunnels, imps, seeds):
        t0 = time.perf_counter()
        rep = design_sweep(
            _setup(tunnel),
            list(arrays),
            target=TARGET_M,
            impairments=imp,
            units=units,
            drives_per_unit=drives,
            max_units=units,
            seed=seed,
            mode="bound",
            workers=workers,
        )
        dt = time.perf_counter() - t0
        for r in rep.rows:
            hy, lo_hi = r.hybrid_bound_rms_m, r.rmse_ci95_m
            out.append(
                {
                    "tunnel": tunnel,
                    "array": r.array,
                    "phase": ph,
                    "gain": g,
                    "seed": seed,
                    "units": r.units,
                    "drives": r.drives_per_unit,
                    "rmse": r.rmse_m,
                    "rmse_ci": lo_hi,
                    "hybrid": hy,
                    "r_hy": r.rmse_over_hybrid_bound,
                    "r_hy_ci": None if hy is None or lo_hi is None else [v / hy for v in lo_hi],
                    "pcrlb": r.pcrlb_rms_m,
                    "r_pc": r.rmse_over_pcrlb,
                    "r_pc_unit_min": r.unit_rmse_over_pcrlb_min,
                    "r_pc_ci": None
                    if r.pcrlb_rms_m is None or lo_hi is None
                    else [v / r.pcrlb_rms_m for v in lo_hi],
                    "r_pred": r.rmse_over_predicted_drive,
                    "p90": r.error_p90_m,
                    "p90_ci": r.error_p90_ci95_m,
                    "yield": r.unit_yield,
                    "yield_ci": r.unit_yield_ci95,
                    "status": r.status,
                    "reason": r.reason,
                    "seconds": dt / len(rep.rows),
                }
            )
    return out


def bound_failures(rows) -> list[str]:
    """Every cell where a figure called a bound is above the tracker's error."""
    bad = []
    for r in rows:
        cell = (
            f"{r['tunnel']} {r['array']} {_g(r['phase'])} deg {_g(r['gain'])} dB seed {r['seed']}"
        )
        if r["r_hy_ci"] is None or r["r_pc_ci"] is None:
            bad.append(f"{cell}: a bound is missing ({r['status']}: {r['reason']})")
            continue
        if r["r_hy_ci"][1] < 1:
            bad.append(f"{cell}: RMSE / hybrid bound interval {_ci(r['r_hy_ci'])} below 1")
        if r["r_pc_ci"][1] < 1:
            bad.append(f"{cell}: RMSE / PCRLB interval {_ci(r['r_pc_ci'])} below 1")
    return bad


def _g(v) -> str:
    """A phase or gain cell: a number, or ``cal`` for the calibrated preset."""
    return v if isinstance(v, str) else f"{v:g}"


def _ci(ci, fmt=".3g") -> str:
    return "-" if ci is None else f"[{ci[0]:{fmt}}, {ci[1]:{fmt}}]"


def _num(v, fmt=".3g") -> str:
    return "-" if v is None else f"{v:{fmt}}"


def bound_table(rows) -> str:
    head = (
        "| tunnel | array | phase deg | gain dB | seed | units x D | RMSE m | RMSE / hybrid "
        "[95 % CI] | RMSE / PCRLB [95 % CI] | min unit RMSE / PCRLB (2 drives: a sample) | "
        "RMSE / pred. drive | p90 m [CI] | "
        "unit yield @0.1 m [Wilson] |\n|" + "---|" * 13
    )
    lines = [head]
    for r in rows:
        if r["rmse"] is None:  # no Monte-Carlo: the row's reason
            lines.append(
                f"| {r['tunnel']} | {r['array']} | {_g(r['phase'])} | {_g(r['gain'])} | {r['seed']} | "
                f"{r['status']}: {r['reason']} |" + " |" * 7
            )
            continue
        lines.append(
            f"| {r['tunnel']} | {r['array']} | {_g(r['phase'])} | {_g(r['gain'])} | {r['seed']} | "
            f"{r['units']} x {r['drives']} | {r['rmse']:.4f} | {_num(r['r_hy'])} "
            f"{_ci(r['r_hy_ci'])} | {_num(r['r_pc'])} {_ci(r['r_pc_ci'])} | "
            f"{_num(r['r_pc_unit_min'])} | "
            f"{_num(r['r_pred'])} | {r['p90']:.4f} {_ci(r['p90_ci'], '.4f')} | "
            f"{r['yield']:.2f} {_ci(r['yield_ci'], '.2f')} |"
        )
    bad = bound_failures(rows)
    lines.append("")
    lines.append(
        f"Cells: {len(rows)}; a bound above the tracker's error: "
        + ("none" if not bad else f"{len(bad)}")
    )
    lines += [f"- {b}" for b in bad]
    return "\n".join(lines)


def _finite(e):
    return np.where(np.isfinite(e), e, np.inf)


def _boot_ci(by, rng, n_boot):
    from tunnelkit.design import bootstrap_quantile_ci

    return bootstrap_quantile_ci(by, SHARE, rng, n_boot=n_boot)


def unit_bounds(array: str = "8x8", units: int = 12, drives: int = 25, seed: int = 4242) -> dict:
    """Part 3: the PCRLB against each unit's own RMSE, measured on many drives per unit.

    Part 1's "min unit RMSE / PCRLB" is a sample from two drives per unit and can fall below 1
    by chance; here ``units`` units of ``drives`` drives each under the calibrated default give
    each unit's RMSE over its drives, and single drives' RMSEs for contrast."""
    from tunnelkit.design import DesignSetup, path_error_model, preset_impairments, sweep_montecarlo
    from tunnelkit.design.setup import parse_array

    setup = DesignSetup.from_scenario(SCENARIO)
    imp = preset_impairments("calibrated", setup, [parse_array(array)])
    res = sweep_montecarlo(setup, [array], units * drives, seed, drives_per_unit=drives,
                           mode="bound", impairments=imp,
                           error_models=partial(path_error_model, impairments=imp))[array]  # fmt: skip
    k = res.settled
    pc = float(np.sqrt(np.mean(np.asarray(res.pcrlb)[k] ** 2)))
    ms = (_finite(res.errors[:, k]) ** 2).reshape(units, drives, -1).mean(axis=2)
    return {
        "array": array,
        "units": units,
        "drives": drives,
        "seed": seed,
        "pcrlb": pc,
        "pooled": float(np.sqrt(ms.mean())) / pc,
        "unit": np.sqrt(ms.mean(axis=1)) / pc,
        "two_drive_min": float(np.min(np.sqrt(ms[:, :2].mean(axis=1)))) / pc,
        "drive_min": float(np.sqrt(ms.min())) / pc,
    }


def unit_bounds_text(r) -> str:
    u = r["unit"]
    return (
        f"{r['array']}, calibrated default, {r['units']} units x {r['drives']} drives (seed "
        f"{r['seed']}): PCRLB {r['pcrlb']:.4g} m; pooled RMSE / PCRLB {r['pooled']:.3g}; each "
        f"unit's RMSE / PCRLB {u.min():.3g}-{u.max():.3g} (median {np.median(u):.3g}); from its "
        f"first two drives only, the smallest unit {r['two_drive_min']:.3g}; the smallest "
        f"single drive {r['drive_min']:.3g}."
    )


def _level(level):
    """An impairment level of part 2: a phase error in degrees (nothing else), or the
    design's default ``"calibrated"``; returns ``(label, impairments)``."""
    from tunnelkit.design import DesignImpairments, preset_impairments
    from tunnelkit.design.setup import parse_array

    if level == "calibrated":
        specs = [parse_array(a) for a in COVERAGE_ARRAYS]
        return "cal", preset_impairments("calibrated", _setup("base"), specs)
    return f"{float(level):g}", DesignImpairments(phase_error_deg=float(level))


def coverage(
    arrays=COVERAGE_ARRAYS,
    levels=PHASES_DEG,
    ref_units: int = 400,
    blocks: int = 40,
    block_units: int = 20,
    drives: int = 2,
    ref_seed: int = 9001,
    seed: int = 1,
    workers: int | None = None,
    n_boot: int = 2000,
    old: bool = False,
    resample: tuple = (20, 40, 80),
    reps: int = 300,
) -> list[dict]:
    """Part 2: per array x impairment level (:func:`_level`), the reference and the coverage
    over ``blocks`` blocks; with ``old`` also the intervals the design reported before (one
    calibration draw per drive, and drives resampled ignoring the unit)."""
    from tunnelkit.design import (
        cluster_quantile_ci,
        path_error_model,
        share_quantile,
        sweep_montecarlo,
    )
    from tunnelkit.design.units import unit_quantiles, unit_yield, wilson_interval
    from tunnelkit.runner import trial_pool

    setup = _setup("base")
    out = []
    with trial_pool(workers) as pool:
        for level in levels:
            label, imp = _level(level)
            kw = {
                "impairments": imp,
                "error_models": partial(path_error_model, impairments=imp),
                "mode": "bound",
                "pool": pool,
            }
            t0 = time.perf_counter()
            ref2 = sweep_montecarlo(setup, arrays, ref_units * drives, ref_seed,
                                    drives_per_unit=drives, **kw)  # fmt: skip
            run2 = sweep_montecarlo(setup, arrays, blocks * block_units * drives, seed,
                                    drives_per_unit=drives, **kw)  # fmt: skip
            if old:
                ref1 = sweep_montecarlo(setup, arrays, ref_units * drives, ref_seed + 1, **kw)
                run1 = sweep_montecarlo(setup, arrays, blocks * block_units, seed + 1, **kw)
            dt = time.perf_counter() - t0
            for a in arrays:
                k = ref2[a].settled
                rng = np.random.default_rng([0xC0FE, *label.encode(), *a.encode()])
                e_ref2 = _finite(ref2[a].errors[:, k])
                p90_ref = share_quantile(e_ref2, SHARE)
                uq = unit_quantiles(ref2[a].errors, drives, k, SHARE)
                y_ref, y_ref_ci = unit_yield(uq, TARGET_M)
                ref_ci = cluster_quantile_ci(e_ref2.reshape(ref_units, -1), SHARE)
                keys = ["cluster", "units", "yield"] + (["drives1", "drives2"] if old else [])
                hits = {key: [] for key in keys}
                widths = {key: [] for key in keys}

                def hit(key, ref, ci, hits=hits, widths=widths):
                    hits[key].append(_where(ref, ci))
                    widths[key].append(ci[1] - ci[0])

                for b in range(blocks):
                    rows2 = slice(b * block_units * drives, (b + 1) * block_units * drives)
                    e2 = _finite(run2[a].errors[rows2][:, k])
                    hit("cluster", p90_ref, cluster_quantile_ci(e2.reshape(block_units, -1), SHARE))
                    hit("units", p90_ref, _boot_ci(e2.reshape(block_units, -1), rng, n_boot))
                    q = unit_quantiles(run2[a].errors[rows2], drives, k, SHARE)
                    hit("yield", y_ref, unit_yield(q, TARGET_M)[1])
                    if old:  # drives resampled, the unit ignored; one draw per drive
                        hit("drives2", p90_ref, _boot_ci(e2, rng, n_boot))
                        e1 = _finite(run1[a].errors[b * block_units : (b + 1) * block_units][:, k])
                        p90_ref1 = share_quantile(_finite(ref1[a].errors[:, k]), SHARE)
                        hit("drives1", p90_ref1, _boot_ci(e1, rng, n_boot))
                # Woodruff's interval at the unit counts the design reports (20 first, doubled
                # to 80 or more for a pass), on blocks drawn from the reference's own units
                sub = {}
                e_units = e_ref2.reshape(ref_units, -1)
                for n_u in resample:
                    if n_u >= ref_units:
                        continue
                    h = []
                    for _ in range(reps):
                        pick = rng.choice(ref_units, n_u, replace=False)
                        h.append(_where(p90_ref, cluster_quantile_ci(e_units[pick], SHARE)))
                    h = np.asarray(h)
                    sub[n_u] = {"in": int(np.sum(h == 0)), "low": int(np.sum(h < 0)),
                                "high": int(np.sum(h > 0)), "reps": reps}  # fmt: skip
                cov = {}
                for key, h in hits.items():
                    h = np.asarray(h)
                    n_in = int(np.sum(h == 0))
                    cov[key] = {
                        "in": n_in,
                        "low": int(np.sum(h < 0)),
                        "high": int(np.sum(h > 0)),
                        "share": n_in / blocks,
                        "ci": wilson_interval(n_in, blocks),
                        "width": float(np.mean(widths[key])),
                    }
                out.append(
                    {
                        "array": a,
                        "level": label,
                        "ref_units": ref_units,
                        "p90_ref": p90_ref,
                        "p90_ref_ci": ref_ci,
                        "yield_ref": y_ref,
                        "yield_ref_ci": y_ref_ci,
                        "blocks": blocks,
                        "block_units": block_units,
                        "drives": drives,
                        "coverage": cov,
                        "resampled": sub,
                        "seconds": dt / len(arrays),
                    }
                )
    return out


def _where(ref: float, ci) -> int:
    """-1: the interval lies below the reference, 0: holds it, 1: lies above it."""
    return -1 if ci[1] < ref else (1 if ci[0] > ref else 0)


def coverage_table(rows) -> str:
    lines = [
        "| array | impairments | reference (units x D) | ref p90 m [Woodruff 95 %] | "
        "ref unit yield [Wilson] |\n|" + "---|" * 5
    ]
    for r in rows:
        lines.append(
            f"| {r['array']} | {r['level']} | {r['ref_units']} x {r['drives']} | "
            f"{r['p90_ref']:.4f} {_ci(r['p90_ref_ci'], '.4f')} | {r['yield_ref']:.3f} "
            f"{_ci(r['yield_ref_ci'], '.3f')} |"
        )
    names = {
        "cluster": "p90, Woodruff over units (reported)",
        "units": "p90, percentile bootstrap over units",
        "yield": "unit yield @0.1 m, Wilson (reported)",
        "drives1": "p90, bootstrap over drives (D=1, one draw per drive)",
        "drives2": "p90, bootstrap over drives (D=2, unit ignored)",
    }
    lines += [
        "",
        "| array | impairments | interval | blocks x units | nominal | measured coverage "
        "[Wilson 95 %] | missed low / high | mean width |\n|" + "---|" * 8,
    ]
    for r in rows:
        for key, name in names.items():
            if key not in r["coverage"]:
                continue
            c = r["coverage"][key]
            n_units = r["block_units"] if key != "drives1" else f"{r['block_units']} drives"
            lines.append(
                f"| {r['array']} | {r['level']} | {name} | {r['blocks']} x {n_units} | 0.95 | "
                f"{c['share']:.3f} {_ci(c['ci'], '.3f')} | {c['low']} / {c['high']} | "
                f"{c['width']:.4g} |"
            )
    lines += [
        "",
        "Woodruff's interval on blocks drawn from the reference's own units (without "
        "replacement; overlapping blocks, so the trials are not independent):",
        "",
        "| array | impairments | units per block | blocks | coverage | missed low / high |\n|"
        + "---|" * 6,
    ]
    for r in rows:
        for n_u, c in r.get("resampled", {}).items():
            lines.append(
                f"| {r['array']} | {r['level']} | {n_u} | {c['reps']} | "
                f"{c['in'] / c['reps']:.3f} | {c['low']} / {c['high']} |"
            )
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a smoke test: small and few")
    ap.add_argument("--part", choices=("1", "2", "3", "both"), default="both")
    ap.add_argument("--tunnels", nargs="+", default=["base"],
                    help="'base' and/or from_scenario overrides such as mount_height=5.0")  # fmt: skip
    ap.add_argument("--seeds", type=int, nargs="+", default=list(SEEDS))
    ap.add_argument("--phases", type=float, nargs="+", default=list(PHASES_DEG))
    ap.add_argument("--levels", nargs="+", default=["2", "calibrated"],
                    help="part 2: impairment levels, a phase error in deg or 'calibrated'")  # fmt: skip
    ap.add_argument("--arrays", nargs="+", default=list(COVERAGE_ARRAYS),
                    help="part 2: the arrays measured")  # fmt: skip
    ap.add_argument("--old", action="store_true",
                    help="part 2: also the intervals reported before (drives resampled)")  # fmt: skip
    ap.add_argument("--tag", default="", help="a suffix of the written files' names")
    ap.add_argument("--units", type=int, default=30, help="part 1: units per cell")
    ap.add_argument("--drives", type=int, default=2, help="drives per unit")
    ap.add_argument("--ref-units", type=int, default=400)
    ap.add_argument("--ref-seed", type=int, default=9001)
    ap.add_argument("--blocks", type=int, default=40, help="part 2: short runs per cell")
    ap.add_argument("--block-units", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1, help="part 2: the short runs' seed")
    ap.add_argument("--n-boot", type=int, default=2000)
    ap.add_argument("--workers", type=int, default=None, choices=(1, 2))
    ap.add_argument("--out", type=Path, default=Path("/tmp/bench_units"))
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    tag = ("_quick" if args.quick else "") + (f"_{args.tag}" if args.tag else "")
    if args.part in ("1", "both"):
        kw = {"units": args.units, "drives": args.drives, "workers": args.workers}
        kw["phases"] = tuple(args.phases)
        if args.quick:
            kw.update(phases=(2.0,), gains=(0.2,), seeds=args.seeds[:1], units=10)
        else:
            kw["seeds"] = args.seeds
        t0 = time.perf_counter()
        rows = bound_matrix(tuple(args.tunnels), **kw)
        dt = time.perf_counter() - t0
        text = f"## Bounds vs the tracker ({dt:.0f} s)\n\n{bound_table(rows)}\n"
        print(text)
        (args.out / f"units_bounds{tag}.md").write_text(text, encoding="utf-8")
    if args.part == "3":
        text = unit_bounds_text(unit_bounds(units=4, drives=5) if args.quick else unit_bounds())
        print(text)
        (args.out / f"units_unit_bounds{tag}.md").write_text(text + "\n", encoding="utf-8")
    if args.part in ("2", "both"):
        kw = {
            "ref_units": args.ref_units,
            "blocks": args.blocks,
            "block_units": args.block_units,
            "drives": args.drives,
            "ref_seed": args.ref_seed,
            "seed": args.seed,
            "workers": args.workers,
            "n_boot": args.n_boot,
            "levels": tuple(args.levels),
            "arrays": tuple(args.arrays),
            "old": args.old,
        }
        if args.quick:
            kw.update(levels=("calibrated",), ref_units=60, blocks=5)
        t0 = time.perf_counter()
        rows = coverage(**kw)
        dt = time.perf_counter() - t0
        text = f"## Coverage of the reported intervals ({dt:.0f} s)\n\n{coverage_table(rows)}\n"
        print(text)
        (args.out / f"units_coverage{tag}.md").write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
