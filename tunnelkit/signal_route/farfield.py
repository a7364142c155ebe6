"""Curvatures the extraction leaves unresolved, reported as far-field paths seen from the array's
centroid (``RouteOptions(centroid_unresolved=True)``, :meth:`SignalRoute.epoch
<tunnelkit.signal_route.SignalRoute.epoch>`): :func:`centroid_far_field`."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .._domains import indices
from .._validate import instance, positive
from ..arrays import ArrayGeometry
from ..extraction.estimates import PathEstimates
from ..tracking.measurements import PathMeasurements

#: nothing exported: the route's own step, on the measurements its epoch made
__all__: list[str] = []

#: a near-field path whose curvature estimate is below ``UNRESOLVED_Z`` reported standard
#: deviations (``kappa < z sigma_kappa``) has an unresolved curvature (:func:`centroid_far_field`)
UNRESOLVED_Z = 3.0


def centroid_far_field(meas: PathMeasurements, est, array: ArrayGeometry, z: float = UNRESOLVED_Z):
    """``meas`` with every near-field path whose curvature its reported covariance leaves
    unresolved (``kappa < z sigma_kappa``) reported as a far-field path seen from the array's
    centroid; ``est`` the estimates ``meas`` came from (rows ``meas.source``), ``array`` its
    array. Without a reported covariance ``meas`` is returned as it is.

    The extraction's model places each path's wave origin ``q`` at ``kappa`` along the direction
    seen from the reference antenna (element 0, a corner of a URA). The data fix the
    wavefront's slope at the aperture's centre ``c``; the direction seen from the reference is
    that slope plus ``c_perp w`` (``w = 1 / kappa``, ``c_perp`` the part of ``c`` across the
    ray), so an error of ``w`` moves it by ``|c_perp| dw``. Far beyond the aperture's near field
    ``w`` is not resolved, and a calibration error's quadratic phase across the aperture drives
    it to a few 1/m, the same every epoch: 28 GHz example, 8 x 8, 2 deg, one drive (seed 0, run
    0): ``kappa`` 3-7 m for sources 45-100 m away, every path's direction 5-8 mrad off seen from
    the reference (``|c_perp|`` 2.6 cm), 1-2 mrad from the centroid, and the tracker 0.7 m off
    over most of the drive. The test takes ``sigma_kappa`` from the reported covariance, the
    impairment budget included (:func:`~tunnelkit.signal_route.judging.apply_budget`): the CRLB
    at a biased estimate alone calls such a curvature resolved. An unresolved path is reported
    with the direction ``(q - c) / |q - c|`` and no curvature (``kappa`` NaN, far field); the
    far-field limit's model error, ``|c_perp| / r`` at range ``r``, is within the reported
    direction covariance, which carries the ``w`` coupling ``|c_perp| sigma_w``. Resolved paths
    keep the reference's direction and curvature."""
    instance("meas", meas, PathMeasurements)
    instance("est", est, PathEstimates)
    instance("array", array, ArrayGeometry)
    z = positive("z", z)
    if meas.cov is None or not len(meas):
        return meas
    rows = indices("meas", meas.source, len(est.d))
    kappa = meas.kappa.copy()
    with np.errstate(invalid="ignore"):
        loose = meas.near_field & np.isfinite(kappa) & ~(kappa >= z * np.sqrt(meas.cov[:, 2, 2]))
    if not loose.any():
        return meas
    c = array.local.mean(axis=0) - array.local[0]
    q = est.kappa[rows[loose], None] * est.direction[rows[loose]] - c
    u = array.dir_to_world(q / np.linalg.norm(q, axis=1, keepdims=True))
    phi, psi = meas.phi.copy(), meas.psi.copy()
    phi[loose] = np.arctan2(u[:, 1], u[:, 0])
    psi[loose] = np.arctan2(u[:, 2], np.hypot(u[:, 0], u[:, 1]))
    kappa[loose] = np.nan
    return replace(meas, phi=phi, psi=psi, kappa=kappa)
