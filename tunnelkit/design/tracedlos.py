"""The traced route's line-of-sight tracker: the line of sight alone, told its sigmas by its elevation.

``tunnelkit design --mode channel --channel sionna --traced-tracker los``. On the ray-traced
channel the reflections' estimates repeat biases of degrees per kind of path, while the line of
sight's angles are nearly unbiased and their size follows the geometry: tenths of a degree where
the line of sight arrives steeply near the site, degrees where it merges with the ceiling's
reflection far from it (``docs/results/traced-robust.md``). This tracker keeps, of every epoch's
ML measurements (the ``"ml-all"`` drive of :func:`tunnelkit.design.traced.design_drive`), the path
taken for the line of sight (:func:`tunnelkit.design.los.los_path`, no truth) and tells JAVELIN
its angle sigmas from a table by measured elevation (:func:`los_table`), surveyed on the same
drives as the ``"paths"`` tracker's errors (the record's ``los_rows``,
:func:`tunnelkit.design.traced.measure_design_errors`: the first 3 drives of seed 0, with their
truth, as a deployment would survey its tunnel once). :func:`told_los` cuts a drive to that path
and tells it the table; :func:`los_javelin` is the tracker that reads what it is told;
:func:`los_summary` what the report says. Its bound over the drive is the told model's
(:func:`tunnelkit.design.tracedbounds.los_bounds`, a prediction).
"""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, instance, integer
from ..tracking.javelin import JavelinDesign, ReportedNoise
from ..tracking.javelin.noise import FixedNoise
from .los import (
    LOS_WINDOW_M,
    ElevationSigmas,
    elevation_sigmas,
    los_only,
    told_by_elevation,
)
from .tracedbounds import config_sigmas

__all__ = ["LOS_BINS", "SUMMARY_KEYS", "los_javelin", "los_summary", "los_table", "told_los"]

#: bins of the measured elevation in the tracker's table (equal counts): four on the survey's
#: 3 drives, compared with 1 and 2 on the studies' seed-0 drives of three scenes
#: (docs/results/traced-robust.md, "The design's line-of-sight tracker"); fewer on a survey of
#: fewer than two epochs per bin (a short route's)
LOS_BINS = 4


def _rows(record) -> np.ndarray:
    """The survey's rows, checked: (measured elevation within +-pi/2, azimuth and elevation errors
    within +-pi) [rad], picked with the window the tracker picks with."""
    if not isinstance(record, dict) or "rows" not in record:
        raise TypeError("record: expected the dict of design.traced.design_errors")
    where = record.get("path", "the record")
    if "los_rows" not in record:
        raise ValueError(
            f"record: {where} holds no survey of the line of sight (los_rows; a record measured "
            "before it was kept): delete it to re-measure"
        )
    if record.get("los_window_m") != LOS_WINDOW_M:
        raise ValueError(
            f"record: {where} surveyed the line of sight picked within "
            f"{record.get('los_window_m')!r} m of the earliest arrival, the tracker picks within "
            f"{LOS_WINDOW_M} m: delete it to re-measure"
        )
    try:
        rows = np.asarray(record["los_rows"], dtype=float).reshape(-1, 3)
    except (TypeError, ValueError):
        raise ValueError(
            "record: los_rows must be rows of three numbers (design.los.los_errors)"
        ) from None
    if len(rows) != len(record["los_rows"]):
        raise ValueError("record: los_rows must be rows of three numbers (design.los.los_errors)")
    rows = finite_array("record['los_rows']", rows, shape=(None, 3))
    if np.any(np.abs(rows[:, 0]) > np.pi / 2) or np.any(np.abs(rows[:, 1:]) > np.pi):
        raise ValueError(
            "record: los_rows hold an elevation beyond +-pi/2 or an angle error beyond +-pi rad"
        )
    return rows


def los_table(record: dict, bins: int | None = None):
    """The tracker's table (:class:`~tunnelkit.design.los.ElevationSigmas`) from ``record``
    (:func:`tunnelkit.design.traced.design_errors`, its ``los_rows``): ``bins`` bins of the
    measured elevation (:func:`~tunnelkit.design.los.elevation_sigmas`), default
    :data:`LOS_BINS` (fewer on a survey of fewer than two epochs per bin)."""
    rows = _rows(record)
    if bins is not None:
        bins = integer("bins", bins, minimum=1)
        try:
            return elevation_sigmas(rows, bins)
        except ValueError as exc:  # too few rows, or tied elevations, for that many bins
            raise ValueError(
                f"bins: {bins} bins of the survey's {len(rows)} epochs: {exc}"
            ) from None
    if rows.shape[0] < 2:
        raise ValueError(
            f"record: a survey of at least 2 epochs with a line of sight, got {rows.shape[0]}"
        )
    b = min(LOS_BINS, rows.shape[0] // 2)
    while True:  # fewer bins where tied elevations leave one short
        try:
            return elevation_sigmas(rows, b)
        except ValueError as exc:
            if b == 1:
                raise ValueError(f"record: los_rows make no table ({exc})") from None
            b -= 1


def los_javelin(design):
    """The line-of-sight tracker: ``design`` (the array's traced tracker,
    :func:`tunnelkit.design.traced.traced_javelin` of its record: its curvature and delay sigmas,
    its fixed sigmas the fallback) reading each measurement's covariance
    (:class:`~tunnelkit.tracking.javelin.ReportedNoise`): it is fed :func:`told_los`'s drive."""
    instance("design", design, JavelinDesign)
    if not isinstance(design.noise, FixedNoise):
        raise TypeError(
            "design: expected the traced tracker (fixed sigmas, traced.traced_javelin), got noise "
            f"{type(design.noise).__name__}"
        )
    return design.with_(noise=ReportedNoise(fallback=design.noise))


def told_los(drive, table, config):
    """``drive`` (an ``"ml-all"`` drive of :func:`tunnelkit.design.traced.design_drive`) cut to
    the path taken for the line of sight each epoch (:func:`~tunnelkit.design.los.los_only`) and
    told its angle sigmas from ``table`` at its measured elevation, the curvature sigma of
    ``config`` (the tracker's JavelinConfig, :func:`los_javelin`) and half its TDoA variance as
    the path's delay variance (:func:`~tunnelkit.design.los.told_by_elevation`). Draws nothing,
    uses no truth."""
    c = config_sigmas(config)
    return told_by_elevation(los_only(drive), table, c["kappa"], c["d"] / np.sqrt(2))


#: the keys of :func:`los_summary`
SUMMARY_KEYS = ("table_deg", "bins", "epochs", "seed", "runs", "window_m", "path")


def los_summary(record: dict, table) -> dict:
    """What the report's JSON says about the tracker's table (``error_model["los"]``): the
    table [deg], its bins, the survey's epochs, seed, runs, window and file."""
    rows = _rows(record)
    if not isinstance(table, ElevationSigmas):
        raise TypeError(f"table: expected a design.los.ElevationSigmas, got {type(table).__name__}")
    return {
        "table_deg": table.as_dict(),
        "bins": int(table.elevation.size),
        "epochs": int(rows.shape[0]),
        "seed": record.get("seed"),
        "runs": record.get("runs"),
        "window_m": record.get("los_window_m"),
        "path": record.get("path"),
    }
