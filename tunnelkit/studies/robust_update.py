"""Heavy-tailed measurement noise in JAVELIN's update: a Huber M-estimate of the state.

On the ray-traced channel a path's angle errors are a Gaussian core with gross errors beside it
(``docs/results/traced-robust.md``). The paper's update (eq. 64-68) trusts every row it keeps as
Gaussian with the told sigma; its gates drop only what lies beyond the gate. :class:`HuberUpdater`
is the updater role (:class:`tunnelkit.tracking.javelin.JosephUpdater`'s protocol) that keeps the
prior Gaussian and gives the measurement rows Huber's loss (after Karlgaard and Schaub's robust
Kalman filter, which also robustifies the prior; linearised at the prediction): the correction
``dx`` minimises ``dx^T P^-1 dx / 2 + sum_i rho_k(e_i)``, ``e = R^-1/2 (y - H dx)`` the whitened
posterior residuals (the symmetric square root, so that the result does not depend on the order
of the rows), ``rho_k`` quadratic within ``k`` and linear beyond. Iteratively reweighted least
squares solves it (:func:`huber_weights`): the Kalman update with ``R_w = R^1/2 W^-1 R^1/2``,
``W = diag(min(1, k / |e_i|))``. With uncorrelated rows, a row within ``k`` sigmas of the
corrected state keeps its sigma; a gross error moves the state by a bounded amount (``P k /
sigma`` for one scalar row) instead of in proportion to its size. ``k = 1.345`` is the classic
choice (95 % of the Gaussian's efficiency). Not used with a consider (bias-aware) noise role.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, replace

import numpy as np

from .._validate import finite_array, instance, positive
from ..tracking.javelin import JosephUpdater
from ..tracking.javelin.update import StackedMeasurement, joseph_update, state_arguments

__all__ = ["HUBER_K", "HuberUpdater", "huber_weights"]

#: the Huber threshold of 95 % efficiency under Gaussian errors [standard deviations]
HUBER_K = 1.345
_MAX_PASSES = 1000
_TOL = 1e-10


def _root(R: np.ndarray) -> np.ndarray:
    """The symmetric square root of the covariance ``R``; refuses one not positive definite."""
    lam, V = np.linalg.eigh(0.5 * (R + R.T))
    if lam.min() <= 0:
        raise ValueError("R: expected a positive definite covariance")
    return (V * np.sqrt(lam)) @ V.T


def _weights(y, H, P, root, k) -> np.ndarray:
    """:func:`huber_weights` on checked arguments, ``root`` = ``R^1/2``."""
    w = np.ones(y.size)
    for _ in range(_MAX_PASSES):
        S = H @ P @ H.T + (root / w) @ root  # H P H^T + R^1/2 W^-1 R^1/2
        dx = P @ H.T @ np.linalg.solve(S, y)
        e = np.linalg.solve(root, y - H @ dx)  # whitened residuals at the corrected state
        new = np.minimum(1.0, k / np.maximum(np.abs(e), np.finfo(float).tiny))
        if np.max(np.abs(new - w)) <= _TOL:
            return new
        w = new
    raise RuntimeError("huber_weights: the reweighting did not converge in 1,000 passes")


def huber_weights(y, H, P, R, k: float = HUBER_K) -> np.ndarray:
    """The weights (K,) of the Huber M-estimate of a linear update: innovation ``y`` (K,),
    measurement matrix ``H`` (K, D), prior covariance ``P`` (D, D), told noise ``R`` (K, K) and
    threshold ``k`` [sigmas]. Iteratively reweighted least squares on the whitened rows (the
    module's docstring) until no weight moves by more than 1e-10; raises ``RuntimeError`` if that
    takes more than 1,000 passes. Every weight is 1 where every whitened residual lies within
    ``k``: the Kalman update itself."""
    y = finite_array("y", y, ndim=1)
    H = finite_array("H", H, shape=(y.size, None))
    P = finite_array("P", P, shape=(H.shape[1], H.shape[1]))
    R = finite_array("R", R, shape=(y.size, y.size))
    return _weights(y, H, P, _root(R), positive("k", k))


@dataclass(frozen=True)
class HuberUpdater(JosephUpdater):
    """JAVELIN's updater role with Huber-weighted rows (the module's docstring): each row's
    whitened noise scaled by :func:`huber_weights` at threshold ``k`` [standard deviations], then
    the Joseph update (eq. 64-68) with it. ``k = inf`` is the paper's update."""

    k: float = HUBER_K

    def __post_init__(self) -> None:
        k = self.k
        if isinstance(k, bool) or not isinstance(k, numbers.Real) or not float(k) > 0:
            raise ValueError(
                f"k: expected a positive number of standard deviations, got {self.k!r}"
            )

    def update(self, x, P, m: StackedMeasurement, C=None):
        """``(x, P, nis)`` after the Huber-weighted Joseph update; ``nis`` is the innovation's
        under the told ``R`` (so that a gross error shows in it). Refuses a consider
        cross-covariance ``C``."""
        instance("m", m, StackedMeasurement)
        if C is not None or m.B is not None:
            raise ValueError(
                "C: the Huber update has no consider (bias-aware) form; use a noise role "
                "without a repeating share"
            )
        if m.z.size == 0 or not np.isfinite(self.k):
            return joseph_update(x, P, m)
        x, P = state_arguments(x, P, m.H.shape[1])
        y, root = m.residual(), _root(m.R)
        w = _weights(y, m.H, P, root, float(self.k))
        x_new, P_new, _ = joseph_update(x, P, replace(m, R=(root / w) @ root))
        S = m.H @ P @ m.H.T + m.R
        return x_new, P_new, float(y @ np.linalg.solve(0.5 * (S + S.T), y))
