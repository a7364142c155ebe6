"""The spatial-wideband term in the array design: its position bias along the route per array,
with and without an estimator that models it, and Monte-Carlo of both ML fits against the bound.

Part ``route``: the 28 GHz example (8 x 6 m, ceiling mount, 400 MHz, the README's design
example) for 4 x 4 ... 32 x 32: median and p90 of the PEB, of the wideband position bias of
eq. 1's fit and of the achievable bound, without (``plain``) and with (``modelled``) the term in
the estimator's model, alone and with 0.5 deg of phase calibration error.

Part ``mc``: at one near epoch (8.6 m) the noisy wideband tensor, 400 MHz (792 tones), fitted
by eq. 1's ML (``ml_paths``) and by the wideband ML (``ml_paths(..., wideband=True)``), both
started at the true paths with the number of paths known: per path and parameter the mean
error against the MCRB bias (plain) and the RMSE against the CRLB (modelled).

    PYTHONPATH=$PWD python benchmarks/bench_wideband.py [--part route|mc|both] [--trials N]
        [--arrays 4x4 8x8] [--seed S]

Under ``benchmarks/run.py`` (:func:`cases`) one eq. 1 fit and one wideband fit of the same
tensor are timed (8 x 8, 50 MHz).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from bench_achievable import extraction_errors

from tunnelkit import propagation
from tunnelkit.channel import synthesize
from tunnelkit.design import DesignImpairments, DesignSetup, predicted_error
from tunnelkit.extraction import ml_truth
from tunnelkit.extraction.ml import ml_paths

SCEN = "example-rectangular-28ghz"
ARRAYS = ("4x4", "8x8", "16x16", "32x32")


def _cm(x) -> str:
    return f"{100 * x:7.2f}"


def part_route(arrays=ARRAYS) -> None:
    setup = DesignSetup.from_scenario(SCEN)
    levels = {
        "wideband, plain": DesignImpairments(spatial_wideband=True),
        "wideband, modelled": DesignImpairments(spatial_wideband=True, wideband_model=True),
        "0.5deg+wb, plain": DesignImpairments(0.5, spatial_wideband=True),
        "0.5deg+wb, modelled": DesignImpairments(0.5, spatial_wideband=True, wideband_model=True),
    }
    print(f"\n## {SCEN}: along the route [cm] (median / p90)")
    print(
        f"{'array':6s} {'impairments':20s} {'PEB med':>7s} {'PEB p90':>7s} {'wb med':>7s} "
        f"{'wb p90':>7s} {'ach med':>7s} {'ach p90':>7s}"
    )
    for spec in arrays:
        for name, imp in levels.items():
            b = predicted_error(setup, spec, imp)
            print(
                f"{spec:6s} {name:20s} {_cm(np.median(b.peb))} {_cm(np.percentile(b.peb, 90))} "
                f"{_cm(np.median(b.wideband))} {_cm(np.percentile(b.wideband, 90))} "
                f"{_cm(np.median(b.predicted))} {_cm(np.percentile(b.predicted, 90))}"
            )


def part_mc(arrays, n_trials: int, seed: int) -> None:
    setup = DesignSetup.from_scenario(SCEN)
    ep = len(setup.trajectory.t) - 3
    x = setup.trajectory.position[ep, 0]
    for spec in arrays:
        print(
            f"\n## {spec}, {setup.config.n_tones} tones, epoch {ep} (x = {x:.1f} m), "
            f"{n_trials} trials, seed {seed}"
        )
        res = {}
        for name, wbm in (("plain", False), ("modelled", True)):
            imp = DesignImpairments(spatial_wideband=True, wideband_model=wbm)
            t0 = time.perf_counter()
            err, ex, model = extraction_errors(
                setup, spec, imp, ep, n_trials, np.random.default_rng(seed)
            )
            res[name] = (err, ex, model, time.perf_counter() - t0)
        err, ex, model, dt = res["plain"]
        sd = np.sqrt(np.diagonal(model.crlb[0]).reshape(-1, 4))
        print(
            f"eq. 1's fit ({dt:.0f} s): mean error / MCRB bias (bias in CRLB standard deviations)"
        )
        for p in np.flatnonzero(ex):
            mean = np.nanmean(err[:, p], axis=0)
            cells = [
                f"{m / b:6.3f} ({b / s:+8.1f})" if b else "     -"
                for m, b, s in zip(mean, model.bias[0, p], sd[p], strict=True)
            ]
            print(f"  {model.kinds[p]:8s} " + " ".join(f"{c:>18s}" for c in cells))
        err, ex, model, dt = res["modelled"]
        print(f"wideband fit ({dt:.0f} s): RMSE / CRLB per (phi, psi, kappa, d)")
        z = err[:, ex] / sd[ex]
        for i, p in enumerate(np.flatnonzero(ex)):
            r = np.sqrt(np.nanmean(z[:, i] ** 2, axis=0))
            print(f"  {model.kinds[p]:8s} " + " ".join(f"{v:6.3f}" for v in r))
        pooled = np.sqrt(np.nanmean(z**2, axis=(0, 1)))
        print("  pooled   " + " ".join(f"{v:6.3f}" for v in pooled))


def cases() -> list:
    from run import Case

    setup = DesignSetup.from_scenario(SCEN).variant(bandwidth=50e6)
    ep = len(setup.trajectory.t) - 3
    ue, vel = setup.trajectory.position[ep], setup.trajectory.velocity[ep]
    arr = propagation.select_array(setup.arrays("8x8"), ue)
    paths = propagation.trace_paths(setup.tunnel, arr, ue, vel, fc=setup.fc, kinds=setup.kinds)
    cfg = setup.config
    H = synthesize(paths, cfg, np.random.default_rng(0), clock_bias=0.0, spatial_wideband=True).H
    start = ml_truth(paths, arr, cfg)

    def fit(wb):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return ml_paths(H, len(paths), arr, cfg, start=start, n_reseed=0, wideband=wb)

    return [
        Case(
            "eq. 1 ML fit, 8x8 50 MHz",
            lambda: fit(False),
            group="wideband",
            baseline=True,
            repeat=3,
        ),
        Case("wideband ML fit, 8x8 50 MHz", lambda: fit(True), group="wideband", repeat=3),
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--part", choices=["route", "mc", "both"], default="both")
    ap.add_argument("--trials", type=int, default=30)
    ap.add_argument("--arrays", nargs="+", default=None)
    ap.add_argument("--seed", type=int, default=20261203)
    a = ap.parse_args()
    if a.part in ("route", "both"):
        part_route(a.arrays or ARRAYS)
    if a.part in ("mc", "both"):
        part_mc(a.arrays or ("4x4", "8x8"), a.trials, a.seed)


if __name__ == "__main__":
    main()
