"""Scoring a tracker on simulated drives: error metrics, settled errors (the baselines, TeNFiLoc's
fixes and dead reckoning: :mod:`tunnelkit.simulation.baselines`).

:func:`evaluate` runs JAVELIN (any :class:`~tunnelkit.tracking.javelin.roles.JavelinDesign`) or
the TeNFiLoc snapshot baseline on a :class:`~tunnelkit.simulation.drives.DriveData` and scores it:
:func:`error_metrics` gives the 2-D RMSE, 2-D MAE and Y-MAE of Tables 1-2. The first
:data:`SETTLE_S` of a drive is the tracker's start-up (an open-sky fix with 1 m of uncertainty,
the VUE tracks born over the first epochs); :func:`settled` selects the epochs after it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checks import attributes
from .._validate import finite_array, instance, record, text
from ..settling import SETTLE_S, settled
from ..tracking import registry
from ..tracking.javelin.designs import paper
from ..tracking.javelin.roles import JavelinDesign
from ..tracking.javelin.tracker import JavelinRun
from .drives import DriveData

__all__ = [
    "SETTLE_S",
    "Evaluation",
    "error_metrics",
    "evaluate",
    "settled",
    "settled_errors",
]


def error_metrics(estimates, truth) -> dict[str, float]:
    """2-D RMSE, 2-D MAE (mean Euclidean error in the road plane) and Y-MAE (lateral) [m]."""
    a, b = finite_array("estimates", estimates), finite_array("truth", truth)
    if a.shape != b.shape or a.ndim == 0 or a.shape[-1] < 2:
        raise ValueError(
            f"estimates, truth: expected positions of one shape, got {a.shape}, {b.shape}"
        )
    e = np.asarray(estimates, float)[..., :2] - np.asarray(truth, float)[..., :2]
    e2 = np.linalg.norm(e, axis=-1)
    return {
        "rmse_2d_m": float(np.sqrt(np.mean(e2**2))),
        "mae_2d_m": float(np.mean(e2)),
        "y_mae_m": float(np.mean(np.abs(e[..., 1]))),
    }


@dataclass
class Evaluation:
    """Tracker output on one drive and its error metrics."""

    estimates: np.ndarray
    metrics: dict[str, float]
    run: JavelinRun | None = None

    def __post_init__(self) -> None:
        record(self, shapes={"estimates": (None, 3)})


def evaluate(
    drive: DriveData,
    design: JavelinDesign | None = None,
    *,
    method: str = "JAVELIN",
    keep_reports: bool = False,
    sigma_p0_ue: float = 1.0,
    start=None,
    sigma_p0_height: float | None = None,
) -> Evaluation:
    """Run ``method`` ("JAVELIN" with ``design``, default the paper's, or "TeNFiLoc") on
    ``drive`` and score it against the truth.

    JAVELIN starts from ``start`` (3,) [m], default the true first position (the open-sky fix
    the paper assumes, as the tables do), with ``sigma_p0_ue`` [m] of uncertainty; the base
    station is the drive's reference antenna; ``sigma_p0_height`` (default ``sigma_p0_ue``) the
    height's. The design's Monte-Carlo gives a start drawn with
    that uncertainty (:func:`tunnelkit.tracking.javelin.draw_start`).
    """
    if not isinstance(drive, DriveData):
        raise TypeError(f"drive: expected a DriveData, got {type(drive).__name__}")
    try:
        cls = registry.get("italiano2026", text("method", method))
    except ValueError:
        members = list(registry.family("italiano2026"))
        raise ValueError(f"method: expected one of {members}, got {method!r}") from None
    if method == "TeNFiLoc":
        if start is not None:
            raise ValueError("start: TeNFiLoc is a snapshot method and takes no start")
        est, _ = cls.for_drive(drive).track(drive)
        return Evaluation(est, error_metrics(est, drive.truth))
    d = paper() if design is None else design
    if not isinstance(d, JavelinDesign):
        raise TypeError(f"design: expected a JavelinDesign, got {type(d).__name__}")
    if d.requires_reported_covariance() and not drive.reports_covariance:
        raise ValueError(
            f"design, drive: the noise role {d.noise!r} needs a measurement route that reports "
            f"each path's covariance, but the drive's route ({drive.extraction!r}) reports none "
            "(RouteOptions(report_covariance=True))"
        )
    est, run = cls.for_drive(
        drive, d, sigma_p0_ue=sigma_p0_ue, start=start, sigma_p0_height=sigma_p0_height
    ).track(drive, keep_reports=keep_reports)
    return Evaluation(run.estimates, error_metrics(run.estimates, drive.truth), run)


def settled_errors(ev: Evaluation, drive: DriveData) -> tuple[float, float, float]:
    """The 2-D RMSE over the whole drive, and the RMSE and median of the 2-D error over the
    settled epochs (NaN when the drive is shorter than the start-up)."""
    attributes("ev", ev, ("estimates", "metrics"), "a simulation.scoring.Evaluation")
    instance("drive", drive, DriveData)
    idx = settled(drive.t)
    e = np.linalg.norm(ev.estimates[idx, :2] - drive.truth[idx, :2], axis=1)
    rmse, med = (np.sqrt(np.mean(e**2)), np.median(e)) if idx.size else (np.nan, np.nan)
    return float(ev.metrics["rmse_2d_m"]), float(rmse), float(med)
