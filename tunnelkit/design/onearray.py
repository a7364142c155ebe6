"""One array's Monte-Carlo summary: :func:`javelin_rmse`, the RMSE of the design's JAVELIN with
a 95 % t-interval, on top of :func:`tunnelkit.design.montecarlo.sweep_montecarlo`."""

from __future__ import annotations

import numpy as np

from .._validate import integer
from ..metrics import settled
from .bounds import path_bounds, route_bounds
from .montecarlo import sweep_montecarlo
from .setup import DesignSetup, parse_array

__all__ = ["javelin_rmse"]


def _t_interval(x: np.ndarray) -> tuple[float, list[float]]:
    """Mean and 95 % t-interval (clipped at 0: an RMSE is not negative)."""
    from scipy import stats

    mean = float(x.mean())
    half = float(stats.t.ppf(0.975, x.size - 1) * x.std(ddof=1) / np.sqrt(x.size))
    return mean, [max(mean - half, 0.0), mean + half]


def javelin_rmse(
    setup: DesignSetup,
    spec,
    runs: int,
    seed: int | np.random.Generator,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    n_epochs: int | None = None,
    crlb: dict | None = None,
    timeout: float | None = None,
) -> dict:
    """Monte-Carlo 2-D RMSE of JAVELIN on ``spec`` with a 95 % t-interval over ``runs`` drives
    (LoS condition, the scenario's route; the interval is clipped at 0).

    Each path's measurement covariance is the one the extraction reports (:func:`javelin_config`),
    and an epoch whose fit fails its own residual test is predict-only. ``crlb`` (default: the
    route-median per-path bounds) only sets the fixed fallback sigmas. Besides the whole-drive
    RMSE (``rmse_m``, as the paper's tables), the settled RMSE leaves out the first
    :data:`SETTLE_S` of every drive (``rmse_settled_m``, ``None`` for a shorter drive) and is set
    beside the RMS of the PEB over the same epochs (``peb_rms_settled_m``); ``median_settled_m``
    is the median over runs of each run's median settled error (the typical epoch, where the
    RMSE also counts the epochs the tracker coasts through without a measurement). Runs go through
    :func:`tunnelkit.montecarlo.run_trials` (``workers`` / ``scheduler`` / ``timeout`` passed on
    when given); ``seed`` is an int or a Generator.
    """
    spec = parse_array(spec)
    runs = integer("runs", runs, minimum=2)
    if not isinstance(seed, np.random.Generator):
        seed = integer("seed", seed, minimum=0)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    if crlb is None:
        pb = path_bounds(setup, spec)
        crlb = {k: float(np.median(pb[k])) for k in ("d", "direction", "kappa")}
    r = sweep_montecarlo(
        setup,
        [spec],
        runs,
        seed,
        mode="channel",
        workers=workers,
        scheduler=scheduler,
        timeout=timeout,
        progress=progress,
        n_epochs=n_epochs,
        crlbs={spec.label: crlb},
    )[spec.label]
    e = r.errors
    whole = np.sqrt(np.mean(e**2, axis=1))
    if r.settled.size:
        es = e[:, r.settled]
        res = np.stack([whole, np.sqrt(np.mean(es**2, axis=1)), np.median(es, axis=1)], axis=1)
    else:
        res = np.stack([whole, np.full(runs, np.nan), np.full(runs, np.nan)], axis=1)
    mean, ci = _t_interval(res[:, 0])
    out = {
        "rmse_m": mean,
        "ci95_m": ci,
        "runs": res[:, 0],
        "rmse_settled_m": None,
        "settled_ci95_m": None,
        "peb_rms_settled_m": None,
        "median_settled_m": None,
        "runs_settled": res[:, 1],
        "sigmas": r.sigmas,
    }
    T = len(setup.trajectory) if n_epochs is None else min(int(n_epochs), len(setup.trajectory))
    idx = settled(setup.trajectory.t[:T])
    if idx.size:
        out["rmse_settled_m"], out["settled_ci95_m"] = _t_interval(res[:, 1])
        out["median_settled_m"] = float(np.median(res[:, 2]))
        peb = route_bounds(setup, spec, epochs=idx).peb
        out["peb_rms_settled_m"] = float(np.sqrt(np.mean(peb**2)))
    return out
