"""The uncertainty an extraction reports with its paths, checked for
:class:`~tunnelkit.tracking.measurements.PathMeasurements`: the covariance ``cov`` of each path's
``(phi, psi, kappa)`` with its delay sigma ``sigma_d`` (:func:`checked_reported`), and the share
``bias_cov`` of it that repeats from epoch to epoch (:func:`checked_bias`). Loaded when a route
reports them (``RouteOptions(report_covariance=True)``).
"""

from __future__ import annotations

import numpy as np

__all__: list[str] = []


def checked_reported(cov, sigma_d, n: int):
    """Checked ``cov`` (n, 3, 3) and ``sigma_d`` (n,), one of them given: both must be."""
    if cov is None or sigma_d is None:
        raise ValueError("cov, sigma_d: give both (the reported uncertainty) or neither")
    cov = np.array(cov, dtype=float)
    if cov.shape != (n, 3, 3):
        raise ValueError(f"cov: expected shape ({n}, 3, 3), got {cov.shape}")
    sd = np.array(sigma_d, dtype=float).reshape(-1)
    if sd.size != n:
        raise ValueError(f"sigma_d: expected {n} values (one per path), got {sd.size}")
    if not (np.all(np.isfinite(sd)) and np.all(sd > 0)):
        raise ValueError("sigma_d: every value must be finite and > 0")
    if not np.all(np.isfinite(cov)):
        raise ValueError("cov: every entry must be finite")
    cov = 0.5 * (cov + np.swapaxes(cov, 1, 2))
    # the curvature block may be absent (far field): only the angular block must be positive
    if n and not np.all(np.linalg.eigvalsh(cov[:, :2, :2]) > 0):
        raise ValueError("cov: the (phi, psi) block of every path must be positive definite")
    return cov, sd


def checked_bias(bias_cov, cov, sigma_d, n: int):
    """Checked ``bias_cov`` (n, 4, 4) given: symmetric, positive semi-definite, and no larger than
    the reported covariance it is a share of (``cov`` / ``sigma_d``) in any direction."""
    if cov is None:
        raise ValueError("bias_cov: needs the reported covariance (cov, sigma_d) it is a share of")
    b = np.array(bias_cov, dtype=float)
    if b.shape != (n, 4, 4):
        raise ValueError(f"bias_cov: expected shape ({n}, 4, 4), got {b.shape}")
    if not np.all(np.isfinite(b)):
        raise ValueError("bias_cov: every entry must be finite")
    b = 0.5 * (b + np.swapaxes(b, 1, 2))
    total = np.zeros((n, 4, 4))
    total[:, :3, :3] = cov
    total[:, 3, 3] = sigma_d**2
    total[:, :3, 3] = total[:, 3, :3] = b[:, :3, 3]  # the d cross terms are not reported
    scale = np.sqrt(np.clip(np.diagonal(total, axis1=1, axis2=2), 1e-300, None))
    tol = 1e-9
    for name, m in (("bias_cov", b), ("cov - bias_cov", total - b)):
        if n and np.min(np.linalg.eigvalsh(m / scale[:, :, None] / scale[:, None, :])) < -tol:
            raise ValueError(f"bias_cov: {name} must be positive semi-definite for every path")
    return b
