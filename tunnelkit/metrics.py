"""Error metrics used across the notebooks and the ``reproduce`` command; the settled epochs they
are taken over are :mod:`tunnelkit.settling`'s (re-exported here)."""

from __future__ import annotations

import numpy as np
from numpy.lib.array_utils import normalize_axis_tuple

from ._validate import finite_array
from .settling import SETTLE_S, settled

__all__ = ["SETTLE_S", "ecdf", "error_stats", "position_errors", "rmse", "settled"]


def position_errors(estimate, truth) -> np.ndarray:
    """Euclidean error per sample, shape (...,), from positions of shape (..., dim)."""
    est = finite_array("estimate", estimate)
    tru = finite_array("truth", truth)
    for name, a in (("estimate", est), ("truth", tru)):
        if a.ndim == 0 or a.shape[-1] == 0:
            raise ValueError(f"{name}: expected positions (..., dim), got shape {a.shape}")
    try:
        diff = est - tru
    except ValueError as exc:
        raise ValueError(
            f"estimate, truth: shapes {est.shape} and {tru.shape} do not broadcast"
        ) from exc
    return np.linalg.norm(diff, axis=-1)


def rmse(estimate, truth, axis=None) -> np.ndarray:
    """Root mean squared Euclidean error (Jiang eq. 64)."""
    e = position_errors(estimate, truth)
    if e.size == 0:
        raise ValueError("estimate, truth: no positions, the RMSE of an empty sample is undefined")
    if axis is not None:
        try:
            axes = normalize_axis_tuple(axis, e.ndim)
        except (TypeError, ValueError, np.exceptions.AxisError):
            raise ValueError(
                f"axis: {axis!r} is not an axis of errors with shape {e.shape}"
            ) from None
        if any(e.shape[a] == 0 for a in axes):
            raise ValueError("estimate, truth: an empty axis, the RMSE is undefined")
    return np.sqrt(np.mean(e**2, axis=axis))


def error_stats(errors) -> dict[str, float]:
    """min / max / mean / std / variance / RMSE / median / 90th percentile of an error sample."""
    e = finite_array("errors", errors).ravel()
    if e.size == 0:
        raise ValueError("errors: empty sample")
    return {
        "min": float(e.min()),
        "max": float(e.max()),
        "mean": float(e.mean()),
        "std": float(e.std()),
        "variance": float(e.var()),
        "rmse": float(np.sqrt(np.mean(e**2))),
        "median": float(np.median(e)),
        "p90": float(np.percentile(e, 90)),
    }


def ecdf(errors) -> tuple[np.ndarray, np.ndarray]:
    """Empirical CDF: sorted values and their cumulative probabilities."""
    e = np.sort(finite_array("errors", errors).ravel())
    if e.size == 0:
        raise ValueError("errors: empty sample")
    return e, np.arange(1, e.size + 1) / e.size
