"""Starts of the maximum-likelihood stage: one path sought in a (residual) tensor
(:func:`search_path`), a start completed to ``L`` paths by successive cancellation
(:func:`complete_paths`), a start read from any route's estimates (:func:`start_from_estimates`)
or checked as given (:func:`check_start`).

A search takes the dominant rank-one term of its tensor (power iterations), the periodogram peaks
of its frequency and time vectors for ``mu_f`` and ``mu_t``, a far-field beam scan of its spatial
vector for ``u``, a 1-D scan of ``w`` and a local single-source fit
(:func:`tunnelkit.extraction.coherent.fit_sources`).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg.blas import zherk

from ..._validate import finite_array, integer, sequence
from ...budget import check_elements
from ...constants import C
from ..coherent import fit_sources
from ..estimates import PathEstimates
from ..numerics import scan_peak, spatial_phase
from ..paper import refine_roots
from .model import Problem, project_feasible

__all__ = [
    "check_start",
    "complete_paths",
    "path_from_peak",
    "search_path",
    "start_from_estimates",
]


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


def _spatial_search(x, prob: Problem, n_grid: int = 61, u=None):
    """Direction and curvature of one wave from a spatial vector ``x`` (M,): far-field beam scan
    (or the direction ``u`` given), then a 1-D scan in ``w``, then a local single-source fit."""
    p = prob.pos
    fc = prob.k0 * C / (2 * np.pi)
    if u is None:
        u = scan_peak(x, p, fc, n_grid=n_grid)
    u = np.asarray(u, float) * min(1.0, 0.98 / max(np.linalg.norm(u), 1e-12))
    ws = np.concatenate([[0.0], 1.0 / np.geomspace(0.6, 300.0, 40)])
    th = np.column_stack([np.tile(u, (ws.size, 1)), ws])
    a = np.exp(1j * spatial_phase(th, p, prob.k0)[0])
    w0 = ws[int(np.argmax(np.abs(a.conj().T @ x)))]
    th_fit, _, _ = fit_sources(x, [u[0], u[1], min(max(w0, 1e-3 + 1e-9), 0.999)], p, fc)
    th_fit = project_feasible(th_fit)
    # the curvature bound of the single-source fit (1 m .. 1 km) is narrower than ours
    return th_fit[0]


def _check_problem(prob) -> Problem:
    if not isinstance(prob, Problem):
        raise TypeError(f"prob: expected a Problem, got {type(prob).__name__}")
    return prob


def search_path(R, prob: Problem) -> tuple[np.ndarray, float, float]:
    """One path ``(theta (3,), mu_f, mu_t)`` from the strongest rank-one term of ``R`` (a tensor
    of the shape of ``prob.H``: the tensor itself, or a residual)."""
    _check_problem(prob)
    if np.shape(R) != prob.H.shape:
        raise ValueError(f"R: expected shape {prob.H.shape}, got {np.shape(R)}")
    finite_array("R", R, dtype=complex)
    x, y, z = _power_rank_one(R)
    mf0 = float(np.angle(np.sum(y[1:] * y[:-1].conj())))
    mt0 = float(np.angle(np.sum(z[1:] * z[:-1].conj())))
    mf, _ = refine_roots(y[:, None] / y[0], np.array([mf0]), n_steps=6)
    mt, _ = refine_roots(z[:, None] / z[0], np.array([mt0]), n_steps=6)
    th = _spatial_search(x, prob)
    return th, float(mf[0]), float(mt[0])


def path_from_peak(prob: Problem, loc, x) -> tuple[np.ndarray, float, float]:
    """One path ``(theta (3,), mu_f, mu_t)`` at a peak of the residual's periodogram
    (:func:`~.residual.residual_peak`: ``loc = (u_x, u_y, mu_f, mu_t)`` on its grid and ``x`` the
    spatial vector of its delay-Doppler cell): the curvature by a 1-D scan and a single-source
    fit of ``x`` from the grid direction."""
    _check_problem(prob)
    ux, uy, mf, mt = (float(v) for v in finite_array("loc", loc, shape=(4,)))
    th = _spatial_search(finite_array("x", x, shape=(prob.M,), dtype=complex), prob, u=(ux, uy))
    return th, mf, mt


def complete_paths(prob: Problem, start, n_paths: int):
    """``start = (theta, mu_f, mu_t)`` with paths found in the residual added until there are
    ``n_paths`` (successive cancellation); returns the completed ``(theta, mu_f, mu_t)``."""
    _check_problem(prob)
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


def start_from_estimates(est: PathEstimates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(theta (L, 3), mu_f, mu_t)`` from any route's estimates, projected onto the feasible set
    (far-field or non-finite curvature -> ``w = 0``; directions behind the array plane are
    mirrored into the front half-space before the projection)."""
    if not isinstance(est, PathEstimates):
        raise TypeError(f"est: expected PathEstimates, got {type(est).__name__}")
    u = np.asarray(est.direction, float)
    kap = np.asarray(est.kappa, float)
    w = np.where(np.isfinite(kap) & (kap > 0), 1.0 / np.where(kap > 0, kap, 1.0), 0.0)
    th = np.column_stack([np.nan_to_num(u[:, 0]), np.nan_to_num(u[:, 1]), w])
    return (
        project_feasible(th),
        np.nan_to_num(est.mu_f).astype(float),
        np.nan_to_num(est.mu_t).astype(float),
    )


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
