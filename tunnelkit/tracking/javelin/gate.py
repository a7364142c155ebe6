"""The validation gate of eq. 56-59: squared Mahalanobis distance against a chi-square quantile."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.stats import chi2

from ..._validate import finite_array, integer, probability

__all__ = ["ChiSquareGate", "mahalanobis2"]


def mahalanobis2(y, S) -> np.ndarray:
    """``eta^2 = y^T S^-1 y`` (eq. 58), vectorised over leading axes of ``y`` (..., n), ``S`` (..., n, n)."""
    y = finite_array("y", y)
    if y.ndim == 0:
        raise ValueError("y: expected residual vector(s) (..., n), got a scalar")
    S = finite_array("S", S)
    if S.shape[-2:] != (y.shape[-1], y.shape[-1]):
        raise ValueError(f"S: expected (..., {y.shape[-1]}, {y.shape[-1]}), got {S.shape}")
    # S is an innovation covariance: symmetric and positive definite (its Cholesky factor exists)
    if abs(S - np.swapaxes(S, -1, -2)).max() > 1e-9 * abs(S).max():
        raise ValueError("S: must be symmetric positive definite (it is not symmetric)")
    try:
        np.linalg.cholesky(S)
    except np.linalg.LinAlgError:
        raise ValueError(
            "S: must be symmetric positive definite (an innovation covariance)"
        ) from None
    sol = np.linalg.solve(S, y[..., None])[..., 0]
    return np.sum(y * sol, axis=-1)


@lru_cache(maxsize=64)
def _threshold(p: float, dof: int) -> float:
    return float(chi2.ppf(p, dof))


@dataclass(frozen=True)
class ChiSquareGate:
    """Accept a pair when ``eta^2 < chi2_dof(p)`` (eq. 59); the paper uses 3 dof and p = 0.99.

    ``dof`` follows the components a measurement carries: 3 for ``(phi, psi, kappa)``, 2 for a
    far-field path without curvature (ours; the paper always has 3).
    """

    probability: float = 0.99

    def __post_init__(self) -> None:
        probability("probability", self.probability)

    def threshold(self, dof: int = 3) -> float:
        """The chi-square quantile ``chi2_dof(p)`` (11.34 for 3 dof, p = 0.99)."""
        return _threshold(float(self.probability), integer("dof", int(dof), minimum=1))

    def accepts(self, eta2, dof) -> np.ndarray:
        """Elementwise ``eta2 < chi2_dof(p)``; ``dof`` broadcasts against ``eta2``."""
        eta2 = np.asarray(eta2, dtype=float)
        dof = np.broadcast_to(np.asarray(dof, dtype=int), eta2.shape)
        thr = np.vectorize(self.threshold, otypes=[float])(dof) if dof.size else np.zeros(dof.shape)
        return np.isfinite(eta2) & (eta2 < thr)
