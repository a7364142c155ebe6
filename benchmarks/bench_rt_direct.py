"""The direct fit under the tracker on the ray-traced channel (:mod:`tunnelkit.design.traceddirect`):
per drive, dead reckoning, the traced tables' line-of-sight column (eq. 1), the direct fix's line
of sight and, with ``--speed-sigma``, its speed (and that speed alone), on the same messages and
snapshots (condition L, start at the truth told 0.1 m). Reports each tracker's mean RMSE, its
ratio to dead reckoning (per drive, mean and 90 % bootstrap interval), the errors each was fed
and the extraction's cost per epoch.

The direct fix's sigmas by elevation are a table (``--table``, JSON of
``ElevationSigmas.as_dict``) or one constant pair (``--sigmas AZ/EL`` [deg]); ``--write-table
PATTERN --bins B ...`` makes tables from this run's errors (choose on one seed, report another).
``--out`` keeps the drives (their fixes too); ``--replay`` feeds those fixes to the trackers told
another table, without fitting (seconds instead of minutes; approximate, as the fit starts at
the track's prediction: the choice is then checked on drives of its own).

    python benchmarks/bench_rt_direct.py --seed 0 --runs 6 --sigmas 0.2/0.1 --speed-sigma 0.1 --write-table 'build/direct/straight-{bins}.json' --bins 1 2 4
    python benchmarks/bench_rt_direct.py --seed 20261202 --runs 10 --table build/direct/straight-2.json --speed-sigma 0.1
    python benchmarks/bench_rt_direct.py --seed 0 --runs 20 --table build/direct/straight-8.json --sigma-scale 2 --speed-sigma 0.1 --element-second-order --diffuse 1 --diffuse-above 0.04 --start-height-sigma 0.01 --replay build/direct/straight-survey.pkl
"""

from __future__ import annotations

import argparse
import functools
import json
import pickle
import shlex
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy.stats import bootstrap
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.design.los import ElevationSigmas, elevation_sigmas
from tunnelkit.design.traceddirect import direct_drive
from tunnelkit.design.verdict import counted_epochs
from tunnelkit.montecarlo import spawn_rngs
from tunnelkit.reproduce.javelin_direct import DIRECT_NUISANCE
from tunnelkit.reproduce.javelin_traced import los_design, los_survey
from tunnelkit.simulation.drives import scenario_route
from tunnelkit.studies.robust_update import HuberUpdater
from tunnelkit.tracking.javelin.runs import draw_start


@functools.cache
def _setup(scenario: str, array: str | None = None):
    """(route, eq. 1's table, design): the traced tables' (``array`` None) or the design's
    traced route of ``array`` with its line-of-sight tracker and that array's survey table."""
    if array is None:
        route = scenario_route(scenario, "exact", "sionna", DIRECT_NUISANCE)
        return route, los_survey(scenario)[0], los_design()
    from tunnelkit.design import DesignSetup, traced, tracedlos

    setup = DesignSetup.from_scenario(scenario, channel="sionna")
    rec = traced.design_errors(setup, array)
    design = tracedlos.los_javelin(traced.traced_javelin(setup, array, rec))
    return traced.traced_route(setup, array), tracedlos.los_table(rec), design


def one(scenario, seed, runs, i, table, second_order, n_epochs, speed_sigma, by_element,
        max_unmodelled, diffuse, diffuse_above, start_height_sigma, huber=None, array=None,
        start_sigma=0.1, drawn_start=False, second_start=False, with_eq1=True, replay=None):  # fmt: skip
    route, eq1, design = _setup(scenario, array)
    eq1 = eq1 if with_eq1 and replay is None else None
    if huber is not None:  # the update with Huber's loss on the whitened rows
        design = design.with_(updater=HuberUpdater(huber))
    rng, start = spawn_rngs(seed, runs)[i], None
    if drawn_start:  # the design's entry fix, drawn from its own generator
        rng, g = rng.spawn(2)
        sh = start_sigma if start_height_sigma is None else start_height_sigma
        start = draw_start(route.trajectory.position[0], start_sigma, g, sh)
    with threadpool_limits(limits=1, user_api="blas"):
        t0 = time.perf_counter()
        r = direct_drive(route, rng, design, eq1, table,
                         speed_sigma=speed_sigma, second_order=second_order,
                         n_epochs=n_epochs, element_second_order=by_element,
                         max_unmodelled=max_unmodelled, diffuse=diffuse,
                         diffuse_above=diffuse_above, start_sigma=start_sigma,
                         start_height_sigma=start_height_sigma, start=start,
                         second_start=second_start, replay=replay)  # fmt: skip
    return i, r, time.perf_counter() - t0


def _interval(x, rng, n=2000) -> tuple[float, float]:
    """The mean's 90 % percentile-bootstrap interval (``n`` resamples)."""
    if len(x) < 2 or np.ptp(x) == 0.0:  # one drive, or dead reckoning's own ratio (every drive 1)
        return float(x[0]), float(x[0])
    ci = bootstrap((x,), np.mean, n_resamples=n, confidence_level=0.9, method="percentile",
                   random_state=rng).confidence_interval  # fmt: skip
    return float(ci.low), float(ci.high)


def report(res, label: str, settled=None, replayed: bool = False) -> str:
    names = list(res[0].estimates)
    rm = np.array([[r.rmse()[t] for t in names] for r in res])  # (runs, trackers)
    rng = np.random.default_rng(0)
    pooled = None
    if settled is not None:  # the horizontal RMSE pooled over drives and settled epochs (the
        # design's rmse_settled) and its gain's 90 % bootstrap interval over the drives
        sq = np.array([[np.mean(np.sum((r.estimates[t][settled, :2] - r.truth[settled, :2]) ** 2,
                                       axis=1)) for t in names] for r in res])  # fmt: skip
        pooled = np.sqrt(sq.mean(axis=0))
        draws = np.random.default_rng(1).integers(0, len(res), size=(2000, len(res)))
        boot = np.sqrt(sq[draws].mean(axis=1))  # (2000, trackers)
        glo, ghi = np.quantile(boot[:, :1] / boot, [0.05, 0.95], axis=0)
    extra = "" if pooled is None else " settled RMSE, pooled [m] | its gain [90 %] |"
    out = [f"### {label}, {len(res)} drives\n",
           "| tracker | mean RMSE [m] | ratio to dead reckoning (per drive: mean [90 %]) | "
           "gain (mean DR / mean tracker) | epochs without a measurement |" + extra,
           "| --- | --- | --- | --- | --- |" + (" --- | --- |" if extra else "")]  # fmt: skip
    for j, t in enumerate(names):
        q = rm[:, j] / rm[:, 0]
        lo, hi = _interval(q, rng)
        drop = sum(r.dropped.get(t, 0) for r in res)
        tail = "" if pooled is None else (
            f" {pooled[j]:.3f} | {pooled[0] / pooled[j]:.2f}x [{glo[j]:.2f}, {ghi[j]:.2f}] |")  # fmt: skip
        out.append(f"| {t} | {rm[:, j].mean():.3f} | {q.mean():.2f} [{lo:.2f}, {hi:.2f}] | "
                   f"{rm[:, 0].mean() / rm[:, j].mean():.2f}x | {drop if j else '-'} |" + tail)  # fmt: skip
    out += ["", "| line of sight fed | n | azimuth error RMS / median abs [deg] | elevation "
            "error RMS / median abs [deg] | extraction per epoch, median [s] |",
            "| --- | --- | --- | --- | --- |"]  # fmt: skip
    for t in [t for t in ("eq. 1", "direct") if t in res[0].los_errors]:
        e = np.degrees(np.concatenate([r.los_errors[t] for r in res]))
        s = np.concatenate([r.seconds[t] for r in res])
        cost = f"{np.median(s):.2f}" if not replayed else "- (replayed)"
        out.append(
            f"| {t} | {len(e)} | {np.sqrt(np.mean(e[:, 1] ** 2)):.2f} / "
            f"{np.median(np.abs(e[:, 1])):.2f} | {np.sqrt(np.mean(e[:, 2] ** 2)):.2f} / "
            f"{np.median(np.abs(e[:, 2])):.2f} | {cost} |"
        )
    u = np.concatenate([r.unmodelled for r in res])
    if u.size:
        q = np.quantile(u, [0.5, 0.9, 0.99])
        out.append(f"\nthe direct fits' unmodelled share ({u.size} converged fits): median "
                   f"{100 * q[0]:.2f} %, 90 % {100 * q[1]:.2f} %, 99 % {100 * q[2]:.2f} %, "
                   f"largest {100 * u.max():.2f} %")  # fmt: skip
    sp = np.concatenate([r.speed_errors for r in res])
    if sp.size:
        out.append(f"\ndirect fit's speed error [m/s] ({sp.size} fits): mean {sp.mean():+.3f}, "
                   f"RMS {np.sqrt(np.mean(sp ** 2)):.3f}, median abs {np.median(np.abs(sp)):.3f}")  # fmt: skip
    return "\n".join(out) + "\n"


def _table(arg: str) -> ElevationSigmas:
    """``--table PATH[:KEY]``: a table (JSON of ``ElevationSigmas.as_dict``) or a record of
    ``data/rt/direct/`` holding one under ``KEY`` (default ``table_deg``; ``told_deg`` the table
    its survey drives were told)."""
    path, _, key = arg.partition(":")
    rec = json.loads(Path(path).read_text())
    if not isinstance(rec, dict):
        raise SystemExit(f"--table: {path} holds no table (a JSON object)")
    if key or "table_deg" in rec:
        key = key or "table_deg"
        if key not in rec:
            raise SystemExit(f"--table: {path} has no {key!r}")
        rec = rec[key]
    return ElevationSigmas.from_dict(rec)


def _drive_all(a, table) -> list:
    """The drives of the parsed options ``a`` told ``table``, two processes at a time (with
    ``--replay``, that run's fixes fed again)."""
    res = [None] * a.runs
    again = [None] * a.runs if a.replay is None else pickle.loads(a.replay.read_bytes())
    if len(again) != a.runs:
        raise SystemExit(f"--replay: {a.replay} holds {len(again)} drives, --runs is {a.runs}")
    with ProcessPoolExecutor(a.workers) as ex:
        futs = [
            ex.submit(one, a.scenario, a.seed, a.runs, i, table, a.second_order, a.n_epochs,
                      a.speed_sigma, a.element_second_order, a.max_unmodelled, a.diffuse,
                      a.diffuse_above, a.start_height_sigma, a.huber, a.design_array,
                      a.start_sigma, a.drawn_start, a.second_start, not a.no_eq1, again[i])
            for i in range(a.runs)
        ]  # fmt: skip
        for f in futs:
            i, r, sec = f.result()
            res[i] = r
            print(f"  drive {i}: {sec:.0f} s, " + ", ".join(
                f"{t} {v:.3f}" for t, v in r.rmse().items()), flush=True)  # fmt: skip
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--runs", type=int, default=6)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--second-order", type=int, default=64)
    ap.add_argument("--speed-sigma", type=float, default=None,
                    help="the direct fit's speed told this sigma [m/s] (default: not used)")  # fmt: skip
    ap.add_argument("--n-epochs", type=int, default=None)
    ap.add_argument("--element-second-order", action="store_true",
                    help="the second-order atoms each on the elements that see it")  # fmt: skip
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--table", help="the direct fix's sigmas by elevation: PATH[:KEY], a JSON "
                   "table or a record of data/rt/direct/ (its KEY, default table_deg)")  # fmt: skip
    g.add_argument("--sigmas", help="one azimuth/elevation sigma pair [deg], e.g. 0.3/0.5")
    ap.add_argument("--sigma-scale", type=float, default=1.0,
                    help="the direct fix's angle sigmas times this (the table's or --sigmas')")  # fmt: skip
    ap.add_argument("--max-unmodelled", type=float, default=None,
                    help="drop a direct fix whose unmodelled share of the power exceeds this")  # fmt: skip
    ap.add_argument("--diffuse", type=int, default=0,
                    help="the direct fit admits at most this many diffuse atoms")  # fmt: skip
    ap.add_argument("--diffuse-above", type=float, default=0.0,
                    help="the diffuse atoms tried only where the tied fit's unmodelled share "
                    "exceeds this")  # fmt: skip
    ap.add_argument("--start-height-sigma", type=float, default=None,
                    help="the start's height told this sigma [m] (default the start's, 0.1 m)")  # fmt: skip
    ap.add_argument("--huber", type=float, default=None,
                    help="every tracker updates with Huber's loss at this many sigmas "
                    "(studies.robust_update.HuberUpdater; default the design's update)")  # fmt: skip
    ap.add_argument("--design-array", default=None,
                    help="the design's traced route of this array (e.g. 8x8), its line-of-sight "
                    "tracker and survey table for eq. 1 (default: the traced tables' route)")  # fmt: skip
    ap.add_argument("--start-sigma", type=float, default=0.1,
                    help="the entry fix's sigma [m] (the design's: 1)")  # fmt: skip
    ap.add_argument("--drawn-start", action="store_true",
                    help="the trackers start from an entry fix drawn with that sigma (as the "
                    "design's), not at the truth")  # fmt: skip
    ap.add_argument("--second-start", action="store_true",
                    help="the direct fit also started from eq. 1's line of sight at the "
                    "predicted range (direct_drive's second_start)")  # fmt: skip
    ap.add_argument("--no-eq1", action="store_true",
                    help="leave out eq. 1's tracker and its extraction (the direct fit's drive "
                    "draws the same snapshots)")  # fmt: skip
    ap.add_argument("--replay", type=Path, default=None,
                    help="feed the fixes of this pickle's drives (--out of an earlier run with "
                    "the same scenario, seed, runs and options) to the trackers told --table / "
                    "--sigmas instead of fitting (direct_drive's replay: seconds, approximate "
                    "for another table); no eq. 1")  # fmt: skip
    ap.add_argument("--write-table", type=Path, default=None)
    ap.add_argument("--bins", type=int, nargs="+", default=[2],
                    help="one table per count; --write-table then names a pattern with {bins}")  # fmt: skip
    ap.add_argument("--out", type=Path, default=None, help="pickle of the drives")
    ap.add_argument("--score", type=Path, default=None,
                    help="report the drives of this pickle (--out of an earlier run) again "
                    "without driving; the other options must be that run's")  # fmt: skip
    a = ap.parse_args(argv)
    if a.replay is not None and a.score is not None:
        ap.error("--replay, --score: give one (a replay drives the trackers again, --score "
                 "re-reports stored drives)")  # fmt: skip
    print("command: python benchmarks/bench_rt_direct.py " + shlex.join(argv or sys.argv[1:]))
    if a.table is not None:
        table = _table(a.table)
    else:
        az, el = (float(v) for v in a.sigmas.split("/"))
        table = ElevationSigmas(np.zeros(1), np.radians([az]), np.radians([el]))
    if a.sigma_scale != 1.0:
        table = table.scaled(a.sigma_scale)
    t0 = time.perf_counter()
    res = pickle.loads(a.score.read_bytes()) if a.score is not None else _drive_all(a, table)
    told = table.as_dict()
    route = _setup(a.scenario, a.design_array)[0]
    try:
        settled = counted_epochs(route.trajectory.t[: res[0].truth.shape[0]])
    except ValueError:  # a drive too short to settle: no settled column
        settled = None
    label = f"{a.scenario}{'' if a.design_array is None else ', design ' + a.design_array}"
    print(f"\n{report(res, f'{label}, seed {a.seed}', settled, a.replay is not None)}\nthe direct fix told (deg): "
          f"{told}; {time.perf_counter() - t0:.0f} s\n")  # fmt: skip
    if a.out is not None:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_bytes(pickle.dumps(res))
    if a.write_table is not None:
        errors = np.concatenate([r.los_errors["direct"] for r in res])
        for b in a.bins:
            new, path = elevation_sigmas(errors, b), Path(str(a.write_table).format(bins=b))
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(new.as_dict(), indent=1) + "\n")
            print(f"table of {len(errors)} epochs, {b} bins -> {path}: {new.as_dict()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
