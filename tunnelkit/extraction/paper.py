"""Stage 2 of the extraction: the paper's route from CPD factors to path parameters (Italiano et
al. 2026, eq. 13-24, Algorithm 1).

:func:`vandermonde_roots` (eq. 13-15; :func:`refine_roots`; the joint refinement:
:func:`~tunnelkit.extraction.joint.refine_joint`),
:func:`unwrap_spatial` (eq. 16), :func:`solve_near_field` and :func:`solve_far_field` (eq.
17-18), :func:`angles_from_solution` (eq. 19-24, ``psi`` the polar angle of eq. 19),
:func:`algorithm1` (ExtractMeas' checks) and :func:`paper_route` (steps 1-4 to a
:class:`~tunnelkit.extraction.PathEstimates`). ``H`` follows eq. 1 exactly as printed.

How it works, with the eq. 19 / eq. 22 convention: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

import numpy as np

from .._checks import numeric_array
from .._validate import finite_array, integer
from ..constants import C
from .decomposition import check_rank, check_tensor, cpd, normalize_factors
from .estimates import PathEstimates, path_estimates
from .numerics import MIN_SIGNIFICANCE, grid_index
from .radio import check_array, check_srs

__all__ = [
    "algorithm1",
    "angles_from_solution",
    "paper_route",
    "refine_roots",
    "solve_far_field",
    "solve_near_field",
    "unwrap_spatial",
    "vandermonde_roots",
]


def vandermonde_roots(B) -> np.ndarray:
    """Eq. 13: ``mu = angle(diag(B_-^H B_+))`` for a (normalised) Vandermonde factor ``B`` (N, L)."""
    B = finite_array("B", B, ndim=2, dtype=complex)
    if B.shape[0] < 2 or B.shape[1] < 1:
        raise ValueError(f"B: expected (N >= 2, L >= 1) factor rows, got shape {B.shape}")
    if np.any(np.abs(B).max(axis=0) == 0):
        raise ValueError("B: a column is all zero (no path to take roots of)")
    return np.angle(np.sum(B[:-1].conj() * B[1:], axis=0))


def refine_roots(B, mu, n_steps: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Newton steps to the peak of ``|sum_n B[n] exp(-j mu n)|^2`` per column (single-tone ML).

    Returns the refined roots and the fitted amplitude ``beta = mean_n B[n] exp(-j mu n)`` (1 for
    a perfect normalised Vandermonde column). Steps are limited to a quarter of a bin.
    """
    B = numeric_array("B", B, (2,))
    N = B.shape[0]
    n = np.arange(N)[:, None]
    mu = numeric_array("mu", mu, (1,))
    if mu.shape[0] != B.shape[1] or mu.dtype.kind == "c":
        raise ValueError(
            f"mu: expected {B.shape[1]} real roots (one per column of B), got {mu.shape}"
        )
    n_steps = integer("n_steps", n_steps, minimum=0, maximum=1000)
    mu = np.array(mu, dtype=float)
    for _ in range(n_steps):
        e = np.exp(-1j * n * mu[None, :])
        S = np.sum(B * e, axis=0)
        S1 = np.sum(-1j * n * B * e, axis=0)
        S2 = np.sum(-(n**2) * B * e, axis=0)
        d1 = 2 * np.real(S.conj() * S1)
        d2 = 2 * (np.abs(S1) ** 2 + np.real(S.conj() * S2))
        step = np.where(d2 < 0, -d1 / np.where(d2 < 0, d2, -1.0), 0.0)
        mu = mu + np.clip(step, -np.pi / (2 * N), np.pi / (2 * N))
    beta = np.mean(B * np.exp(-1j * n * mu[None, :]), axis=0)
    return np.angle(np.exp(1j * mu)), beta


def unwrap_spatial(b, element_positions) -> np.ndarray:
    """Eq. 16 without the ``c / (2 pi fc)`` factor: unwrapped phase (M, L) of the spatial factor.

    ``b`` (M, L) normalised so that ``b[0] = 1``. On a full rectangular grid (a URA, or a ULA) the
    phase image is unwrapped with scikit-image's ``unwrap_phase`` (Herráez et al. 2002); for other
    planar layouts it is unwrapped along a minimum spanning tree of the elements. The result is
    shifted so that the reference element has phase 0 (eq. 2: ``delta_0 = 0``).
    """
    b = finite_array("b", b, dtype=complex)
    p = finite_array("element_positions", element_positions, ndim=2)
    if b.ndim not in (1, 2) or b.shape[0] != p.shape[0]:
        raise ValueError(f"b: expected (M, L) with M = {p.shape[0]} elements, got shape {b.shape}")
    ph = np.angle(b)
    grid = grid_index(p)
    out = np.empty_like(ph)
    if grid is not None and min(grid[2], grid[3]) > 1:
        from skimage.restoration import unwrap_phase

        r, c, nr, nc = grid
        for j_ in range(ph.shape[1]):
            img = np.zeros((nr, nc))
            img[r, c] = ph[:, j_]
            un = unwrap_phase(img)
            out[:, j_] = un[r, c]
    elif grid is not None:  # one row or column: 1-D unwrap in element order along the line
        r, c, nr, nc = grid
        order = np.argsort(r * nc + c)
        out[order] = np.unwrap(ph[order], axis=0)
    else:
        from scipy.sparse.csgraph import breadth_first_order, minimum_spanning_tree

        dist = np.linalg.norm(p[:, None, :2] - p[None, :, :2], axis=-1)
        tree = minimum_spanning_tree(dist)
        order, pred = breadth_first_order(tree, 0, directed=False)
        out[0] = ph[0]
        for i in order[1:]:
            j = pred[i]
            out[i] = out[j] + np.angle(np.exp(1j * (ph[i] - ph[j])))
    return out - out[0]


def _line_direction(p: np.ndarray, rtol: float = 1e-12):
    """Unit in-plane direction ``e`` (2,) if the elements' xy positions are collinear, else None.

    The reference antenna is at the origin, so a linear array lies on the line ``t e``; any
    direction counts (a ULA along local x *or* y, or diagonal).
    """
    xy = p[:, :2]
    far = int(np.argmax(np.linalg.norm(xy, axis=1)))
    size = float(np.linalg.norm(xy[far]))
    if size == 0:
        return None
    e = xy[far] / size
    off = np.abs(xy[:, 0] * e[1] - xy[:, 1] * e[0])  # distance from the line through 0 along e
    return e if np.max(off) <= rtol * size else None


def _delta_positions(delta, element_positions) -> tuple[np.ndarray, np.ndarray]:
    """``delta`` as (M, L) real (NaN allowed) and the (M, 3) element positions, M matching."""
    delta = numeric_array("delta", delta, (1, 2))
    if delta.dtype.kind == "c":
        raise TypeError("delta: expected real phase distances, got complex numbers")
    delta = np.atleast_2d(np.asarray(delta, float).T).T
    p = finite_array("element_positions", element_positions, ndim=2)
    if p.shape[1] != 3 or p.shape[0] != delta.shape[0] or p.shape[0] < 2:
        raise ValueError(
            f"element_positions: expected ({delta.shape[0]}, 3) (one row per row of delta), "
            f"got {p.shape}"
        )
    return delta, p


def solve_near_field(delta, element_positions) -> np.ndarray:
    """TLS solution ``x = (x_l, y_l, kappa_l)`` of eq. 18 for each column of ``delta`` (M, L).

    Rows ``2 [x_m, y_m, delta_m] x = r_m^2 - delta_m^2`` (m >= 1); the TLS solution is the last
    right singular vector of ``[2 A, -y]`` scaled to a unit last entry. For a linear array (a
    ULA along any direction ``e`` of the array plane) the columns ``x_m, y_m`` are replaced by the
    coordinate ``t_m = e . p_m`` along the line and the returned ``(x, y)`` is ``t e`` (the
    component across the line is unobservable and returned as 0). Returns (L, 3).
    """
    delta, p = _delta_positions(delta, element_positions)
    xm, ym = p[1:, 0], p[1:, 1]
    r2 = np.sum(p[1:] ** 2, axis=1)
    line = _line_direction(p)
    linear = line is not None
    tm = p[1:, :2] @ line if linear else None  # coordinate along the array's line
    out = np.empty((delta.shape[1], 3))
    for j_ in range(delta.shape[1]):
        dm = delta[1:, j_]
        cols = [tm, dm] if linear else [xm, ym, dm]
        A = 2 * np.stack(cols, axis=1)
        aug = np.column_stack([A, -(r2 - dm**2)])
        aug_scale = np.linalg.norm(aug, axis=0)
        aug_scale[aug_scale == 0] = 1.0
        _, _, vh = np.linalg.svd(aug / aug_scale, full_matrices=False)
        v = vh[-1] / aug_scale
        sol = v[:-1] / v[-1] if abs(v[-1]) > 1e-300 else np.full(len(cols), np.nan)
        out[j_] = [*(sol[0] * line), sol[1]] if linear else sol
    return out


def solve_far_field(delta, element_positions) -> np.ndarray:
    """LS far-field solution of ``[x_m, y_m] u = -delta_m``: ``u = (cos phi sin psi, sin phi sin psi)``.

    In the far field ``delta_m = -u . p_m`` (eq. 17 with ``kappa -> inf``). Returns (L, 2); for a
    linear array along ``e`` only ``u . e`` is observable and ``(u . e) e`` is returned.
    """
    delta, p = _delta_positions(delta, element_positions)
    line = _line_direction(p)
    A = (p[1:, :2] @ line)[:, None] if line is not None else p[1:, :2]
    sol = np.linalg.lstsq(A, -delta[1:], rcond=None)[0].T
    return sol[:, :1] * line[None, :] if line is not None else sol


def angles_from_solution(x_nf, u_ff):
    """Eq. 19-24 in the eq. 19 convention; returns dict of phi/psi/direction for NF and FF.

    NF: ``rho = ||(x, y)||``, ``psi = asin(rho / kappa)`` (polar angle from the array normal),
    ``direction = (x, y, sqrt(kappa^2 - rho^2)) / kappa``. FF: ``direction = (u_x, u_y,
    sqrt(1 - |u|^2))``. Ratios above 1 (noise) are clipped to 1.
    """
    x_nf = np.atleast_2d(numeric_array("x_nf", x_nf, (1, 2), last=3))
    u_ff = np.atleast_2d(numeric_array("u_ff", u_ff, (1, 2), last=2))
    if x_nf.shape[0] != u_ff.shape[0]:
        raise ValueError(
            f"u_ff: expected {x_nf.shape[0]} rows (one per row of x_nf), got {u_ff.shape[0]}"
        )
    kap = x_nf[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        s_nf = np.clip(np.hypot(x_nf[:, 0], x_nf[:, 1]) / np.abs(kap), 0.0, 1.0)
    phi_nf = np.arctan2(x_nf[:, 1], x_nf[:, 0])
    dir_nf = np.column_stack([s_nf * np.cos(phi_nf), s_nf * np.sin(phi_nf), np.sqrt(1 - s_nf**2)])
    s_ff = np.clip(np.hypot(u_ff[:, 0], u_ff[:, 1]), 0.0, 1.0)
    phi_ff = np.arctan2(u_ff[:, 1], u_ff[:, 0])
    dir_ff = np.column_stack([s_ff * np.cos(phi_ff), s_ff * np.sin(phi_ff), np.sqrt(1 - s_ff**2)])
    return {
        "phi_nf": phi_nf,
        "psi_nf": np.arcsin(s_nf),
        "dir_nf": dir_nf,
        "kappa_nf": kap,
        "phi_ff": phi_ff,
        "psi_ff": np.arcsin(s_ff),
        "dir_ff": dir_ff,
    }


def algorithm1(est: PathEstimates, min_d: float = 0.0) -> np.ndarray:
    """Algorithm 1 (ExtractMeas) checks: indices of the kept paths (``d >= min_d``).

    The near/far choice (``kappa < 0`` -> far-field angles, no kappa) is already applied in
    :func:`extract_paths`; this returns the paths that survive line 5-6. As printed, line 5
    drops ``d < 0`` (``min_d = 0``, :attr:`PathEstimates.valid`). But ``d`` carries the clock
    bias, up to ``b_max = 100`` ns either way in section 4.2, so a path nearer than
    ``c b_max = 30`` m can arrive with ``d < 0`` and still be good; ``min_d = -c b_max`` is the
    check that only drops what no bias explains. Paths the maximum-likelihood route finds
    indistinguishable from noise stay dropped either way, and so do paths that are not physical
    (:meth:`PathEstimates.physical`: ``|v| >= c``, a direction behind the array).
    """
    if not isinstance(est, PathEstimates):
        raise TypeError(f"est: expected PathEstimates, got {type(est).__name__}")
    min_d = float(min_d)
    if not np.isfinite(min_d) or min_d > 0:
        raise ValueError(f"min_d: expected a finite value <= 0, got {min_d}")
    if min_d == 0.0:
        return np.flatnonzero(est.valid)
    detected = (
        np.ones(len(est), bool)
        if est.significance is None
        else np.asarray(est.significance) >= MIN_SIGNIFICANCE
    )
    return np.flatnonzero(detected & (est.d >= min_d) & est.physical())


#: the refinements of the paper's route (see :func:`paper_route`)
PAPER_REFINES = ("joint", "column", "none")


def paper_route(
    H,
    n_paths: int,
    array,
    srs,
    *,
    refine: str = "joint",
    method: str = "fast",
    n_iter_max: int = 200,
    tol: float = 1e-10,
    polish: int | None = None,
) -> PathEstimates:
    """The CPD of ``H`` and eq. 13-24: path parameters from the CPD factors.

    ``array`` (:class:`~tunnelkit.arrays.ArrayGeometry` or (M, 3) local positions) and ``srs``
    (:class:`~tunnelkit.channel.SRSConfig`) as in :func:`~tunnelkit.extraction.extract_paths`.
    ``refine``: "joint" — after eq. 13, maximum-likelihood refinement of all roots together with
    free spatial factors (:func:`~tunnelkit.extraction.joint.refine_joint`); "column" — each root to the periodogram peak of
    its own factor column (:func:`refine_roots`); "none" — eq. 13 roots and eq. 12 gains as
    they are. ``method``, ``n_iter_max``, ``tol`` go to :func:`~tunnelkit.extraction.cpd`;
    ``polish`` ALS sweeps on the full tensor after the compressed CPD (default 2, or 0 with
    ``refine="joint"``, which supersedes them).
    """
    H = check_tensor(H)
    L = check_rank(H.shape, n_paths)
    pos = check_array(array, m=H.shape[0])
    srs = check_srs(srs)
    if refine not in PAPER_REFINES:
        raise ValueError(f"refine: expected one of {PAPER_REFINES}, got {refine!r}")
    fc, df, T0 = srs.fc, srs.tone_spacing, srs.symbol_period
    if polish is None:
        polish = 0 if refine == "joint" else 2
    res = cpd(
        H, L, method=method, n_iter_max=n_iter_max, tol=tol, element_positions=pos, polish=polish
    )
    (bs, bf, bt), alpha = normalize_factors(res.factors)
    mu_f, mu_t = vandermonde_roots(bf), vandermonde_roots(bt)  # eq. 13
    if refine in ("column", "joint"):
        mu_f, beta_f = refine_roots(bf, mu_f)
        mu_t, beta_t = refine_roots(bt, mu_t)
        alpha = alpha * beta_f * beta_t
    if refine == "joint":
        # project the spatial mode on the span of the CPD's spatial factors first: the roots'
        # information lies there, and each Gauss-Newton step gets M / L times cheaper
        from .joint import refine_joint  # loaded when the step runs

        Q, _ = np.linalg.qr(res.factors[0])
        mu_f, mu_t, Ac = refine_joint(np.tensordot(Q.conj(), H, axes=(0, 0)), mu_f, mu_t)
        A = Q @ Ac
        alpha = A[0].copy()
        bs = A / A[0][None, :]
    d = -C / (2 * np.pi * df) * mu_f  # eq. 14
    v = C / (2 * np.pi * fc * T0) * mu_t  # eq. 15
    delta = C / (2 * np.pi * fc) * unwrap_spatial(bs, pos)  # eq. 16
    x_nf = solve_near_field(delta, pos)
    u_ff = solve_far_field(delta, pos)
    ang = angles_from_solution(x_nf, u_ff)
    near = np.isfinite(ang["kappa_nf"]) & (ang["kappa_nf"] > 0)
    return path_estimates(
        alpha,
        d,
        v,
        ang,
        near,
        delta.T,
        mu_f,
        mu_t,
        (bs, bf, bt),
        res.rel_error,
        res.n_iter,
        res.converged,
    )
