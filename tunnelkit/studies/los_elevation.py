"""The line of sight's angle errors by its elevation: a table from traced drives, and a drive told it.

On the ray-traced channel the path taken for the line of sight (:func:`~.los_only.los_path`) is
accurate where it arrives steeply and off by degrees where it arrives at a shallow angle: near the
site the line of sight and the ceiling's reflection are apart by more than the array resolves, far
from it they merge and the fit's one atom lies between them (straight drive, 10 x 10, seed 0: RMS
0.2 deg below 15 m, 2-3 deg beyond 25 m; ``docs/results/traced-robust.md``). One told sigma for
every epoch under-trusts the near epochs and over-trusts the far ones.

:func:`los_errors` measures the picked path's azimuth and elevation errors against the true line of
sight on traced drives (a record, with their truth); :func:`elevation_sigmas` summarises them as an
:class:`ElevationSigmas` table, the RMS of each error in bins of the *measured* elevation (equal
counts), so that the tracker can read its sigma from what it measures (the range is not known to
it; the elevation is, and under a site above the road it falls monotonically with the range);
:func:`told_by_elevation` gives each epoch of a line-of-sight drive its covariance from the table,
for a design with :class:`~tunnelkit.tracking.javelin.ReportedNoise`. ``benchmarks/bench_rt_los.py
--by-elevation`` builds the table on seed 0 and reports it on the held-out seed and other scenes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._domains import positive_array
from .._validate import finite_array, instance, integer, nonnegative, positive
from ..angles import wrap_angle
from ..geometry import spherical
from ..simulation import DriveData
from .los_only import LOS_WINDOW_M, los_only

__all__ = ["ElevationSigmas", "elevation_sigmas", "los_errors", "told_by_elevation"]


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

    def as_dict(self) -> dict:
        """The table in degrees, for JSON."""
        return {k: np.degrees(getattr(self, k)).round(6).tolist() for k in _FIELDS}

    @classmethod
    def from_dict(cls, table: dict) -> ElevationSigmas:
        """The table of :meth:`as_dict`."""
        instance("table", table, dict)
        missing = [k for k in _FIELDS if k not in table]
        if missing:
            raise ValueError(f"table: missing {missing} (expected the keys {list(_FIELDS)})")
        return cls(*(np.radians(np.asarray(table[k], float)) for k in _FIELDS))


_FIELDS = ("elevation", "sigma_azimuth", "sigma_elevation")


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
        az, el, _ = spherical(los.truth - np.asarray(los.base_station, float)).T
        for k, ep in enumerate(los.epochs):
            if ep is not None:
                rows.append((ep.psi[0], wrap_angle(ep.phi[0] - az[k]), ep.psi[0] - el[k]))
    if not rows:
        raise ValueError("drives: no epoch with a measurement")
    return np.array(rows, float)


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
    epochs = []
    for ep in drive.epochs:
        if ep is None or len(ep) == 0:
            epochs.append(ep)
            continue
        saz, sel = table.at(ep.psi)
        cov = np.zeros((len(ep), 3, 3))
        cov[:, 0, 0], cov[:, 1, 1], cov[:, 2, 2] = saz**2, sel**2, sigma_kappa**2
        epochs.append(replace(ep, cov=cov, sigma_d=np.full(len(ep), sigma_d)))
    return replace(drive, epochs=epochs, reports_covariance=True)
