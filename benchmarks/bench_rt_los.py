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
(:func:`~tunnelkit.studies.los_only.los_path`) is the true one.

    python benchmarks/bench_rt_los.py --runs 12 --workers 2
    python benchmarks/bench_rt_los.py --runs 12 --workers 2 --scenario italiano2026-slalom --sigmas 1
    python benchmarks/bench_rt_los.py --runs 12 --workers 2 --array 8x8 --sigmas 1
"""

from __future__ import annotations

import argparse
import functools
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.design import DesignSetup, drive_pcrlb
from tunnelkit.metrics import settled
from tunnelkit.runner import run_trials
from tunnelkit.signal_route import SignalRoute
from tunnelkit.simulation import HELD_OUT_SEED, evaluate, without_radio
from tunnelkit.studies.attribution import scenario_with_array
from tunnelkit.studies.los_only import los_angle_information, los_design, los_only, los_path
from tunnelkit.studies.traced import simulate_traced, traced_design
from tunnelkit.tracking.javelin import draw_start

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
    d = simulate_traced(route, rng, condition="L", channel="sionna")
    return {k: d[k] for k in ("ml-all", "ml-traced")}


def _rmse(drive, truth, design, p0, sigma, idx) -> float:
    ev = evaluate(drive, design, sigma_p0_ue=sigma, start=p0, sigma_p0_height=START_HEIGHT)
    e = np.linalg.norm(ev.estimates[:, :2] - truth[:, :2], axis=1)[idx]
    return float(np.sqrt(np.mean(e**2)))


def score(drives, seed, sigmas, start_sigma) -> dict:
    """Mean RMSE per tracker over ``drives`` (the starts from a stream of their own)."""
    rng = np.random.default_rng([seed, 1])
    td = traced_design()
    designs = {f"LoS only, {s:g} deg": los_design(float(np.radians(s)), td) for s in sigmas}
    out = {"traced design": [], "dead reckoning": [], **{k: [] for k in designs}}
    los_share = []
    for dd in drives:
        tr, every = dd["ml-traced"], dd["ml-all"]
        p0 = draw_start(tr.truth[0], start_sigma, rng, START_HEIGHT)
        idx = settled(tr.t)
        out["traced design"].append(_rmse(tr, tr.truth, td, p0, start_sigma, idx))
        out["dead reckoning"].append(_rmse(without_radio(tr), tr.truth, td, p0, start_sigma, idx))
        los = los_only(every)
        for k, d in designs.items():
            out[k].append(_rmse(los, tr.truth, d, p0, start_sigma, idx))
        for ep, ti in zip(every.epochs, every.truth_index, strict=True):
            if ep is not None and len(ep):
                los_share.append(int(ti[los_path(ep.d, ep.psi)]) == 0)
    res = {k: float(np.mean(v)) for k, v in out.items()}
    res["_los_share"] = float(np.mean(los_share)) if los_share else float("nan")
    return res


def reference(drive, sigma_deg, start_sigma, scenario=SCENARIO) -> float:
    """Settled RMS of the drive's posterior CRLB of the LoS angles at ``sigma_deg``."""
    setup = DesignSetup.from_scenario(scenario)
    T = len(drive.truth)
    info = los_angle_information(drive.truth, drive.base_station, float(np.radians(sigma_deg)))
    b = drive_pcrlb(setup, info[:T], sigma_p0=start_sigma)
    idx = settled(drive.t)
    return float(np.sqrt(np.mean(b[idx] ** 2)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=12)
    ap.add_argument("--scenario", default=SCENARIO, help="a preset with a ray-traced channel")
    ap.add_argument("--array", default=None, help="replace the preset's arrays, e.g. 8x8")
    ap.add_argument("--sigmas", type=float, nargs="+", default=[0.5, 1.0, 2.0, 4.0, 8.0])
    ap.add_argument("--start-sigma", type=float, default=1.0)
    ap.add_argument("--workers", type=int, default=None)
    a = ap.parse_args()
    chosen = None
    for seed in (0, HELD_OUT_SEED):
        t0 = time.perf_counter()
        case = (a.scenario, a.array)
        drives = run_trials(_drive, a.runs, seed, inputs=[case] * a.runs, workers=a.workers)
        sigmas = a.sigmas if chosen is None else [chosen]
        res = score(drives, seed, sigmas, a.start_sigma)
        if chosen is None:  # chosen on seed 0, the lowest mean RMSE of the grid
            chosen = min(sigmas, key=lambda s: res[f"LoS only, {s:g} deg"])
        ref = reference(drives[0]["ml-traced"], chosen, a.start_sigma, a.scenario)
        dr = res["dead reckoning"]
        arrays = "" if a.array is None else f" with {a.array} arrays"
        print(f"\nseed {seed}: {a.runs} drives of {a.scenario}{arrays}, traced channel, L, entry fix "
              f"{a.start_sigma:g} m ({time.perf_counter() - t0:.0f} s); path taken = the "
              f"true LoS in {100 * res['_los_share']:.1f} % of the epochs")  # fmt: skip
        print("| tracker | RMSE [m] | gain over dead reckoning |\n| --- | --- | --- |")
        for k, v in res.items():
            if not k.startswith("_"):
                print(f"| {k} | {v:.3f} | {dr / v:.2f}x |")
        print(f"| posterior CRLB of the LoS angles at {chosen:g} deg (told model, first drive) "
              f"| {ref:.3f} | |")  # fmt: skip
    print(f"\nangle sigma chosen on seed 0: {chosen:g} deg")


if __name__ == "__main__":
    main()
