"""One path sought in a (residual) tensor (:func:`search_path`) and a start completed to ``L``
paths by successive cancellation (:func:`complete_paths`): the dominant rank-one term of the
tensor (power iterations), the periodogram peaks of its frequency and time vectors for ``mu_f``
and ``mu_t`` and the direction and curvature of its spatial vector
(:func:`~.search.spatial_search`: a far-field beam scan, a 1-D scan of ``w``, a single-source
fit)."""

from __future__ import annotations

import numpy as np
from scipy.linalg.blas import zherk

from ..._validate import finite_array, integer, sequence
from ...budget import check_elements
from ..paper import refine_roots
from .model import Problem
from .search import check_problem, spatial_search

__all__ = ["complete_paths", "search_path"]


def _power_rank_one(R, n_iter: int = 6):
    """Dominant rank-one term ``x o y o z`` of ``R`` by alternating power iterations."""
    M, nf, nt = R.shape
    R2 = R.reshape(M * nf, nt)
    _, V = np.linalg.eigh(zherk(1.0, R2.T, trans=0), UPLO="U")  # conj of the time-mode Gram
    z = V[:, -1].conj()
    Rz = (R2 @ z.conj()).reshape(M, nf)
    u, _, vh = np.linalg.svd(Rz, full_matrices=False)
    x, y = u[:, 0], vh[0].conj()
    for _ in range(n_iter):
        z = np.einsum("msk,m,s->k", R, x.conj(), y.conj(), optimize=True)
        z /= np.linalg.norm(z)
        Rz = (R2 @ z.conj()).reshape(M, nf)
        y = Rz.T @ x.conj()
        y /= np.linalg.norm(y)
        x = Rz @ y.conj()
        x /= np.linalg.norm(x)
    return x, y, z


def search_path(R, prob: Problem) -> tuple[np.ndarray, float, float]:
    """One path ``(theta (3,), mu_f, mu_t)`` from the strongest rank-one term of ``R`` (a tensor
    of the shape of ``prob.H``: the tensor itself, or a residual)."""
    check_problem(prob)
    if np.shape(R) != prob.H.shape:
        raise ValueError(f"R: expected shape {prob.H.shape}, got {np.shape(R)}")
    finite_array("R", R, dtype=complex)
    x, y, z = _power_rank_one(R)
    mf0 = float(np.angle(np.sum(y[1:] * y[:-1].conj())))
    mt0 = float(np.angle(np.sum(z[1:] * z[:-1].conj())))
    mf, _ = refine_roots(y[:, None] / y[0], np.array([mf0]), n_steps=6)
    mt, _ = refine_roots(z[:, None] / z[0], np.array([mt0]), n_steps=6)
    th = spatial_search(x, prob)
    return th, float(mf[0]), float(mt[0])


def complete_paths(prob: Problem, start, n_paths: int):
    """``start = (theta, mu_f, mu_t)`` with paths found in the residual added until there are
    ``n_paths`` (successive cancellation); returns the completed ``(theta, mu_f, mu_t)``."""
    check_problem(prob)
    if len(sequence("start", start)) != 3:
        raise ValueError(f"start: expected a tuple (theta, mu_f, mu_t), got {len(start)} items")
    theta, mu_f, mu_t = start
    L = integer("n_paths", n_paths, minimum=theta.shape[0])
    check_elements("n_paths", 5 * L, what=f"{L} paths' parameters")
    H = prob.H
    while theta.shape[0] < L:
        if theta.shape[0]:
            ev = prob.evaluate(theta, mu_f, mu_t, derivatives=False)
            R = H - prob.model(theta, mu_f, mu_t, ev["c"])
        else:
            R = H
        th, mf, mt = search_path(R, prob)
        theta = np.vstack([theta, th])
        mu_f, mu_t = np.append(mu_f, mf), np.append(mu_t, mt)
    return theta, mu_f, mu_t
