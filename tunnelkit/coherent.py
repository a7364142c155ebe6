"""Coherent paths inside one CPD component: spatial separation (ours, beyond Italiano et al. 2026).

In the JAVELIN tunnel every path of an epoch arrives within about a metre of the LoS (the 100 MHz
SRS resolves 3 m) and within a fraction of a metre per second in Doppler (12 symbols resolve
about 140 m/s). The ceiling bounce, 0.2 m above the base station, is only centimetres longer than
the LoS. Such paths have (nearly) the same frequency and time factors, so their sum is a rank-one
term of the tensor. The CPD of eq. 11 then returns them as **one** component, whose spatial factor
is a mixture ``a_1 s(q_1) + a_2 s(q_2)``; eq. 16-18 read one biased angle from it, and another
component of the rank-``L`` fit is spent on noise.

The array still separates them: the steering vectors of sources ``q`` (local frame) are known in
closed form (spherical wavefront, eq. 2), so a mixture is fitted with one, two or three sources by
nonlinear least squares (the complex gains enter linearly). Steps:

1. :func:`split_component` — for each CPD component, fit one source (started at eq. 16-24's
   answer); while the relative residual stays above ``tol``, start one more source at the
   far-field beam-scan peak of the residual and refit all together (RELAX-like); a split is kept
   only if it halves the residual, its gains stay bounded and its sources are distinct.
2. :func:`resolve_coherent` — pool the sources of all components, drop duplicates (one path seen
   in two components), keep the ``L`` strongest (``L`` known, as in the paper), then estimate
   every path's own delay and Doppler from ``S^+ H`` (the tensor beamformed onto the separated
   steering matrix ``S``; eq. 13-15 on each row's rank-one factors).

The returned :class:`~tunnelkit.extraction.PathEstimates` reads like :func:`extract_paths`'s, so
Algorithm 1, the measurements and the trackers take it unchanged.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.optimize import least_squares

from ._validate import integer, nonnegative, positive
from .arrays import check_element_positions
from .constants import C
from .extraction import (
    PathEstimates,
    _check_tensor,
    angles_from_solution,
    normalize_factors,
    path_estimates,
    refine_roots,
    vandermonde_roots,
)

__all__ = [
    "fit_sources",
    "resolve_coherent",
    "source_points",
    "spherical_steering",
    "split_component",
]

#: curvature bounds of a fitted source: 1 / kappa in [1 / KAPPA_MAX, 1 / KAPPA_MIN]
KAPPA_MIN, KAPPA_MAX = 1.0, 1000.0


def source_points(theta) -> np.ndarray:
    """Local source points (n, 3) from parameters ``(u_x, u_y, w)`` per source (flat or (n, 3)).

    ``(u_x, u_y)`` are the direction cosines in the array plane (the front half-space,
    ``u_z = sqrt(1 - u_x^2 - u_y^2)``) and ``w = 1 / kappa`` the wavefront curvature.
    """
    th = np.asarray(theta, float).reshape(-1, 3)
    uz = np.sqrt(np.clip(1.0 - th[:, 0] ** 2 - th[:, 1] ** 2, 1e-12, None))
    return np.column_stack([th[:, 0], th[:, 1], uz]) / th[:, 2:3]


def spherical_steering(sources, element_positions, fc: float) -> np.ndarray:
    """Steering matrix (M, n) of point sources: ``exp(j k0 (||q - p_m|| - ||q||))`` (eq. 1-2)."""
    q = np.atleast_2d(np.asarray(sources, float))
    p = np.asarray(element_positions, float)
    k0 = 2 * np.pi * fc / C
    dist = np.linalg.norm(q[None, :, :] - p[:, None, :], axis=-1)
    return np.exp(1j * k0 * (dist - np.linalg.norm(q, axis=1)[None, :]))


def _steering_and_jacobian(theta, p, k0):
    """Steering (M, n) and its derivatives (M, n, 3) with respect to ``(u_x, u_y, w)``."""
    th = np.asarray(theta, float).reshape(-1, 3)
    q = source_points(th)
    diff = q[None, :, :] - p[:, None, :]
    dist = np.linalg.norm(diff, axis=-1)
    rq = np.linalg.norm(q, axis=1)
    S = np.exp(1j * k0 * (dist - rq[None, :]))
    grad_q = k0 * (diff / dist[..., None] - (q / rq[:, None])[None])  # d phase / d q, (M, n, 3)
    ux, uy, w = th[:, 0], th[:, 1], th[:, 2]
    uz = q[:, 2] * w
    dq = np.stack(
        [
            np.column_stack([1 / w, np.zeros_like(w), -ux / (uz * w)]),
            np.column_stack([np.zeros_like(w), 1 / w, -uy / (uz * w)]),
            -q / w[:, None],
        ],
        axis=1,
    )  # (n, 3 params, 3 coords)
    dphase = np.einsum("mnc,npc->mnp", grad_q, dq)
    return S, 1j * S[..., None] * dphase


def fit_sources(
    b, theta0, element_positions, fc: float, *, max_nfev: int = 40
) -> tuple[np.ndarray, np.ndarray, float]:
    """Least-squares fit of ``b ~ S(theta) g`` (point sources, complex gains ``g``).

    ``theta0`` (n, 3) starts ``(u_x, u_y, 1 / kappa)`` per source; the gains start at their
    least-squares values. All parameters then take bounded trust-region steps (scipy's
    ``least_squares``) with the analytic Jacobian of the model (real and imaginary parts
    stacked), and the gains are re-solved exactly at the optimum.
    Returns ``(theta (n, 3), g (n,), relative residual energy ||b - S g||^2 / ||b||^2)``.
    """
    b = np.asarray(b, complex)
    p = np.asarray(element_positions, float)
    k0 = 2 * np.pi * fc / C
    th0 = np.asarray(theta0, float).reshape(-1, 3)
    n = th0.shape[0]
    lo = np.tile([-1.0, -1.0, 1 / KAPPA_MAX], n)
    hi = np.tile([1.0, 1.0, 1 / KAPPA_MIN], n)
    S0 = spherical_steering(source_points(th0), p, fc)
    g0 = np.linalg.lstsq(S0, b, rcond=None)[0]
    x0 = np.concatenate([np.clip(th0.ravel(), lo + 1e-9, hi - 1e-9), g0.real, g0.imag])
    lb = np.concatenate([lo, np.full(2 * n, -np.inf)])
    ub = np.concatenate([hi, np.full(2 * n, np.inf)])

    def split(x):
        return x[: 3 * n], x[3 * n : 4 * n] + 1j * x[4 * n :]

    def resid(x):
        th, g = split(x)
        S, _ = _steering_and_jacobian(th, p, k0)
        e = S @ g - b
        return np.concatenate([e.real, e.imag])

    def jac(x):
        th, g = split(x)
        S, dS = _steering_and_jacobian(th, p, k0)
        Jt = (dS * g[None, :, None]).reshape(p.shape[0], 3 * n)
        J = np.concatenate([Jt, S, 1j * S], axis=1)
        return np.concatenate([J.real, J.imag], axis=0)

    sol = least_squares(
        resid,
        x0,
        jac=jac,
        bounds=(lb, ub),
        method="trf",
        x_scale="jac",
        ftol=1e-6,
        xtol=1e-6,
        max_nfev=max_nfev,
    )
    th, _ = split(sol.x)
    S = spherical_steering(source_points(th), p, fc)
    g = np.linalg.lstsq(S, b, rcond=None)[0]  # exact projection at the optimum
    rel = float(np.linalg.norm(b - S @ g) ** 2 / max(np.linalg.norm(b) ** 2, 1e-300))
    return th.reshape(n, 3), g, rel


@lru_cache(maxsize=8)
def _scan_grid(pos_bytes: bytes, m: int, fc: float, n_grid: int):
    """Far-field beam-scan grid of one array: directions (G, 2) and the steering matrix (M, G)."""
    p = np.frombuffer(pos_bytes).reshape(m, 3)
    g = np.linspace(-1, 1, n_grid)
    ux, uy = np.meshgrid(g, g)
    keep = ux**2 + uy**2 < 0.99
    u = np.column_stack([ux[keep], uy[keep]])
    A = np.exp(-2j * np.pi * fc / C * (p[:, :2] @ u.T))  # far field: delta_m = -u . p_m
    return u, A


def _scan_peak(r, p, fc: float, n_grid: int = 121) -> np.ndarray:
    """Direction cosines ``(u_x, u_y)`` of the strongest far-field beam of residual ``r``."""
    p = np.ascontiguousarray(p, float)
    u, A = _scan_grid(p.tobytes(), p.shape[0], float(fc), n_grid)
    return u[int(np.argmax(np.abs(A.conj().T @ r)))]


def split_component(
    b,
    theta0,
    element_positions,
    fc: float,
    *,
    max_sources: int = 3,
    tol: float = 1e-3,
    min_separation: float = 0.05,
    max_gain: float = 3.0,
) -> tuple[np.ndarray, np.ndarray, float]:
    """One CPD spatial factor ``b`` (M,) as one to ``max_sources`` point sources.

    Starts with one source at ``theta0`` ``(u_x, u_y, 1 / kappa)``; while the relative residual
    exceeds ``tol`` a source is added at the beam-scan peak of the residual and all are refitted.
    The split is kept only if the residual at least halves, no two sources are closer than
    ``min_separation`` in ``(u_x, u_y)`` and no gain exceeds ``max_gain`` times ``|b|_rms`` (an
    ill-conditioned pair of near-identical sources with large opposite gains is not a path).
    Returns ``(theta (n, 3), g (n,), relative residual)``.
    """
    b = np.asarray(b, complex)
    p = np.asarray(element_positions, float)
    th, g, rel = fit_sources(b, theta0, p, fc)
    scale = float(np.sqrt(np.mean(np.abs(b) ** 2)))
    while rel > tol and th.shape[0] < max_sources:
        S = spherical_steering(source_points(th), p, fc)
        u = _scan_peak(b - S @ g, p, fc)
        start = np.vstack([th, [u[0], u[1], 1 / 30.0]])
        th2, g2, rel2 = fit_sources(b, start, p, fc)
        du = np.linalg.norm(th2[:, None, :2] - th2[None, :, :2], axis=-1)
        distinct = np.min(du[np.triu_indices(len(th2), 1)]) >= min_separation
        if not (rel2 < 0.5 * rel and distinct and np.max(np.abs(g2)) <= max_gain * scale):
            break
        th, g, rel = th2, g2, rel2
    return th, g, rel


def resolve_coherent(
    H,
    est: PathEstimates,
    element_positions,
    fc: float,
    subcarrier_spacing: float,
    symbol_period: float,
    n_paths: int | None = None,
    *,
    max_sources: int = 3,
    tol: float = 1e-3,
    min_separation: float = 0.05,
    min_power: float = 0.01,
) -> PathEstimates:
    """Separate coherent paths merged in the CPD components of ``est`` (see the module text).

    ``H`` is the tensor ``est`` was extracted from, ``n_paths`` the number of paths to return
    (default ``len(est)``). Every returned path has its own source fit (direction; curvature,
    NaN = far field when the fit sits on the ``KAPPA_MAX`` bound), and its own delay, Doppler
    and gain from the tensor beamformed onto the separated steering vectors. Components weaker
    than ``min_power`` times the strongest (in amplitude) are fitted with one source only: at
    that level they are the noise a rank-``L`` fit spends its spare components on.
    """
    if not isinstance(est, PathEstimates):
        raise TypeError(f"est: expected PathEstimates, got {type(est).__name__}")
    H = _check_tensor(H)
    M, nf, nt = H.shape
    pos = check_element_positions("element_positions", element_positions, m=M)
    fc = positive("fc", fc)
    df = positive("subcarrier_spacing", subcarrier_spacing)
    T0 = positive("symbol_period", symbol_period)
    L = len(est) if n_paths is None else integer("n_paths", n_paths, minimum=1)
    max_sources = integer("max_sources", max_sources, minimum=1)
    positive("tol", tol)
    positive("min_separation", min_separation)
    nonnegative("min_power", min_power)

    # 1. split every component; candidates carry (theta, power)
    thetas, powers = [], []
    strong = np.abs(est.alpha) >= min_power * np.max(np.abs(est.alpha))
    for l_ in range(len(est)):
        u = est.direction[l_]
        kap = est.kappa[l_] if np.isfinite(est.kappa[l_]) and est.kappa[l_] > 0 else 30.0
        w = float(np.clip(1 / kap, 1 / KAPPA_MAX, 1 / KAPPA_MIN))
        th, g, _ = split_component(
            est.factors[0][:, l_],
            [u[0], u[1], w],
            pos,
            fc,
            max_sources=max_sources if strong[l_] else 1,
            tol=tol,
            min_separation=min_separation,
        )
        thetas.append(th)
        powers.append(np.abs(est.alpha[l_] * g) ** 2)
    theta = np.vstack(thetas)
    power = np.concatenate(powers)

    # 2. strongest first; a source closer than min_separation to a kept one is the same path
    kept: list[int] = []
    for i in np.argsort(-power):
        if all(np.linalg.norm(theta[i, :2] - theta[j, :2]) >= min_separation for j in kept):
            kept.append(int(i))
        if len(kept) == L:
            break
    theta = theta[kept]
    q = source_points(theta)

    # 3. each path's own delay, Doppler and gain: rows of S^+ H, rank one in (frequency, time)
    S = spherical_steering(q, pos, fc)
    X = np.linalg.lstsq(S, H.reshape(M, nf * nt), rcond=None)[0].reshape(-1, nf, nt)
    bf = np.empty((nf, len(kept)), complex)
    bt = np.empty((nt, len(kept)), complex)
    for j, Xj in enumerate(X):
        uu, ss, vh = np.linalg.svd(Xj, full_matrices=False)
        bf[:, j], bt[:, j] = uu[:, 0] * ss[0], vh[0]
    (bs, bf, bt), alpha = normalize_factors((S, bf, bt))
    mu_f, beta_f = refine_roots(bf, vandermonde_roots(bf))
    mu_t, beta_t = refine_roots(bt, vandermonde_roots(bt))
    alpha = alpha * beta_f * beta_t
    d = -C / (2 * np.pi * df) * mu_f  # eq. 14
    v = C / (2 * np.pi * fc * T0) * mu_t  # eq. 15

    kap = np.linalg.norm(q, axis=1)
    near = theta[:, 2] > 1.001 / KAPPA_MAX
    ang = angles_from_solution(np.column_stack([q[:, :2], kap]), theta[:, :2])
    delta = np.linalg.norm(q[:, None, :] - pos[None], axis=-1) - kap[:, None]
    model = np.einsum(
        "ml,sl,kl->msk",
        bs * alpha,
        np.exp(1j * np.arange(nf)[:, None] * mu_f),
        np.exp(1j * np.arange(nt)[:, None] * mu_t),
    )
    rel = float(np.linalg.norm(H - model) / np.linalg.norm(H))
    return path_estimates(
        alpha, d, v, ang, near, delta, mu_f, mu_t, (bs, bf, bt), rel, est.n_iter, est.converged
    )
