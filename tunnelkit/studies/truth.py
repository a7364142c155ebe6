"""Paths against their truth, for the studies: the true paths' world angles, delay distance and
curvature radius, the same of estimates in the ML parametrisation, and their differences (used by
:mod:`.attribution` and :mod:`.nuisance`)."""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, instance
from ..arrays import ArrayGeometry
from ..constants import C
from ..extraction.radio import check_srs
from ..propagation import as_path_list

__all__ = ["angles_of_theta", "path_differences", "path_truth", "world_angles"]


def world_angles(u) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth and elevation [rad] of unit vectors ``u`` (L, 3) in the world frame."""
    u = np.atleast_2d(finite_array("u", u))
    if u.shape[1] != 3:
        raise ValueError(f"u: expected shape (L, 3), got {u.shape}")
    return np.arctan2(u[:, 1], u[:, 0]), np.arcsin(np.clip(u[:, 2], -1.0, 1.0))


def _array(arr):
    return instance("arr", arr, ArrayGeometry)


def path_truth(paths, arr) -> dict:
    """World azimuth, elevation [rad], ``d`` [m] and ``kappa`` [m] of the true ``paths`` (traced
    to the :class:`~tunnelkit.arrays.ArrayGeometry` ``arr``)."""
    paths, arr = as_path_list(paths), _array(arr)
    phi, psi = world_angles(np.stack([p.direction for p in paths]))
    kap = np.array([np.linalg.norm(p.source - arr.origin) for p in paths])
    return {"phi": phi, "psi": psi, "d": np.array([p.length for p in paths]), "kappa": kap}


def angles_of_theta(theta, mu_f, arr, srs) -> dict:
    """:func:`path_truth`'s quantities of paths in the ML parametrisation: ``theta`` (L, 3) local
    direction cosines and curvature, ``mu_f`` (L,) the tone phase step, at ``arr`` with the radio
    ``srs`` (:class:`~tunnelkit.channel.SRSConfig`)."""
    theta = finite_array("theta", theta, shape=(None, 3))
    mu_f = finite_array("mu_f", mu_f, shape=(theta.shape[0],))
    arr, srs = _array(arr), check_srs(srs)
    ux, uy = theta[:, 0], theta[:, 1]
    u = np.column_stack([ux, uy, np.sqrt(np.clip(1 - ux**2 - uy**2, 0, 1))])
    phi, psi = world_angles(arr.dir_to_world(u))
    with np.errstate(divide="ignore"):
        kap = np.where(theta[:, 2] > 0, 1.0 / theta[:, 2], np.inf)
    return {"phi": phi, "psi": psi, "d": -C * mu_f / (2 * np.pi * srs.tone_spacing), "kappa": kap}


def _wrap(x):
    return np.angle(np.exp(1j * np.asarray(x)))


def _index(name: str, idx, n: int) -> np.ndarray:
    """``idx`` as a vector of indices into ``n`` items."""
    x = finite_array(name, idx, ndim=1)
    if np.any(x != np.round(x)) or np.any(x < 0) or np.any(x >= n):
        raise ValueError(f"{name}: expected indices 0 to {n - 1}, got {idx!r}")
    return x.astype(int)


def path_differences(est: dict, tru: dict, rows, cols, offset: float = 0.0) -> np.ndarray:
    """(n, 4) errors of estimates ``rows`` against truths ``cols``: azimuth, elevation [deg],
    ``d - offset`` [m], ``kappa`` [m] (inf where the estimate is a far-field wave); ``est`` and
    ``tru`` as :func:`path_truth` returns."""
    for name, x in (("est", est), ("tru", tru)):
        if not isinstance(x, dict) or not {"phi", "psi", "d", "kappa"} <= set(x):
            raise ValueError(f"{name}: expected a dict of phi, psi, d, kappa (path_truth)")
    rows = _index("rows", rows, len(est["d"]))
    cols = _index("cols", cols, len(tru["d"]))
    if rows.shape != cols.shape:
        raise ValueError(f"rows, cols: expected one length, got {rows.shape}, {cols.shape}")
    offset = finite_array("offset", offset, shape=())
    return np.column_stack(
        [
            np.degrees(_wrap(est["phi"][rows] - tru["phi"][cols])),
            np.degrees(est["psi"][rows] - tru["psi"][cols]),
            est["d"][rows] - offset - tru["d"][cols],
            est["kappa"][rows] - tru["kappa"][cols],
        ]
    )
