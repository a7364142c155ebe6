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
from ..montecarlo import run_trials
from .bounds import path_bounds, route_bounds
from .setup import ArraySpec, DesignSetup, parse_array

__all__ = ["SETTLE_S", "SIGMA_HEADING", "SIGMA_SPEED", "javelin_config", "javelin_rmse"]

#: V2X speed [m/s] and heading [rad] message noise of the Monte-Carlo drives (section 4.2)
SIGMA_SPEED, SIGMA_HEADING = 0.2, float(np.radians(1.0))


def javelin_config(crlb: dict, min_d: float = 0.0):
    """JAVELIN (our design, curvature centred on the VUE) for a design sweep at any carrier and
    array size: every path's measurement covariance is the one the extraction reports (the CRLB
    at its estimate, which the ML route attains: ``measurement_noise="reported"``), so no
    5.9 GHz constant enters; pairs are ranked by ``eta^2 + ln det S``
    (``association_cost="likelihood"``), so a new, wide track cannot take a path an established
    track predicts to a millimetre; and a VUE is born with the covariance of the angles that
    placed it (``birth_covariance="measured"``), not 10 m, so two new tracks a few degrees apart
    cannot swap their paths in the next epoch; and pairs whose stacked innovation is
    inconsistent are left out of the update (``update_gate=0.999``), which catches a wrong LoS
    taken by eq. 61 after the per-pair gate missed the true one. ``min_d``: Algorithm 1's delay
    check (``-c b_max`` keeps the paths a negative clock bias pushed below zero). The fixed sigmas, used only in an epoch whose Fisher information is
    singular at the estimate, are ``crlb`` (``d`` [m], ``direction`` [rad], ``kappa`` [m]; e.g.
    an upper percentile of the route's per-path bounds); ``sigma_delta_d`` is ``sqrt(2)`` times
    the delay-distance sigma (a difference of two delays).
    """
    from ..tracking.javelin.experiment import OURS

    def pick(k):
        v = crlb.get(k)
        if v is None or not np.isfinite(v) or v <= 0:
            raise ValueError(f"crlb: {k!r} must be finite and > 0, got {v!r}")
        return float(v)

    ang, kap, d = pick("direction"), pick("kappa"), pick("d")
    return OURS.with_(
        kappa_model="vue",
        measurement_noise="reported",
        association_cost="likelihood",
        birth_covariance="measured",
        update_gate=0.999,
        min_d=float(min_d),
        sigma_phi=ang,
        sigma_psi=ang,
        sigma_kappa=kap,
        sigma_delta_d=float(np.sqrt(2.0) * d),
    )


def _drive(route, rng: np.random.Generator, n_epochs: int | None):
    """One LoS drive through the design's signal route (:meth:`DesignSetup.signal_route`)."""
    import warnings

    from ..tracking.javelin.experiment import CONDITIONS, DriveData
    from ..tracking.javelin.measurement import PathMeasurements

    traj = route.trajectory
    T = len(traj) if n_epochs is None else min(int(n_epochs), len(traj))
    epochs, faults = [], []
    n_true = np.zeros(T, int)
    bs = route.arrays[0].origin.copy()
    for k in range(T):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                ep = route.epoch(k, rng)
            except (ValueError, np.linalg.LinAlgError) as exc:
                faults.append(f"epoch {k}: extraction failed ({exc})")
                epochs.append(None)
                continue
        m = ep.measurements
        bs = m.origin.copy()
        n_true[k] = len(ep.paths)
        if m.cov is None and len(m):
            # the fit failed its residual test (or its Fisher information is singular): no
            # covariance to trust, so no measurement this epoch
            faults.append(f"epoch {k}: extraction failed its residual test")
            epochs.append(None)
            continue
        epochs.append(
            PathMeasurements.from_arrays(
                m.phi,
                m.psi,
                m.kappa,
                m.d,
                m.v,
                warn=False,
                cov=m.cov,
                sigma_d=m.sigma_d,
                min_d=route.min_d,
            )
        )
    vel = traj.velocity[:T]
    speed = np.linalg.norm(vel[:, :2], axis=1) + SIGMA_SPEED * rng.standard_normal(T)
    heading = np.arctan2(vel[:, 1], vel[:, 0]) + SIGMA_HEADING * rng.standard_normal(T)
    drive = DriveData(
        "design",
        CONDITIONS["L"],
        traj.t[:T].copy(),
        traj.position[:T].copy(),
        vel.copy(),
        speed,
        heading,
        epochs,
        n_true > 0,
        n_true,
        bs,
        faults=faults,
    )
    return drive


#: the first second of a drive is the tracker's start-up (an open-sky fix with 1 m of
#: uncertainty, the VUE tracks born over the first epochs): the settled RMSE leaves it out
SETTLE_S = 1.0


def _settled(t: np.ndarray) -> np.ndarray:
    """Indices of the epochs at least :data:`SETTLE_S` after the start."""
    return np.flatnonzero(t - t[0] >= SETTLE_S - 1e-9)


@dataclass(frozen=True)
class _JavelinTrial:
    """One Monte-Carlo run (picklable for Dask workers): a drive, JAVELIN, its 2-D RMSE over the
    whole drive, and the RMSE and median of the 2-D error over the settled epochs (NaN when the
    drive is shorter than the start-up)."""

    setup: DesignSetup
    spec: ArraySpec
    config: object
    n_epochs: int | None

    def __call__(self, rng: np.random.Generator) -> tuple[float, float, float]:
        from ..tracking.javelin.experiment import evaluate

        drive = _drive(self.setup.signal_route(self.spec), rng, self.n_epochs)
        ev = evaluate(drive, self.config)
        idx = _settled(drive.t)
        e = np.linalg.norm(ev.estimates[idx, :2] - drive.truth[idx, :2], axis=1)
        rmse, med = (np.sqrt(np.mean(e**2)), np.median(e)) if idx.size else (np.nan, np.nan)
        return float(ev.metrics["rmse_2d_m"]), float(rmse), float(med)


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
            "direction_rad": cfg.sigma_phi,
            "kappa_m": cfg.sigma_kappa,
            "delta_d_m": cfg.sigma_delta_d,
        },
    }
    T = len(setup.trajectory) if n_epochs is None else min(int(n_epochs), len(setup.trajectory))
    idx = _settled(setup.trajectory.t[:T])
    if idx.size:
        out["rmse_settled_m"], out["settled_ci95_m"] = _t_interval(res[:, 1])
        out["median_settled_m"] = float(np.median(res[:, 2]))
        peb = route_bounds(setup, spec, epochs=idx).peb
        out["peb_rms_settled_m"] = float(np.sqrt(np.mean(peb**2)))
    return out
