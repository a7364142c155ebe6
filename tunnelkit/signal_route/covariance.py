"""The covariance the extraction reports for the paths Algorithm 1 keeps
(:func:`reported_covariance`): the CRLB at the estimate, in the world frame's ``(phi, psi,
kappa)`` and ``d``, what a route with ``report_covariance`` hands the tracker."""

from __future__ import annotations

import numpy as np

from .._domains import indices
from .._validate import boolean, instance
from ..arrays import ArrayGeometry
from ..channel import SRSConfig

__all__ = ["reported_covariance"]


def reported_covariance(est, keep, array: ArrayGeometry, config: SRSConfig, judged=True):
    """The CRLB at the estimate (:func:`tunnelkit.extraction.estimate_crlb`) of the kept paths
    ``keep`` (their Fisher information jointly) as the covariance of the world-frame ``(phi,
    psi, kappa)`` (K, 3, 3) and the standard deviation of ``d`` (K,): the wave origin's
    covariance rotated to the world frame, mapped through d(phi, psi, r)/dq (``spherical_jacobian``).
    Returns ``(None, None)`` when the Fisher information is singular at the estimate or, if
    ``judged``, the fit failed its own residual test (``fit.rho > fit.rho_max``: a wrong basin)."""
    from ..extraction import estimate_crlb
    from ..extraction.estimates import PathEstimates
    from ..geometry import spherical_jacobian

    instance("est", est, PathEstimates)
    instance("array", array, ArrayGeometry)
    instance("config", config, SRSConfig)
    keep = indices("keep", keep, len(est.d))
    fit = getattr(est, "fit", None)
    if boolean("judged", judged) and fit is not None and not fit.rho <= fit.rho_max:
        return None, None
    try:
        b = estimate_crlb(est, array, config, paths=keep)
    except np.linalg.LinAlgError:
        return None, None
    rot = array.R  # local -> world: u_world = R u_local
    cov_w = rot @ b["source_cov"] @ rot.T
    G = spherical_jacobian(array.dir_to_world(b["source"]))
    return G @ cov_w @ np.swapaxes(G, 1, 2), b["d"]
