"""The line of sight alone on the ray-traced channel: JAVELIN fed each epoch's earliest arrival.

On the traced channel the reflections' estimates are biased by degrees per kind of path and the bias
repeats from epoch to epoch, while the line of sight's angles are nearly unbiased (median -0.15 /
0.10 deg azimuth / elevation, robust sigma 1.0 / 1.8 deg; ``docs/results/traced-robust.md``). This
study keeps, of every epoch's ML measurements (``"ml-all"`` of
:func:`tunnelkit.studies.traced.simulate_traced`), one path taken for the line of sight and tells
JAVELIN an angle sigma for it (one for both angles, or the azimuth's and the elevation's):
:func:`los_only`, :func:`los_design`. The line of sight arrives first, but under a ceiling-mounted
site the ceiling's reflection follows within centimetres and the delay errors swap them (the
earliest arrival is the true line of sight in 62-64 % of the epochs); the ceiling's image lies above
the array, so of the arrivals within ``window`` of the earliest the lowest in elevation is taken
(87-89 %, window 0.3 m chosen on seed 0 among 0.3 / 0.6 / 1.0 m). No truth is used to pick it.
:func:`los_angle_information` is the position information the line of sight's two angles would carry
as independent Gaussian errors of that sigma, for the drive's posterior CRLB beside the tracker (a
reference figure of the told model, not a bound on the traced channel, whose errors are neither).
``benchmarks/bench_rt_los.py`` runs it beside the traced design and dead reckoning.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .._validate import finite_array, instance, nonnegative, positive
from ..geometry import spherical_jacobian
from ..simulation import DriveData
from ..simulation.prefilter import traced_measurements
from ..tracking.javelin import JavelinDesign
from .traced import traced_design

__all__ = [
    "LOS_WINDOW_M",
    "flagged_los",
    "los_angle_information",
    "los_design",
    "los_only",
    "los_path",
]


#: the arrivals within this delay distance of the earliest are candidates for the LoS [m]
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


def _angle_sigma(name: str, value: float) -> float:
    value = positive(name, value)
    if value > np.pi:
        raise ValueError(f"{name}: at most pi rad (half a turn), got {value:g}")
    return value


def flagged_los(ep, route, window: float = LOS_WINDOW_M):
    """A drive adapter (:func:`tunnelkit.simulation.simulate_routes`, ``adapters=``): of the
    epoch's ML measurements (every row, as ``"ml-all"``), the path :func:`los_path` takes for the
    line of sight, kept only where the fit does not flag it: ``(None, reason)`` when the fit put
    that path in its threshold region (``PathEstimates.below_threshold``: its SNR below the
    threshold of the method of interval errors, or unresolved from another path, where its
    errors leave the bound). Uses the fit's own verdict, no truth."""

    window = nonnegative("window", window)
    pm, _ = traced_measurements(ep, route, prefilter=False)  # checks ep and route
    if len(pm) == 0:
        return None, "no path"
    m = ep.measurements
    j = los_path(pm.d, pm.psi, window)
    flags = ep.estimates.below_threshold
    if flags is not None and bool(flags[m.source[pm.source[j]]]):
        return None, "the path taken for the line of sight is in the fit's threshold region"
    return pm.subset(np.array([j])), None


def los_design(sigma_angle: float, base=None, sigma_elevation: float | None = None):
    """``base`` (default the traced design, :func:`tunnelkit.studies.traced.traced_design`) told
    ``sigma_angle`` [rad] for the azimuth of the path it is fed and ``sigma_elevation`` [rad]
    (default ``sigma_angle``) for its elevation (the other sigmas unchanged)."""

    sigma_angle = _angle_sigma("sigma_angle", sigma_angle)
    el = (
        sigma_angle if sigma_elevation is None else _angle_sigma("sigma_elevation", sigma_elevation)
    )

    base = traced_design() if base is None else instance("base", base, JavelinDesign)
    return base.with_(sigma_phi=sigma_angle, sigma_psi=el)


def los_angle_information(
    ue, station, sigma_angle: float, sigma_elevation: float | None = None
) -> np.ndarray:
    """Position information (T, 2, 2) [1/m^2] of the line of sight's azimuth and elevation seen
    from ``station`` (3,), for the UE at ``ue`` (T, 3), the angles with independent Gaussian
    errors of ``sigma_angle`` (azimuth) and ``sigma_elevation`` (default ``sigma_angle``) [rad]:
    ``J^T R^-1 J`` with ``J`` the angles' Jacobian in the road plane (the height known;
    :func:`tunnelkit.geometry.spherical_jacobian`)."""
    ue = finite_array("ue", ue, shape=(None, 3))
    station = finite_array("station", station, shape=(3,))
    sigma_angle = _angle_sigma("sigma_angle", sigma_angle)
    el = (
        sigma_angle if sigma_elevation is None else _angle_sigma("sigma_elevation", sigma_elevation)
    )
    try:
        jac = spherical_jacobian(ue - station)[:, :2, :2]  # (azimuth, elevation) by (x, y)
    except ValueError:
        raise ValueError(
            "ue: a position straight below or above the station has no azimuth"
        ) from None
    jac = jac / np.array([sigma_angle, el])[None, :, None]  # whitened rows
    return np.swapaxes(jac, 1, 2) @ jac
