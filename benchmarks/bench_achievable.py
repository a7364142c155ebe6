"""The achievable (misspecified) bound against Monte-Carlo of the actual extraction, and the
design's bounds along the route.

Part 1 (validation): at one near epoch, impaired tensors are synthesised (calibration drawn per
trial, diffuse multipath per trial, noise), the joint ML extraction
(:func:`tunnelkit.extraction.ml.ml_paths`, number of paths known, started at the true paths)
measures every path, and the RMSE of each ``z = [phi, psi, kappa, d]`` is set beside the
predicted ``sqrt(bias^2 + E[calibration bias^2] + var)`` of
:func:`tunnelkit.design.path_error_model`. Part 2: median PEB and median / p90 achievable bound
along the route per array, ideal and impaired, and the time per array (median of three runs).

    PYTHONPATH=$PWD python benchmarks/bench_achievable.py [--trials N] [--part 1|2|both]

Under ``benchmarks/run.py`` (:func:`cases`) only the route bounds are timed (the ideal PEB and
the achievable bound of the 28 GHz tunnel, 8 x 8 and 32 x 32); the tables come from the command
line above (the Monte-Carlo part takes minutes).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from scipy.optimize import linear_sum_assignment

from tunnelkit import propagation
from tunnelkit.channel import synthesize
from tunnelkit.design import DesignImpairments, DesignSetup, path_error_model, predicted_error
from tunnelkit.design.setup import parse_array
from tunnelkit.extraction.ml import ml_paths

Z = ("phi", "psi", "kappa", "d")


def predicted_rmse(model, t: int = 0) -> np.ndarray:
    """``sqrt(bias^2 + E[calibration bias^2] + var)`` (P, 4) at epoch ``t`` of a
    :class:`~tunnelkit.design.PathErrorModel`."""
    P = model.exists.shape[1]
    mse = model.bias[t] ** 2 + np.diagonal(model.cov[t]).reshape(P, 4)
    if model.k_phase is not None:
        mse = mse + model.phase_sigma_rad**2 * np.sum(model.k_phase[t] ** 2, axis=-1)
        mse = mse + model.gain_sigma_db**2 * np.sum(model.k_gain[t] ** 2, axis=-1)
    return np.sqrt(mse)


def extraction_errors(
    setup, spec, imp, epoch: int, n_trials: int, rng, n_reseed=0, wideband: bool | None = None
) -> tuple:
    """Monte-Carlo of the ML extraction at ``epoch``: errors (n_trials, P, 4) in ``z`` (NaN
    where a path is absent or reported far field), the route slots ``exists`` (P,). The
    extraction models the spatial-wideband term (``ml_paths(..., wideband=True)``) when
    ``wideband``, by default when ``imp.wideband_model``."""
    wideband = imp.wideband_model if wideband is None else wideband
    spec = parse_array(spec)
    traj = setup.trajectory
    ue, vel = traj.position[epoch], traj.velocity[epoch]
    arrays = setup.arrays(spec)
    arr = propagation.select_array(arrays, ue)
    paths = propagation.trace_paths(setup.tunnel, arr, ue, vel, fc=setup.fc, kinds=setup.kinds)
    model = path_error_model(setup, spec, imp, epochs=[epoch])
    ex = model.exists[0]
    truth = model.truth[0]
    # the slot of every traced path: match by delay distance (ties are impossible here)
    slots = [int(np.argmin(np.where(ex, np.abs(truth[:, 3] - p.length), np.inf))) for p in paths]
    ch = imp.channel_impairments()
    cfg = setup.config
    src = np.stack([arr.to_local(p.source) for p in paths])
    th = np.column_stack(
        [src[:, :2] / np.linalg.norm(src, axis=1)[:, None], 1 / np.linalg.norm(src, axis=1)]
    )
    start = (
        th,
        -2 * np.pi * cfg.tone_spacing * np.array([p.length for p in paths]) / 299792458.0,
        2 * np.pi * cfg.symbol_period * np.array([p.doppler for p in paths]),
    )
    pred = predicted_rmse(model)
    out = np.full((n_trials, ex.size, 4), np.nan)
    for n in range(n_trials):
        cal = ch.draw(rng, arr.M)
        snap = synthesize(
            paths,
            cfg,
            rng,
            clock_bias=0.0,
            calibration=cal,
            spatial_wideband=ch.spatial_wideband,
            dmc=ch.dmc,
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            est = ml_paths(
                snap.H, len(paths), arr, cfg, start=start, n_reseed=n_reseed, wideband=wideband
            )
        dw = est.direction @ arr.R.T  # world unit vectors
        z = np.column_stack(
            [
                np.arctan2(dw[:, 1], dw[:, 0]),
                np.arctan2(dw[:, 2], np.hypot(dw[:, 0], dw[:, 1])),
                est.kappa,
                est.d,
            ]
        )
        # each true path to one estimate: the assignment closest in (phi, psi, d) standard units
        e = z[None, :, :] - truth[slots][:, None, :]
        e[..., 0] = (e[..., 0] + np.pi) % (2 * np.pi) - np.pi
        cost = np.sum((e[..., [0, 1, 3]] / pred[slots][:, None, [0, 1, 3]]) ** 2, axis=-1)
        r, c = linear_sum_assignment(cost)
        out[n, np.array(slots)[r]] = e[r, c]
    return out, ex, model


#: an error beyond this many predicted RMSEs in phi, psi or d is a gross error (a threshold
#: failure of the extraction: a path lost or swapped), counted apart
GROSS = 6.0


def validate(setup, spec, imp, epoch, n_trials, rng):
    """Per existing path: (kind, predicted RMSE (4,), Monte-Carlo RMSE without gross errors
    (4,), share of gross errors, kappa resolved: predicted kappa RMSE below a tenth of the
    range)."""
    err, ex, model = extraction_errors(setup, spec, imp, epoch, n_trials, rng)
    pred = predicted_rmse(model)
    rows = []
    for p in np.flatnonzero(ex):
        e = err[:, p]
        gross = np.any(np.abs(e[:, [0, 1, 3]]) > GROSS * pred[p, [0, 1, 3]], axis=1)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            mc = np.sqrt(np.nanmean(e[~gross] ** 2, axis=0))
        resolved = pred[p, 2] < 0.1 * model.truth[0, p, 2]
        rows.append((model.kinds[p], pred[p], mc, float(gross.mean()), bool(resolved)))
    return rows


LEVELS = {
    "ideal": DesignImpairments(),
    "0.5deg": DesignImpairments(phase_error_deg=0.5),
    "2deg": DesignImpairments(phase_error_deg=2.0),
    "0.2dB": DesignImpairments(gain_error_db=0.2),
    "wideband": DesignImpairments(spatial_wideband=True),
    "dmc0.01": DesignImpairments(dmc_share=0.01),
    "dmc0.1": DesignImpairments(dmc_share=0.1),
}


def part1(n_trials: int, seed: int = 1) -> None:
    cases = [
        ("example-rectangular-28ghz", "8x8", dict(bandwidth=50e6), -3),
        ("example-rectangular-28ghz", "4x4", dict(bandwidth=50e6), -3),
        ("italiano2026-straight", "8x8", dict(bandwidth=20e6), -3),
    ]
    for scen, spec, kw, epoch in cases:
        setup = DesignSetup.from_scenario(scen).variant(**kw)
        ep = len(setup.trajectory.t) + epoch
        x = setup.trajectory.position[ep, 0]
        print(
            f"\n## {scen} {spec}, {setup.config.n_tones} tones, epoch {ep} (x = {x:.1f} m), "
            f"{n_trials} trials: predicted / Monte-Carlo RMSE (ratio MC/pred)"
        )
        print(f"{'level':9s} {'path':8s} " + " ".join(f"{z:>27s}" for z in Z))
        for name, imp in LEVELS.items():
            rows = validate(setup, spec, imp, ep, n_trials, np.random.default_rng(seed))
            for kind, pr, mc, gross, resolved in rows:
                cells = [f"{p:9.3g} {m:9.3g} ({m / p:5.2f})" for p, m in zip(pr, mc, strict=True)]
                if not resolved:
                    cells[2] += "*"
                print(
                    f"{name:9s} {kind:8s} "
                    + " ".join(f"{c:>27s}" for c in cells)
                    + f"  gross {100 * gross:4.1f} %"
                )
        print("* kappa not resolved (predicted RMSE above a tenth of the range): below threshold")


def part2() -> None:
    imps = {
        "ideal": DesignImpairments(),
        "0.5deg+0.2dB+wb": DesignImpairments(0.5, 0.2, True),
        "2deg+0.2dB+wb": DesignImpairments(2.0, 0.2, True),
    }
    for scen in ("italiano2026-straight", "example-rectangular-28ghz"):
        setup = DesignSetup.from_scenario(scen)
        print(f"\n## {scen}: PEB and achievable bound along the route [m]")
        print(
            f"{'array':6s} {'impairments':16s} {'PEB med':>9s} {'ach med':>9s} {'ach p90':>9s} "
            f"{'cal med':>9s} {'wb med':>9s} {'time s':>7s}"
        )
        for spec in ("4x4", "8x8", "16x16", "32x32"):
            try:
                setup.arrays(spec)
            except ValueError as e:
                print(f"{spec:6s} does not fit: {e}")
                continue
            for name, imp in imps.items():
                times = []
                for _ in range(3):  # the median of three runs (the machine is shared)
                    t0 = time.perf_counter()
                    b = predicted_error(setup, spec, imp)
                    times.append(time.perf_counter() - t0)
                dt = float(np.median(times))
                print(
                    f"{spec:6s} {name:16s} {np.median(b.peb):9.3g} {np.median(b.predicted):9.3g} "
                    f"{np.percentile(b.predicted, 90):9.3g} {np.median(b.calibration):9.3g} "
                    f"{np.median(b.wideband):9.3g} {dt:7.2f}"
                )


def cases() -> list:
    from run import Case

    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    imp = DesignImpairments(0.5, 0.2, True, 0.1)
    out = []
    for spec in ("8x8", "32x32"):
        out.append(
            Case(
                f"route PEB only, 28 GHz {spec}",
                lambda s=spec: predicted_error(setup, s),
                group=f"achievable_{spec}",
                baseline=True,
                repeat=5,
            )
        )
        out.append(
            Case(
                f"achievable, 0.5 deg 0.2 dB wideband DMC 0.1, 28 GHz {spec}",
                lambda s=spec: predicted_error(setup, s, imp),
                group=f"achievable_{spec}",
                repeat=5,
            )
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=200)
    ap.add_argument("--part", choices=("1", "2", "both"), default="both")
    a = ap.parse_args()
    if a.part in ("1", "both"):
        part1(a.trials)
    if a.part in ("2", "both"):
        part2()


if __name__ == "__main__":
    main()
