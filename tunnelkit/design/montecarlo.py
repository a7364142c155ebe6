"""JAVELIN on a design: Monte-Carlo drives through the design's signal route.

:func:`javelin_rmse` runs the tracker over drives of the scenario's route through
:func:`tunnelkit.montecarlo.run_trials`; JAVELIN there takes each path's covariance as the
extraction reports it (the CRLB at the estimate, which the ML route attains), so the tracker is
tuned by the design itself at any carrier and size (:func:`javelin_config`), and its settled
RMSE (after the first :data:`SETTLE_S`) is set beside the PEB over the same epochs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import integer
from ..metrics import SETTLE_S, settled
from ..montecarlo import run_trials
from .bounds import path_bounds, route_bounds
from .setup import ArraySpec, DesignSetup, parse_array

__all__ = ["SETTLE_S", "javelin_config", "javelin_rmse"]


def javelin_config(crlb: dict, min_d: float = 0.0):
    """The design's JAVELIN: :func:`tunnelkit.tracking.javelin.designs.array_design` (reported
    covariances, likelihood cost, measured births, the joint innovation test; ``crlb`` sets
    only the fixed fallback sigmas, ``min_d`` Algorithm 1's delay check)."""
    # the tracker and the drive simulator load on the first Monte-Carlo, not with the bounds
    from ..tracking.javelin.designs import array_design

    return array_design(crlb, min_d)


@dataclass(frozen=True)
class _JavelinTrial:
    """One Monte-Carlo run (picklable for Dask workers): a drive of the design's route (no
    visibility draw, the route's own extraction: :func:`tunnelkit.studies.simulate_drive`),
    JAVELIN, its 2-D RMSE over the whole drive, and the RMSE and median of the 2-D error over the
    settled epochs (NaN when the drive is shorter than the start-up)."""

    setup: DesignSetup
    spec: ArraySpec
    design: object  # a tracking.javelin.JavelinDesign
    n_epochs: int | None

    def __call__(self, rng: np.random.Generator) -> tuple[float, float, float]:
        from ..studies import evaluate, settled_errors, simulate_drive

        route = self.setup.signal_route(self.spec)
        drive = simulate_drive(
            route, rng, condition=None, extraction="route", n_epochs=self.n_epochs
        )
        return settled_errors(evaluate(drive, self.design), drive)


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
    if crlb is None:
        pb = path_bounds(setup, spec)
        crlb = {k: float(np.median(pb[k])) for k in ("d", "direction", "kappa")}
    cfg = javelin_config(crlb, setup.signal_route(spec).min_d)
    kw = (("workers", workers), ("scheduler", scheduler), ("timeout", timeout))
    res = np.asarray(
        run_trials(
            _JavelinTrial(setup, spec, cfg, n_epochs),
            runs,
            seed,
            progress=progress,
            desc=f"JAVELIN {spec.label}",
            **{k: v for k, v in kw if v is not None},
        ),
        float,
    ).reshape(runs, 3)
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
        "sigmas": {
            "direction_rad": cfg.config.sigma_phi,
            "kappa_m": cfg.config.sigma_kappa,
            "delta_d_m": cfg.config.sigma_delta_d,
        },
    }
    T = len(setup.trajectory) if n_epochs is None else min(int(n_epochs), len(setup.trajectory))
    idx = settled(setup.trajectory.t[:T])
    if idx.size:
        out["rmse_settled_m"], out["settled_ci95_m"] = _t_interval(res[:, 1])
        out["median_settled_m"] = float(np.median(res[:, 2]))
        peb = route_bounds(setup, spec, epochs=idx).peb
        out["peb_rms_settled_m"] = float(np.sqrt(np.mean(peb**2)))
    return out
