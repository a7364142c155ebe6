"""Estimates matched to the true paths: the Hungarian assignment on range and direction.

:func:`match_paths` assigns extracted paths to traced ones (a signal route's epoch, the notebooks'
tables, the benchmarks); :func:`match_points` does the same on plain arrays.
"""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, positive, real
from ..constants import C

__all__ = ["match_paths", "match_points"]


def _ranges_directions(d_name: str, d, u_name: str, u) -> tuple[np.ndarray, np.ndarray]:
    """Distances (N,) and unit directions (N, 3), checked and named."""
    d = np.atleast_1d(finite_array(d_name, d))
    if d.ndim != 1:
        raise ValueError(f"{d_name}: expected 1-D distances, got shape {d.shape}")
    u = finite_array(u_name, u)
    if not (u.size == 0 and d.size == 0) and u.shape != (d.shape[0], 3):
        raise ValueError(f"{u_name}: expected shape ({d.shape[0]}, 3), got {u.shape}")
    return d, u.reshape(d.shape[0], 3)


def match_paths(
    d_est,
    dir_est,
    paths,
    *,
    clock_bias: float = 0.0,
    direction_scale: float = 0.1,
    range_scale: float = 1.0,
) -> np.ndarray:
    """Assign estimates to true paths (Hungarian on range and direction); -1 where unmatched.

    Cost: ``|d_est - (length + c b)| / range_scale + ||u_est - u_true|| / direction_scale``;
    assignments costing more than 10 are refused.
    """
    d_est, dir_est = _ranges_directions("d_est", d_est, "dir_est", dir_est)
    if isinstance(paths, str | bytes) or not hasattr(paths, "__len__"):
        raise TypeError(f"paths: expected a list of traced paths, got {type(paths).__name__}")
    if any(not hasattr(p, "length") or not hasattr(p, "direction") for p in paths):
        raise TypeError("paths: expected traced paths (with .length and .direction)")
    clock_bias = real("clock_bias", clock_bias)
    direction_scale = positive("direction_scale", direction_scale)
    range_scale = positive("range_scale", range_scale)
    if not len(paths) or not d_est.size:
        return -np.ones(d_est.shape[0], dtype=int)
    d_true = np.array([p.length for p in paths]) + C * clock_bias
    u_true = np.stack([p.direction for p in paths])
    return match_points(
        d_est,
        dir_est,
        d_true,
        u_true,
        direction_scale=direction_scale,
        range_scale=range_scale,
    )


def match_points(
    d_est, dir_est, d_true, dir_true, *, direction_scale: float = 0.1, range_scale: float = 1.0
) -> np.ndarray:
    """:func:`match_paths` on plain arrays (distances and unit directions in one frame)."""
    from scipy.optimize import linear_sum_assignment

    d_est, dir_est = _ranges_directions("d_est", d_est, "dir_est", dir_est)
    d_true, dir_true = _ranges_directions("d_true", d_true, "dir_true", dir_true)
    direction_scale = positive("direction_scale", direction_scale)
    range_scale = positive("range_scale", range_scale)
    out = -np.ones(d_est.shape[0], dtype=int)
    if not d_true.size or not d_est.size:
        return out
    cost = (
        np.abs(d_est[:, None] - d_true[None, :]) / range_scale
        + np.linalg.norm(dir_est[:, None, :] - dir_true[None], axis=-1) / direction_scale
    )
    r, c = linear_sum_assignment(cost)
    ok = cost[r, c] < 10.0
    out[r[ok]] = c[ok]
    return out
