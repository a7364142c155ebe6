"""The fit from a start the caller gives: the start checked and projected onto the feasible set
(:func:`check_start`) and the joint fit on a tensor (:func:`fit_ml`, :func:`~.fitting.fit_problem`
on its :class:`~.model.Problem`)."""

from __future__ import annotations

import numpy as np

from ..._validate import integer, sequence
from ..decomposition import check_tensor
from ..radio import check_array, check_srs
from .fitting import MLFit, fit_problem
from .model import Problem, project_feasible

__all__ = ["check_start", "fit_ml"]


def check_start(start, n_paths: int):
    """A start ``(theta (L, 3), mu_f (L,), mu_t (L,))`` of ``L = n_paths`` paths, checked
    (finite, ``|u| < 1``, ``w >= 0``; ``ValueError`` naming ``start``) and projected onto the
    feasible set."""
    L = integer("n_paths", n_paths, minimum=1)
    if len(sequence("start", start)) != 3:
        raise ValueError(f"start: expected a tuple (theta, mu_f, mu_t), got {len(start)} items")
    try:
        th, mf, mt = (np.asarray(v, float) for v in start)
    except (TypeError, ValueError) as exc:
        raise ValueError("start: expected a tuple (theta, mu_f, mu_t) of real arrays") from exc
    th = np.atleast_2d(th)
    if th.shape != (L, 3) or mf.shape != (L,) or mt.shape != (L,):
        raise ValueError(
            f"start, n_paths: expected theta ({L}, 3), mu_f ({L},), mu_t ({L},); got "
            f"{th.shape}, {mf.shape}, {mt.shape}"
        )
    if not (np.all(np.isfinite(th)) and np.all(np.isfinite(mf)) and np.all(np.isfinite(mt))):
        raise ValueError("start: contains NaN or infinite values")
    if np.any(np.hypot(th[:, 0], th[:, 1]) >= 1.0):
        raise ValueError("start: a direction (u_x, u_y) lies outside the front half-space |u| < 1")
    if np.any(th[:, 2] < 0):
        raise ValueError(
            "start: a curvature w = 1/kappa is negative (wave origin behind the array)"
        )
    return project_feasible(th), mf, mt


def fit_ml(
    H,
    start,
    array,
    srs,
    *,
    noise_power: float | None = None,
    max_iter: int = 60,
    n_reseed: int | None = None,
    search: str = "residual",
) -> MLFit:
    """Joint maximum-likelihood fit of ``L`` paths started at ``start = (theta, mu_f, mu_t)``.

    ``theta`` (L, 3) is ``(u_x, u_y, 1/kappa)`` per path (local frame, ``|u| < 1``, ``w >= 0``);
    ``mu_f``, ``mu_t`` (L,) the Vandermonde frequencies. ``noise_power`` per sample (default:
    estimated, :func:`~.model.noise_floor`). ``n_reseed`` bounds the SAGE-like re-seedings (default
    ``L``; 0 = local fit only), ``search`` as in :func:`fit_problem`. ``array`` and ``srs`` as in
    :func:`~tunnelkit.extraction.extract_paths` (only the carrier of ``srs`` enters). See
    docs/internals/extraction-ml.md for the algorithm.
    """
    H = check_tensor(H)
    pos = check_array(array, m=H.shape[0])
    srs = check_srs(srs)
    L = np.atleast_2d(np.asarray(sequence("start", start)[0])).shape[0]
    start = check_start(start, L)
    return fit_problem(
        Problem(H, pos, srs.fc),
        start,
        noise_power=noise_power,
        max_iter=max_iter,
        n_reseed=n_reseed,
        search=search,
    )
