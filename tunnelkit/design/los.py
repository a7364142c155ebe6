"""The line of sight told its sigmas by its elevation: the traced route's line-of-sight tracker.

On the ray-traced channel the reflections' estimates are biased by degrees per kind of path and
the bias repeats from epoch to epoch, while the line of sight's angles are nearly unbiased
(``docs/results/traced-robust.md``). The design's line-of-sight tracker on that channel
(``tunnelkit design --mode channel --channel sionna --traced-tracker los``) keeps, of every epoch's ML
measurements, the one path taken for the line of sight and tells JAVELIN its angle sigmas from a
table measured by the line of sight's elevation:

* :func:`los_path` picks it without truth: the line of sight arrives first, but under a
  ceiling-mounted site the ceiling's reflection follows within centimetres and the delay errors
  swap them, so of the arrivals within ``window`` (:data:`LOS_WINDOW_M`) of the earliest it takes
  the lowest in elevation (the ceiling's image lies above the array); :func:`los_only` cuts a
  drive to that path.
* The picked path is accurate where it arrives steeply and off by degrees where it arrives at a
  shallow angle (near the site the line of sight and the ceiling's reflection are further apart
  than the array resolves; far from it they merge). :func:`los_errors` measures its errors
  against the true line of sight on surveyed drives; :func:`elevation_sigmas` summarises them as
  an :class:`ElevationSigmas` table, the RMS of each angle in bins of the *measured* elevation
  (the tracker does not know its range, but under a site above the road the elevation falls
  monotonically with it); :func:`told_by_elevation` gives every epoch its covariance from the
  table, read by :class:`~tunnelkit.tracking.javelin.ReportedNoise`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._domains import positive_array
from .._validate import finite_array, instance, integer, nonnegative, positive
from ..angles import wrap_angle
from ..geometry import spherical, spherical_jacobian
from ..simulation import DriveData

__all__ = [
    "LOS_WINDOW_M",
    "ElevationSigmas",
    "angle_sigma",
    "elevation_sigmas",
    "los_angle_information",
    "los_error_rows",
    "los_errors",
    "los_only",
    "los_path",
    "told_by_elevation",
]


#: the arrivals within this delay distance of the earliest are candidates for the LoS [m] (chosen
#: on seed 0 of the straight drive among 0.3 / 0.6 / 1.0 m, docs/results/traced-robust.md)
LOS_WINDOW_M = 0.3


def los_path(d, psi, window: float = LOS_WINDOW_M) -> int:
    """The index of the path taken for the line of sight among delay distances ``d`` (L,) [m]
    and elevations ``psi`` (L,) [rad]: of the arrivals within ``window`` [m] of the earliest, the
    lowest in elevation (``window = 0``: the earliest)."""
    d = finite_array("d", d, ndim=1)
    psi = finite_array("psi", psi, shape=d.shape)
    window = nonnegative("window", window)
    if d.size == 0:
        raise ValueError("d: no path to choose from")
    near = np.flatnonzero(d <= d.min() + float(window))
    return int(near[np.argmin(psi[near])])


def los_only(drive, window: float = LOS_WINDOW_M):
    """``drive`` (a :class:`tunnelkit.simulation.DriveData`) with each epoch's measurements cut
    to the path :func:`los_path` takes for the line of sight (an epoch without measurements
    stays ``None``). Draws nothing, uses no truth."""

    drive = instance("drive", drive, DriveData)
    window = nonnegative("window", window)  # checked here once for every epoch
    epochs = [
        None
        if ep is None or len(ep) == 0
        else ep.subset(np.array([los_path(ep.d, ep.psi, window)]))
        for ep in drive.epochs
    ]
    return replace(drive, epochs=epochs)


@dataclass(frozen=True)
class ElevationSigmas:
    """The line of sight's angle sigmas by measured elevation: bin centres ``elevation`` (B,)
    [rad], strictly increasing, and the azimuth's and the elevation's sigma there (B,) [rad];
    between centres linear, beyond the ends the end's value (:meth:`at`)."""

    elevation: np.ndarray
    sigma_azimuth: np.ndarray
    sigma_elevation: np.ndarray

    def __post_init__(self) -> None:
        el = finite_array("elevation", self.elevation, ndim=1)
        if el.size == 0 or np.any(np.diff(el) <= 0) or np.any(np.abs(el) > np.pi / 2):
            raise ValueError(
                "elevation: expected strictly increasing bin centres within +-pi/2 rad"
            )
        for name in ("sigma_azimuth", "sigma_elevation"):
            s = positive_array(name, getattr(self, name), shape=el.shape)
            if np.any(s > np.pi):
                raise ValueError(f"{name}: an angle sigma of at most pi rad, got {s.max():g}")
            object.__setattr__(self, name, s)
        object.__setattr__(self, "elevation", el)

    def at(self, psi) -> tuple[np.ndarray, np.ndarray]:
        """The azimuth's and the elevation's sigma (L,) [rad] at measured elevations ``psi``
        (L,) [rad]."""
        psi = finite_array("psi", psi, ndim=1)
        return (
            np.interp(psi, self.elevation, self.sigma_azimuth),
            np.interp(psi, self.elevation, self.sigma_elevation),
        )

    def scaled(self, factor) -> ElevationSigmas:
        """The same bins with both sigmas times ``factor`` (> 0): a survey's RMS told with a
        margin."""
        k = positive("factor", factor)
        return ElevationSigmas(self.elevation, k * self.sigma_azimuth, k * self.sigma_elevation)

    def as_dict(self) -> dict:
        """The table in degrees, for JSON."""
        return {k: np.degrees(getattr(self, k)).round(6).tolist() for k in _FIELDS}

    def describe(self) -> str:
        """The table as one line of text: ``"<elevation> deg: <azimuth> / <elevation sigma>
        deg"`` per bin, in degrees (the reports' notes)."""
        t = self.as_dict()
        return "; ".join(
            f"{e:.1f} deg: {a:.2f} / {b:.2f} deg"
            for e, a, b in zip(*(t[k] for k in _FIELDS), strict=True)
        )

    @classmethod
    def from_dict(cls, table: dict) -> ElevationSigmas:
        """The table of :meth:`as_dict`."""
        instance("table", table, dict)
        missing = [k for k in _FIELDS if k not in table]
        if missing:
            raise ValueError(f"table: missing {missing} (expected the keys {list(_FIELDS)})")
        return cls(*(np.radians(np.asarray(table[k], float)) for k in _FIELDS))


_FIELDS = ("elevation", "sigma_azimuth", "sigma_elevation")


def los_error_rows(phi, psi, sight) -> np.ndarray:
    """The survey's rows of measured line-of-sight angles ``phi``, ``psi`` (N,) [rad] against
    the true line of sight ``sight`` (N, 3) [m] (from the site to the UE): ``(measured
    elevation, azimuth error, elevation error)`` [rad], the azimuth's wrapped, (N, 3)."""
    phi = finite_array("phi", phi, ndim=1)
    psi = finite_array("psi", psi, shape=phi.shape)
    sight = finite_array("sight", sight, shape=(phi.size, 3))
    az, el, _ = spherical(sight).T
    return np.column_stack([psi, wrap_angle(phi - az), psi - el])


def los_errors(drives, window: float = LOS_WINDOW_M) -> np.ndarray:
    """The path taken for the line of sight against the true one on ``drives`` (a sequence of
    :class:`~tunnelkit.simulation.DriveData` of every path, ``"ml-all"``): one row per epoch with
    a measurement, ``(measured elevation, azimuth error, elevation error)`` [rad], the true line
    of sight from the drive's ``base_station`` to its ``truth``."""
    if not isinstance(drives, list | tuple) or not drives:
        raise ValueError("drives: expected a non-empty list of DriveData")
    window = nonnegative("window", window)
    rows = []
    for i, drive in enumerate(drives):
        instance(f"drives[{i}]", drive, DriveData)
        los = los_only(drive, window)
        k = [k for k, ep in enumerate(los.epochs) if ep is not None]
        if k:
            sight = los.truth[k] - np.asarray(los.base_station, float)
            phi, psi = np.array([(los.epochs[j].phi[0], los.epochs[j].psi[0]) for j in k]).T
            rows.append(los_error_rows(phi, psi, sight))
    if not rows:
        raise ValueError("drives: no epoch with a measurement")
    return np.concatenate(rows)


def elevation_sigmas(errors, bins: int = 8) -> ElevationSigmas:
    """The table of ``errors`` (N, 3) of :func:`los_errors`: ``bins`` bins of the measured
    elevation with nearly equal counts (cut at its quantiles), in each the RMS of the azimuth's
    and the elevation's errors (gross errors included: the tracker meets them too), at the
    mid-point of the bin's edges (the end bins' outer edges are the extreme measurements, so an
    outlying elevation moves their centres)."""
    errors = finite_array("errors", errors, shape=(None, 3))
    bins = integer("bins", bins, minimum=1)
    if errors.shape[0] < 2 * bins:
        raise ValueError(f"errors: at least two rows per bin ({2 * bins}), got {errors.shape[0]}")
    psi = errors[:, 0]
    edges = np.quantile(psi, np.linspace(0.0, 1.0, bins + 1))
    which = np.clip(np.searchsorted(edges, psi, side="right") - 1, 0, bins - 1)
    counts = np.bincount(which, minlength=bins)
    if counts.min() < 2:
        b = int(np.argmin(counts))
        raise ValueError(
            f"errors: tied measured elevations leave bin {b} with {counts[b]} rows (at least 2 "
            "per bin); use fewer bins"
        )
    rms = np.array([np.sqrt(np.mean(errors[which == b, 1:] ** 2, axis=0)) for b in range(bins)])
    if np.any(rms <= 0):
        raise ValueError("errors: a bin without any error (all zero): not a measured record")
    return ElevationSigmas(0.5 * (edges[:-1] + edges[1:]), rms[:, 0], rms[:, 1])


def told_by_elevation(drive, table: ElevationSigmas, sigma_kappa: float, sigma_d: float):
    """``drive`` (a :class:`~tunnelkit.simulation.DriveData`) with every measured path's
    covariance reported from ``table`` at its measured elevation: ``diag(sigma_azimuth^2,
    sigma_elevation^2, sigma_kappa^2)`` [rad^2, rad^2, m^2] and ``sigma_d`` [m] for its delay
    distance (a design told it reads them with :class:`~tunnelkit.tracking.javelin.ReportedNoise`).
    Draws nothing, uses no truth."""
    drive = instance("drive", drive, DriveData)
    table = instance("table", table, ElevationSigmas)
    sigma_kappa, sigma_d = positive("sigma_kappa", sigma_kappa), positive("sigma_d", sigma_d)
    epochs = [ep if ep is None or len(ep) == 0 else told_epoch(ep, table, sigma_kappa, sigma_d)
              for ep in drive.epochs]  # fmt: skip
    return replace(drive, epochs=epochs, reports_covariance=True)


def told_epoch(ep, table: ElevationSigmas, sigma_kappa: float, sigma_d: float):
    """:func:`told_by_elevation` of one epoch's measured paths ``ep`` (not empty), checked."""
    saz, sel = table.at(ep.psi)
    cov = np.zeros((len(ep), 3, 3))
    cov[:, 0, 0], cov[:, 1, 1], cov[:, 2, 2] = saz**2, sel**2, sigma_kappa**2
    return replace(ep, cov=cov, sigma_d=np.full(len(ep), sigma_d))


def angle_sigma(name: str, value: float) -> float:
    """``value`` checked as an angle's standard deviation [rad]: > 0 and at most pi (half a
    turn; an error naming ``name``, a parameter's name, otherwise)."""
    if not isinstance(name, str) or not name:
        raise TypeError(f"name: expected the parameter's name, got {name!r}")
    value = positive(name, value)
    if value > np.pi:
        raise ValueError(f"{name}: at most pi rad (half a turn), got {value:g}")
    return value


def los_angle_information(ue, station, sigma_angle, sigma_elevation=None) -> np.ndarray:
    """Position information (T, 2, 2) [1/m^2] of the line of sight's azimuth and elevation seen
    from ``station`` (3,), for the UE at ``ue`` (T, 3), the angles with independent Gaussian
    errors of ``sigma_angle`` (azimuth) and ``sigma_elevation`` (default ``sigma_angle``) [rad],
    each a number or one per epoch (T,) (a table's, :meth:`ElevationSigmas.at`): ``J^T R^-1 J``
    with ``J`` the angles' Jacobian in the road plane (the height known;
    :func:`tunnelkit.geometry.spherical_jacobian`). The told model's information, for a drive's
    posterior CRLB beside a tracker told those sigmas (a reference of that model, not a bound on
    the ray-traced channel, whose errors are neither Gaussian nor independent)."""
    ue = finite_array("ue", ue, shape=(None, 3))
    station = finite_array("station", station, shape=(3,))
    T = ue.shape[0]

    def sigmas(name, value):
        if np.ndim(value) == 0:
            return np.full(T, angle_sigma(name, value))
        value = positive_array(name, value, shape=(T,))
        if np.any(value > np.pi):
            raise ValueError(f"{name}: at most pi rad (half a turn), got {value.max():g}")
        return value

    az = sigmas("sigma_angle", sigma_angle)
    el = az if sigma_elevation is None else sigmas("sigma_elevation", sigma_elevation)
    try:
        jac = spherical_jacobian(ue - station)[:, :2, :2]  # (azimuth, elevation) by (x, y)
    except ValueError:
        raise ValueError(
            "ue: a position straight below or above the station has no azimuth"
        ) from None
    jac = jac / np.stack([az, el], axis=1)[:, :, None]  # whitened rows
    return np.swapaxes(jac, 1, 2) @ jac
