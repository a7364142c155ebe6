"""Input checks of arrays with a structure of their own: signed arrays, particle weights,
symmetric positive definite matrices, distinct points, (low, high) ranges and indices.

Built on :mod:`tunnelkit._validate`; each raises ``ValueError`` or ``TypeError`` whose message
starts with the offending parameter's name.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ._validate import finite_array

__all__ = [
    "distinct_points",
    "indices",
    "interval",
    "nonnegative_array",
    "positive_array",
    "spd_matrix",
    "weights",
]


def positive_array(name: str, value, **kw) -> np.ndarray:
    """A finite real array whose every entry is > 0."""
    arr = finite_array(name, value, **kw)
    if arr.size and arr.min() <= 0:
        raise ValueError(f"{name}: must be > 0 everywhere, got {float(arr.min())}")
    return arr


def nonnegative_array(name: str, value, **kw) -> np.ndarray:
    """A finite real array whose every entry is >= 0."""
    arr = finite_array(name, value, **kw)
    if arr.size and arr.min() < 0:
        raise ValueError(f"{name}: must be >= 0 everywhere, got {float(arr.min())}")
    return arr


def weights(name: str, value) -> np.ndarray:
    """Particle weights (..., N): finite, ``>= 0``, ``N >= 1`` and a positive sum in every row."""
    w = finite_array(name, value)
    if w.ndim == 0 or w.shape[-1] == 0:
        raise ValueError(f"{name}: expected at least one weight in the last axis, got {w.shape}")
    if w.min() < 0:
        raise ValueError(f"{name}: must be >= 0, got {float(w.min())}")
    if np.any(w.sum(axis=-1) <= 0):
        raise ValueError(f"{name}: every row must have a positive sum (all weights are zero)")
    return w


def spd_matrix(name: str, value, *, n: int | None = None, rtol: float = 1e-9) -> np.ndarray:
    """Symmetric positive definite matrix (or stack (..., n, n)) such as a covariance or an
    information matrix: finite, real, square, symmetric to ``rtol`` and Cholesky-factorable."""
    A = finite_array(name, value)
    if A.ndim < 2 or A.shape[-1] != A.shape[-2]:
        raise ValueError(f"{name}: expected square matrices (..., n, n), got shape {A.shape}")
    if n is not None and A.shape[-1] != n:
        raise ValueError(f"{name}: expected {n} x {n} matrices, got shape {A.shape}")
    if A.size == 0:
        raise ValueError(f"{name}: empty matrix")
    At = np.swapaxes(A, -1, -2)
    scale = np.max(np.abs(A))
    if np.max(np.abs(A - At)) > rtol * max(scale, np.finfo(float).tiny):
        raise ValueError(f"{name}: must be symmetric positive definite (it is not symmetric)")
    try:
        np.linalg.cholesky(0.5 * (A + At))
    except np.linalg.LinAlgError:
        raise ValueError(
            f"{name}: must be symmetric positive definite (it is not positive definite)"
        ) from None
    return A


def distinct_points(name: str, value, *, dim: int, minimum: int = 2, atol: float = 0.0):
    """Points (N, dim) with at least ``minimum`` distinct rows (e.g. stations for positioning)."""
    P = finite_array(name, value, ndim=2)
    if P.shape[1] != dim:
        raise ValueError(f"{name}: expected shape (N, {dim}), got {P.shape}")
    if P.shape[0] < minimum:
        raise ValueError(f"{name}: need at least {minimum} stations, got {P.shape[0]}")
    if minimum > 1:
        scale = max(float(np.max(np.abs(P))), 1.0)
        key = np.round(P / (max(atol, 1e-12) * scale))
        if np.unique(key, axis=0).shape[0] < minimum:
            raise ValueError(
                f"{name}: need at least {minimum} distinct stations, the {P.shape[0]} given coincide"
            )
    return P


def interval(name: str, value, *, lower: float | None = None) -> tuple[float, float]:
    """A range ``(lo, hi)`` of two finite reals with ``lo <= hi`` (and ``lo >= lower`` when
    given), e.g. the bounds a uniform draw takes: NaN, a reversed or a wrong-length range named."""
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise TypeError(f"{name}: expected a (low, high) pair, got {type(value).__name__}")
    pair = finite_array(name, value)
    if pair.shape != (2,):
        raise ValueError(f"{name}: expected a (low, high) pair, got shape {pair.shape}")
    lo, hi = float(pair[0]), float(pair[1])
    if lo > hi:
        raise ValueError(f"{name}: low {lo:g} is above high {hi:g}")
    if lower is not None and lo < lower:
        raise ValueError(f"{name}: must be >= {lower:g}, got low {lo:g}")
    return lo, hi


def indices(name: str, value, n: int) -> np.ndarray:
    """A 1-D list or array of integer indices into ``n`` items, each in ``[0, n)``."""
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise TypeError(f"{name}: expected a list of indices, got {type(value).__name__}")
    arr = np.asarray(value)
    if arr.size == 0:
        return np.zeros(0, int)
    if arr.dtype.kind not in "iu":
        raise TypeError(f"{name}: expected integer indices, got dtype {arr.dtype}")
    if arr.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D list of indices, got shape {arr.shape}")
    if arr.min() < 0 or arr.max() >= n:
        raise ValueError(f"{name}: expected indices in [0, {n - 1}], got {arr.tolist()}")
    return arr.astype(int, copy=False)
