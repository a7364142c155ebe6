"""Starts of the maximum-likelihood stage: a path at a peak of the residual's periodogram
(:func:`path_from_peak`), a start read from any route's estimates (:func:`start_from_estimates`)
and the halves of a split path (:data:`SPLIT_STEPS`). One path sought in a (residual) tensor and
a start completed by successive cancellation are :mod:`.rank_one`'s, a start checked as given
:mod:`.given_start`'s.

A path's direction and curvature come from a spatial vector (:func:`spatial_search`): a far-field
beam scan (or the direction given), a 1-D scan of ``w`` and a local single-source fit
(:func:`tunnelkit.extraction.coherent.fit_sources`).
"""

from __future__ import annotations

import numpy as np

from ..._validate import finite_array
from ...constants import C
from ..coherent import fit_sources
from ..estimates import PathEstimates
from ..numerics import scan_peak, spatial_phase
from .model import Problem, project_feasible

__all__ = [
    "SPLIT_STEPS",
    "path_from_peak",
    "start_from_estimates",
]

#: offsets in (u_x, u_y) of the two halves of a split path (an eighth of a 10 x 10 beamwidth)
SPLIT_STEPS = ((0.012, 0.0), (0.0, 0.012))


def spatial_search(x, prob: Problem, n_grid: int = 61, u=None):
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


def check_problem(prob) -> Problem:
    """``prob`` itself if it is a :class:`~.model.Problem`, else ``TypeError`` naming ``prob``."""
    if not isinstance(prob, Problem):
        raise TypeError(f"prob: expected a Problem, got {type(prob).__name__}")
    return prob


def path_from_peak(prob: Problem, loc, x) -> tuple[np.ndarray, float, float]:
    """One path ``(theta (3,), mu_f, mu_t)`` at a peak of the residual's periodogram
    (:func:`~.residual.residual_peak`: ``loc = (u_x, u_y, mu_f, mu_t)`` on its grid and ``x`` the
    spatial vector of its delay-Doppler cell): the curvature by a 1-D scan and a single-source
    fit of ``x`` from the grid direction."""
    check_problem(prob)
    ux, uy, mf, mt = (float(v) for v in finite_array("loc", loc, shape=(4,)))
    th = spatial_search(finite_array("x", x, shape=(prob.M,), dtype=complex), prob, u=(ux, uy))
    return th, mf, mt


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
