"""The line of sight alone on the ray-traced channel (:mod:`tunnelkit.studies.los_only`), from an
open-sky entry fix: JAVELIN fed the path each epoch takes for the line of sight, told a plain angle sigma,
beside the traced design (every path the geometry test keeps, told the traced sigmas) and dead
reckoning (the same JAVELIN, every measurement dropped), on the same drives and the same starts.

Per seed ``--runs`` condition-L drives of the straight preset on the ray-traced channel (drive
``i`` from the ``i``-th child of the seed, :func:`tunnelkit.runner.run_trials`), each tracker
started from one draw of the entry fix (``--start-sigma`` per axis, 5 cm in height); 2-D RMSE
over the settled epochs, mean over the drives; the angle sigma is chosen on seed 0 (the
``--sigmas`` grid) and reported on the held-out seed. Beside them the drive's posterior CRLB of
the line of sight's two angles at the chosen sigma as independent Gaussian errors, the start
and the V2X messages (:func:`tunnelkit.design.drive_pcrlb`): a reference of the told model, not
a bound on the traced channel. Also the share of epochs whose path taken for the line of sight
(:func:`~tunnelkit.design.los.los_path`) is the true one.

    python benchmarks/bench_rt_los.py --runs 12 --workers 2
    python benchmarks/bench_rt_los.py --runs 12 --workers 2 --scenario italiano2026-slalom --sigmas 1
    python benchmarks/bench_rt_los.py --runs 12 --workers 2 --array 8x8 --sigmas 1
    python benchmarks/bench_rt_los.py --bound-grid 1 1/1.8 0.5/1.8 1/1.3 1/0.5

``--starts N`` tracks every drive from ``N`` entry fixes (the gain's 90 % interval is a bootstrap
over the drives); ``--by-elevation BINS`` adds the first sigma's design told each epoch's sigmas
by the measured elevation (:mod:`tunnelkit.design.los`, the table built on seed 0's
drives), ``--table FILE`` one built elsewhere (``--write-table``); ``--huber`` each sigma with
the Huber-weighted update (:mod:`tunnelkit.studies.robust_update`); ``--cost`` the tracking time
per epoch; ``--drives-cache DIR`` keeps the drives to score them again; ``--errors-out`` writes
seed 0's error record and ``--pooled-errors`` builds the tables from such records of other runs.
"""

from __future__ import annotations

import argparse
import functools
import json
import pickle
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.design import DesignSetup, drive_pcrlb
from tunnelkit.design.los import (
    ElevationSigmas,
    elevation_sigmas,
    los_angle_information,
    los_errors,
    los_only,
    los_path,
    told_by_elevation,
)
from tunnelkit.geometry import spherical
from tunnelkit.metrics import settled
from tunnelkit.runner import run_trials
from tunnelkit.signal_route import SignalRoute
from tunnelkit.simulation import HELD_OUT_SEED, evaluate, without_radio
from tunnelkit.studies.attribution import scenario_with_array
from tunnelkit.studies.los_only import flagged_los, los_design
from tunnelkit.studies.robust_update import HuberUpdater
from tunnelkit.studies.traced import simulate_traced, traced_design
from tunnelkit.tracking.javelin import ReportedNoise, draw_start

SCENARIO = "italiano2026-straight"
START_HEIGHT = 0.05


@functools.cache
def _route(scenario: str, array: str | None):
    """The traced route of ``scenario`` with its arrays replaced by ``array`` ("RxC"), built
    once per process (the ray tracer's cache keeps the traces on disk)."""
    shape = tuple(int(n) for n in array.split("x"))
    return SignalRoute.from_scenario(scenario_with_array(scenario, shape), channel="sionna")


def _drive(case, rng):
    scenario, array = case
    route = scenario if array is None else _route(scenario, array)
    d = simulate_traced(
        route, rng, condition="L", channel="sionna", adapters={"flags": flagged_los}
    )
    return {k: d[k] for k in ("ml-all", "ml-traced", "flags")}


def _drives(case, runs, seed, workers, cache) -> list:
    """The ``runs`` drives of ``case`` from ``seed`` (:func:`_drive`), read from or written to
    ``cache`` (a folder, or ``None``): a pickle per case, count and seed, for re-scoring."""
    scenario, array = case
    path = (
        None if cache is None else Path(cache) / f"{scenario}-{array or 'preset'}-{runs}-{seed}.pkl"
    )
    if path is not None and path.is_file():
        return pickle.loads(path.read_bytes())
    drives = run_trials(_drive, runs, seed, inputs=[case] * runs, workers=workers)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(pickle.dumps(drives))
    return drives


def _rmse(drive, truth, design, p0, sigma, idx) -> float:
    ev = evaluate(drive, design, sigma_p0_ue=sigma, start=p0, sigma_p0_height=START_HEIGHT)
    e = np.linalg.norm(ev.estimates[:, :2] - truth[:, :2], axis=1)[idx]
    return float(np.sqrt(np.mean(e**2)))


def score(
    drives,
    seed,
    sigmas,
    start_sigma,
    los_gammas=(),
    flags=False,
    starts=1,
    tables=None,
    huber=False,
    told_sigma=None,
) -> dict:
    """Mean RMSE per tracker over ``drives`` x ``starts`` entry fixes (the starts from a stream of
    their own, ``starts`` per drive in turn); ``tables``: {label: ElevationSigmas}, the
    ``told_sigma`` design (default the first sigma's; its kappa and d sigmas kept) told each
    epoch's sigmas from each table; ``huber``: each sigma also with the Huber-weighted update."""
    rng = np.random.default_rng([seed, 1])
    td = traced_design()
    designs = {}
    for s in sigmas:
        designs[f"LoS only, {s} deg"] = _los(s, td)
        # eq. 61's tolerance widened: the one path taken for the line of sight more often
        for g in los_gammas:
            d = designs[f"LoS only, {s} deg"].with_(los_gamma=float(g))
            designs[f"LoS only, {s} deg, gamma {g:g}"] = d
        if huber:
            d = designs[f"LoS only, {s} deg"].with_(updater=HuberUpdater())
            designs[f"LoS only, {s} deg, Huber update"] = d
    plain = list(designs)
    flagged = [f"{k}, fit flags" for k in plain] if flags else []
    tables = tables or {}
    told = _los(told_sigma or sigmas[0], td).with_(noise=ReportedNoise())  # its kappa, d sigmas
    ranged = [f"LoS only, sigmas by elevation ({k})" for k in tables]
    out = {"traced design": [], "dead reckoning": [], **{k: [] for k in plain + flagged + ranged}}
    los_share, kept = [], []
    for dd in drives:
        tr, every = dd["ml-traced"], dd["ml-all"]
        idx = settled(tr.t)
        los = los_only(every)
        by_el = [_told(los, t, told) for t in tables.values()]
        for _ in range(starts):
            p0 = draw_start(tr.truth[0], start_sigma, rng, START_HEIGHT)
            out["traced design"].append(_rmse(tr, tr.truth, td, p0, start_sigma, idx))
            out["dead reckoning"].append(
                _rmse(without_radio(tr), tr.truth, td, p0, start_sigma, idx)
            )
            for k, d in designs.items():
                out[k].append(_rmse(los, tr.truth, d, p0, start_sigma, idx))
                if flags:  # the same path, dropped in the epochs where the fit flags it
                    r = _rmse(dd["flags"], tr.truth, d, p0, start_sigma, idx)
                    out[f"{k}, fit flags"].append(r)
            for k, drive in zip(ranged, by_el, strict=True):
                out[k].append(_rmse(drive, tr.truth, told, p0, start_sigma, idx))
        kept += [ep is not None for ep in dd["flags"].epochs]
        for ep, ti in zip(every.epochs, every.truth_index, strict=True):
            if ep is not None and len(ep):
                los_share.append(int(ti[los_path(ep.d, ep.psi)]) == 0)
    res = {k: float(np.mean(v)) for k, v in out.items()}
    # the root mean square over the drives: the statistic a posterior CRLB bounds
    res["_rms"] = {k: float(np.sqrt(np.mean(np.square(v)))) for k, v in out.items()}
    res["_gain_interval"] = _gain_interval(out, len(drives), starts)
    res["_los_share"] = float(np.mean(los_share)) if los_share else float("nan")
    res["_kept"] = float(np.mean(kept)) if kept else float("nan")
    return res


def _gain_interval(out, n_drives, starts, level=0.9) -> dict:
    """Per tracker the ``level`` interval of the gain (mean dead reckoning over mean tracker)
    from a bootstrap over the drives (the independent unit: a drive's starts share its
    measurements), 2,000 resamples."""
    boot = np.random.default_rng(7).integers(0, n_drives, (2000, n_drives))
    dr = np.reshape(out["dead reckoning"], (n_drives, starts)).mean(axis=1)[boot].mean(axis=1)
    lo, hi = (1 - level) / 2, (1 + level) / 2
    res = {}
    for k, v in out.items():
        g = dr / np.reshape(v, (n_drives, starts)).mean(axis=1)[boot].mean(axis=1)
        res[k] = (float(np.quantile(g, lo)), float(np.quantile(g, hi)))
    return res


def _told(los, table, design):
    """``los`` told its sigmas by elevation from ``table``, ``design``'s curvature sigma and its
    TDoA sigma shared as two paths' delay sigmas."""
    c = design.config
    return told_by_elevation(los, table, c.sigma_kappa, c.sigma_delta_d / np.sqrt(2))


def tracker_cost(drives, table, sigma, repeats=5) -> dict:
    """Median over ``repeats`` of the tracking time per epoch [ms] of each tracker on ``drives``
    (from the truth's first point; the extraction's cost is the drive's, the same for all), the
    line of sight told ``sigma`` ("az[/el]" deg)."""
    td = traced_design()
    one = _los(sigma, td)
    cases = {
        "traced design": (lambda dd: dd["ml-traced"], td),
        f"LoS only, {sigma} deg": (lambda dd: los_only(dd["ml-all"]), one),
        "the same, Huber update": (
            lambda dd: los_only(dd["ml-all"]),
            one.with_(updater=HuberUpdater()),
        ),
    }
    if table is not None:
        cases["LoS only, sigmas by elevation"] = (
            lambda dd: _told(los_only(dd["ml-all"]), table, one),
            one.with_(noise=ReportedNoise()),
        )
    out = {}
    for name, (prepare, design) in cases.items():
        runs = []
        for _ in range(repeats):
            t0, n = time.perf_counter(), 0
            for dd in drives:
                drive = prepare(dd)
                evaluate(drive, design, sigma_p0_ue=1.0, start=drive.truth[0])
                n += len(drive.t)
            runs.append(1e3 * (time.perf_counter() - t0) / n)
        out[name] = float(np.median(runs))
    return out


def _los(sigma: str, base):
    """``base`` told the line of sight's sigmas ``sigma`` ("az[/el]" deg)."""
    az, el = np.radians(_pair(sigma))
    return los_design(float(az), base, sigma_elevation=float(el))


def _pair(text: str) -> tuple[float, float]:
    """``"1"`` or ``"1/1.8"``: the azimuth's and the elevation's sigma [deg]."""
    az, _, el = text.partition("/")
    return float(az), float(el or az)


def settled_bound(setup, ue, station, t, sigma_deg, start_sigma) -> float:
    """Settled RMS of the posterior CRLB over ``setup``'s drive of the LoS angles at
    ``sigma_deg`` ("az[/el]"; ``None``: no radio, dead reckoning's) seen from ``station``."""
    T = len(ue)
    if sigma_deg is None:
        info = np.zeros((T, 2, 2))
    else:
        info = los_angle_information(ue, station, *np.radians(_pair(sigma_deg)))
    b = drive_pcrlb(setup, info, sigma_p0=start_sigma)
    idx = settled(t[:T])
    return float(np.sqrt(np.mean(b[idx] ** 2)))


def reference(drive, sigma_deg, start_sigma, scenario=SCENARIO) -> float:
    """:func:`settled_bound` of ``drive`` (its truth and its reference antenna)."""
    setup = DesignSetup.from_scenario(scenario)
    return settled_bound(setup, drive.truth, drive.base_station, drive.t, sigma_deg, start_sigma)


def table_reference(drive, table, start_sigma, scenario=SCENARIO) -> float:
    """:func:`settled_bound`'s figure with each epoch's sigmas read from ``table`` at the true
    line of sight's elevation (the told model of a design told the table)."""
    setup = DesignSetup.from_scenario(scenario)
    saz, sel = table.at(spherical(drive.truth - drive.base_station)[:, 1])
    info = np.concatenate([
        los_angle_information(drive.truth[k : k + 1], drive.base_station, saz[k], sel[k])
        for k in range(len(drive.truth))
    ])  # fmt: skip
    b = drive_pcrlb(setup, info, sigma_p0=start_sigma)
    return float(np.sqrt(np.mean(b[settled(drive.t[: len(b)])] ** 2)))


def bound_grid(scenario, pairs, start_sigma) -> None:
    """The told model's posterior CRLB over the preset's drive for each "az/el" of ``pairs``
    beside dead reckoning's (the same recursion, no radio): their ratio is the gain an efficient
    tracker fed Gaussian LoS angles of those sigmas shows over dead reckoning on average (RMS).
    Drives nothing."""
    setup = DesignSetup.from_scenario(scenario)
    ue, t = setup.trajectory.position, setup.trajectory.t
    bs = SignalRoute.from_scenario(scenario).arrays[0].origin
    dr = settled_bound(setup, ue, bs, t, None, start_sigma)
    print(f"\n{scenario}: told model, entry fix {start_sigma:g} m, {settled(t).size} settled "
          f"epochs; dead reckoning's posterior CRLB {dr:.3f} m")  # fmt: skip
    print("| azimuth / elevation sigma [deg] | posterior CRLB [m] | ratio to dead reckoning's |\n"
          "| --- | --- | --- |")  # fmt: skip
    for s in pairs:
        b = settled_bound(setup, ue, bs, t, s, start_sigma)
        print(f"| {s} | {b:.3f} | {dr / b:.2f}x |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=12)
    ap.add_argument("--scenario", default=SCENARIO, help="a preset with a ray-traced channel")
    ap.add_argument("--array", default=None, help="replace the preset's arrays, e.g. 8x8")
    ap.add_argument(
        "--sigmas",
        nargs="+",
        default=["0.5", "1", "2", "4", "8"],
        help="told angle sigmas [deg], each 'az' (both angles) or 'az/el'",
    )
    ap.add_argument("--start-sigma", type=float, default=1.0)
    ap.add_argument(
        "--los-gamma",
        type=float,
        nargs="*",
        default=[],
        help="also each sigma with eq. 61's tolerance gamma widened to these (0.2: the paper's)",
    )
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument(
        "--fit-flags",
        action="store_true",
        help="also each sigma on the path dropped where the fit puts it in its threshold region",
    )
    ap.add_argument(
        "--bound-grid",
        nargs="+",
        default=None,
        help="print the told model's bound for these 'az/el' sigmas [deg] and stop (no driving)",
    )
    ap.add_argument(
        "--starts", type=int, default=1, help="entry fixes drawn per drive (the tracker is cheap)"
    )
    ap.add_argument(
        "--huber", action="store_true", help="also each sigma with the Huber-weighted update"
    )
    ap.add_argument(
        "--by-elevation",
        type=int,
        nargs="+",
        default=None,
        metavar="BINS",
        help="also the first sigma's design told each epoch's sigmas from a table of the LoS "
        "errors by measured elevation, built on seed 0's drives with each of these bin counts "
        "(the count chosen on seed 0)",
    )
    ap.add_argument(
        "--drives-cache", default=None, help="keep the drives here (a folder) to score them again"
    )
    ap.add_argument(
        "--every-sigma",
        action="store_true",
        help="report every sigma on the held-out seed too (the choice still made on seed 0)",
    )
    ap.add_argument(
        "--cost", action="store_true", help="also time each tracker per epoch on each seed's drives"
    )
    ap.add_argument("--table", default=None, help="use this table (JSON) instead of building one")
    ap.add_argument("--write-table", default=None, help="write the chosen table (JSON) here")
    ap.add_argument(
        "--errors-out", default=None, help="write seed 0's LoS error record here (.npy)"
    )
    ap.add_argument(
        "--survey",
        type=int,
        default=None,
        metavar="N",
        help="with --by-elevation: build the tables from seed 0's first N drives only (the "
        "design's survey is 3) and score seed 0 on its other drives",
    )
    ap.add_argument(
        "--pooled-errors",
        nargs="+",
        default=None,
        help="with --by-elevation: build the tables from these records (--errors-out of other "
        "runs) instead of this run's drives",
    )
    a = ap.parse_args()
    if a.survey is not None and (not a.by_elevation or a.pooled_errors or a.survey < 1
                                 or a.survey >= a.runs):  # fmt: skip
        ap.error("--survey: give --by-elevation, no --pooled-errors, and 1 <= N < --runs")
    if a.pooled_errors and not a.by_elevation:
        ap.error("--pooled-errors: give --by-elevation (the bin counts)")
    if a.table and a.by_elevation:
        ap.error("--table and --by-elevation: give one (a table built elsewhere, or built here)")
    if a.write_table and not (a.table or a.by_elevation):
        ap.error("--write-table: no table to write (give --by-elevation)")
    if a.write_table and a.table:
        ap.error("--write-table: the table given by --table is written already")
    if a.bound_grid:
        bound_grid(a.scenario, a.bound_grid, a.start_sigma)
        return
    chosen, tables = None, None
    if a.table:
        tables = {f"table {Path(a.table).name}": ElevationSigmas.from_dict(
            json.loads(Path(a.table).read_text())["table"])}  # fmt: skip
    for seed in (0, HELD_OUT_SEED):
        t0 = time.perf_counter()
        case = (a.scenario, a.array)
        drives = _drives(case, a.runs, seed, a.workers, a.drives_cache)
        sigmas = a.sigmas if chosen is None or a.every_sigma else [chosen]
        if seed == 0 and a.errors_out:  # this scene's seed-0 record, to pool with others
            np.save(a.errors_out, los_errors([dd["ml-all"] for dd in drives]))
        if tables is None and a.by_elevation:  # built on seed 0's drives (or the pooled records)
            if a.pooled_errors:
                errors, src = np.vstack([np.load(f) for f in a.pooled_errors]), "pooled"
            else:
                survey = drives if a.survey is None else drives[: a.survey]
                errors = los_errors([dd["ml-all"] for dd in survey])
                src = "seed 0" if a.survey is None else f"seed 0's first {a.survey} drives"
            tables = {f"{b} bins, {src}": elevation_sigmas(errors, b) for b in a.by_elevation}
            if a.survey is not None:  # seed 0 scored on the drives the survey did not see
                drives = drives[a.survey :]
        res = score(drives, seed, sigmas, a.start_sigma, a.los_gamma, a.fit_flags, a.starts,
                    tables, a.huber, a.sigmas[0])  # fmt: skip
        if chosen is None:  # chosen on seed 0, the lowest mean RMSE of the grid
            chosen = min(sigmas, key=lambda s: res[f"LoS only, {s} deg"])
            # (a widened eq. 61 is reported beside the chosen sigma, not chosen among)
            if tables and len(tables) > 1:
                best = min(tables, key=lambda k: res[f"LoS only, sigmas by elevation ({k})"])
                tables = {best: tables[best]}
        ref = reference(drives[0]["ml-traced"], chosen, a.start_sigma, a.scenario)
        dr = res["dead reckoning"]
        arrays = "" if a.array is None else f" with {a.array} arrays"
        print(f"\nseed {seed}: {len(drives)} drives x {a.starts} entry fixes of {a.scenario}{arrays}, "
              f"traced channel, L, entry fix {a.start_sigma:g} m "
              f"({time.perf_counter() - t0:.0f} s); path taken = the "
              f"true LoS in {100 * res['_los_share']:.1f} % of the epochs; none kept (fit "
              f"flags, no path) in "
              f"{100 * (1 - res['_kept']):.1f} %")  # fmt: skip
        print("| tracker | RMSE, mean [m] | gain over dead reckoning (90 % over drives) | RMS "
              "[m] |\n| --- | --- | --- | --- |")  # fmt: skip
        for k, v in res.items():
            if not k.startswith("_"):
                lo, hi = res["_gain_interval"][k]
                print(f"| {k} | {v:.3f} | {dr / v:.2f}x ({lo:.2f}-{hi:.2f}) | "
                      f"{res['_rms'][k]:.3f} |")  # fmt: skip
        print(f"| told model's figure (not a bound here): posterior CRLB of Gaussian LoS angles "
              f"at {chosen} deg, every epoch, first drive | {ref:.3f} | |")  # fmt: skip
        for name, table in (tables or {}).items():
            tref = table_reference(drives[0]["ml-traced"], table, a.start_sigma, a.scenario)
            print(f"| told model's figure (not a bound here): the same, sigmas by elevation "
                  f"({name}) | {tref:.3f} | |")  # fmt: skip
        if a.cost:
            table = next(iter(tables.values())) if tables else None
            for name, ms in tracker_cost(drives, table, a.sigmas[0]).items():
                print(f"tracking cost, {name}: {ms:.2f} ms per epoch (median of 5)")
    print(f"\nangle sigma chosen on seed 0: {chosen} deg")
    if tables:
        name, table = next(iter(tables.items()))
        print(f"elevation table ({name}) [deg]: {table.as_dict()}")
        if a.write_table:
            Path(a.write_table).write_text(json.dumps(
                {"scenario": a.scenario, "array": a.array, "runs": a.runs, "built": name,
                 "table": table.as_dict()}, indent=1))  # fmt: skip


if __name__ == "__main__":
    main()
