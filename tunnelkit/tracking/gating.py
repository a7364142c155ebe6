"""The chi-square gate every tracker uses: the squared Mahalanobis distance of an innovation
(:func:`mahalanobis2`, Italiano eq. 58) against its chi-square quantile (:class:`ChiSquareGate`,
eq. 59), with the one default probability :data:`DEFAULT_GATE`. The filters' policy around it (a
rejected measurement is a missed epoch, and the gate reopens) is :mod:`tunnelkit.tracking.reopening`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.stats import chi2

from .._validate import finite_array, integer
from .._validate import probability as check_probability

__all__ = [
    "DEFAULT_GATE",
    "ChiSquareGate",
    "mahalanobis2",
    "squared_distances",
]

#: default gate probability of every tracker (chi-square quantile of the innovation)
DEFAULT_GATE = 0.999


@lru_cache(maxsize=64)
def _quantile(p: float, dof: int) -> float:
    return float(chi2.ppf(p, dof))


def squared_distances(d2) -> np.ndarray:
    """Squared Mahalanobis distances: real, ``>= 0`` or NaN/inf (a non-finite one is rejected)."""
    if type(d2) is float or type(d2) is np.float64:  # one filter's distance: the inner loop's case
        if d2 < 0:
            raise ValueError(f"d2: must be >= 0 (a squared distance), got {d2}")
        return np.asarray(d2)
    if isinstance(d2, np.ndarray) and d2.dtype == float:
        arr = d2
    else:
        if isinstance(d2, str | bytes) or np.asarray(d2).dtype.kind not in "iuf":
            raise TypeError(f"d2: expected real numbers, got {type(d2).__name__}")
        arr = np.asarray(d2, dtype=float)
    if np.any(arr < 0):
        raise ValueError(f"d2: must be >= 0 (a squared distance), got {float(np.nanmin(arr))}")
    return arr


def mahalanobis2(y, S) -> np.ndarray:
    """``d2 = y^T S^-1 y`` (Italiano eq. 58), vectorised over leading axes of ``y`` (..., n) and
    ``S`` (..., n, n); ``S`` must be symmetric positive definite (an innovation covariance)."""
    y = finite_array("y", y)
    if y.ndim == 0:
        raise ValueError("y: expected residual vector(s) (..., n), got a scalar")
    S = finite_array("S", S)
    if S.shape[-2:] != (y.shape[-1], y.shape[-1]):
        raise ValueError(f"S: expected (..., {y.shape[-1]}, {y.shape[-1]}), got {S.shape}")
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


@dataclass(frozen=True)
class ChiSquareGate:
    """The chi-square test every tracker uses: accept when ``d2 < chi2_dof(p)``.

    One default, :data:`DEFAULT_GATE` (0.999). JAVELIN's association gate (Italiano eq. 59) is
    this test at the paper's ``p = 0.99`` (``JavelinConfig.gate_probability``), with ``dof`` the
    components a path carries (3 for ``(phi, psi, kappa)``, 2 without curvature).
    :class:`tunnelkit.tracking.reopening.InnovationGate` is the same test with the reopening
    policy of the filters.
    """

    probability: float = DEFAULT_GATE

    def __post_init__(self) -> None:
        check_probability("probability", self.probability)

    def threshold(self, dof: int = 3) -> float:
        """The chi-square quantile ``chi2_dof(p)`` (11.34 for 3 dof at p = 0.99)."""
        return _quantile(float(self.probability), integer("dof", dof, minimum=1))

    def accepts(self, d2, dof) -> np.ndarray:
        """Elementwise ``d2 < chi2_dof(p)``; ``dof`` broadcasts against ``d2``."""
        d2 = squared_distances(d2)
        dof = np.asarray(dof)
        if dof.dtype.kind not in "iu":
            raise TypeError(f"dof: expected integers, got {dof.dtype}")
        dof = np.broadcast_to(dof, d2.shape)
        thr = np.vectorize(self.threshold, otypes=[float])(dof) if dof.size else np.zeros(dof.shape)
        return np.isfinite(d2) & (d2 < thr)
