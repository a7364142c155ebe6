"""Coherent paths inside one CPD component: spatial separation (ours, beyond Italiano et al. 2026).

Paths with (nearly) the same delay and Doppler are one CPD component whose spatial factor is a
mixture; the array separates them by fitting one, two or three point sources (spherical
wavefront, eq. 2): :func:`split_component` per component, :func:`resolve_coherent` for the
whole estimate (:func:`fit_sources`, :func:`spherical_steering`, :func:`source_points` under
them). The result reads like :func:`~tunnelkit.extraction.extract_paths`'s and starts the
maximum-likelihood stage (:mod:`.ml`).

How it works: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._physical import carrier
from .._validate import finite_array, integer, nonnegative, positive, probability
from ..arrays import check_element_positions
from ..constants import C
from .decomposition import check_tensor, cp_rel_error, normalize_factors
from .estimates import PathEstimates, path_estimates
from .numerics import (
    damped_solve_unchecked,
    damped_system_unchecked,
    free_newton_unchecked,
    scan_peak,
    solve_unchecked,
    spatial_phase_unchecked,
)
from .paper import angles_from_solution, refine_roots, vandermonde_roots
from .radio import check_array, check_srs

__all__ = [
    "fit_sources",
    "resolve_coherent",
    "source_points",
    "spherical_steering",
    "split_component",
]


#: curvature bounds of a fitted source: 1 / kappa in [1 / KAPPA_MAX, 1 / KAPPA_MIN]
KAPPA_MIN, KAPPA_MAX = 1.0, 1000.0
#: the most Levenberg-Marquardt steps :func:`fit_sources` takes (``max_nfev``)
MAX_NFEV = 10_000


def source_points(theta) -> np.ndarray:
    """Local source points (n, 3) from parameters ``(u_x, u_y, w)`` per source (flat or (n, 3)).

    ``(u_x, u_y)`` are the direction cosines in the array plane (the front half-space,
    ``u_z = sqrt(1 - u_x^2 - u_y^2)``) and ``w = 1 / kappa`` the wavefront curvature.
    """
    th = _theta("theta", theta)
    uz = np.sqrt(np.clip(1.0 - th[:, 0] ** 2 - th[:, 1] ** 2, 1e-12, None))
    return np.column_stack([th[:, 0], th[:, 1], uz]) / th[:, 2:3]


def _theta(name: str, theta) -> np.ndarray:
    """Source parameters ``(u_x, u_y, w)`` flat or (n, 3), finite, ``w = 1 / kappa > 0``."""
    th = finite_array(name, theta)
    if th.ndim > 2 or th.size == 0 or th.size % 3 or (th.ndim == 2 and th.shape[1] != 3):
        raise ValueError(f"{name}: expected (u_x, u_y, w) per source, (n, 3), got {th.shape}")
    th = th.reshape(-1, 3)
    if np.any(th[:, 2] <= 0):
        raise ValueError(f"{name}: the curvature w = 1 / kappa must be > 0, got {th[:, 2].min()}")
    return th


def spherical_steering(sources, element_positions, fc: float) -> np.ndarray:
    """Steering matrix (M, n) of point sources: ``exp(j k0 (||q - p_m|| - ||q||))`` (eq. 1-2)."""
    q = np.atleast_2d(finite_array("sources", sources))
    if q.ndim != 2 or q.shape[1] != 3:
        raise ValueError(f"sources: expected points (n, 3), got shape {q.shape}")
    p = finite_array("element_positions", element_positions, ndim=2)
    k0 = 2 * np.pi * carrier("fc", fc) / C
    dist = np.linalg.norm(q[None, :, :] - p[:, None, :], axis=-1)
    return np.exp(1j * k0 * (dist - np.linalg.norm(q, axis=1)[None, :]))


def fit_sources(
    b, theta0, element_positions, fc: float, *, max_nfev: int = 40
) -> tuple[np.ndarray, np.ndarray, float]:
    """Least-squares fit of ``b ~ S(theta) g`` (point sources, complex gains ``g``).

    ``theta0`` (n, 3) starts ``(u_x, u_y, 1 / kappa)`` per source; the gains start at their
    least-squares values and stay concentrated out (variable projection). Levenberg-Marquardt
    steps with the analytic Jacobian (Kaufman's form) are projected onto ``|u| <= 0.999`` (the
    front half-space) and the curvature onto ``[1 / KAPPA_MAX, 1 / KAPPA_MIN]``; at most
    ``max_nfev`` steps, stopping when a full Gauss-Newton step would lower the residual by
    less than a relative ``1e-6``.
    Returns ``(theta (n, 3), g (n,), relative residual energy ||b - S g||^2 / ||b||^2)``.
    """
    b = finite_array("b", b, ndim=1, dtype=complex)
    theta0 = _theta("theta0", theta0)
    p = check_element_positions("element_positions", element_positions, m=b.shape[0])
    max_nfev = integer("max_nfev", max_nfev, minimum=1, maximum=MAX_NFEV)
    return _fit_sources(b, theta0, p, carrier("fc", fc), max_nfev)


def _fit_sources(b, theta0, p, fc, max_nfev=40):
    """:func:`fit_sources` on checked arguments: variable projection (the gains are
    ``S^+ b``), Levenberg-Marquardt on ``(u_x, u_y, w)`` with Kaufman's Jacobian (as in
    :mod:`.ml`, one spatial mode only), every step projected onto ``|u| <= 0.999``,
    ``w in [1 / KAPPA_MAX, 1 / KAPPA_MIN]``."""
    k0 = 2 * np.pi * fc / C
    th = np.asarray(theta0, float).reshape(-1, 3).copy()
    n, m = th.shape[0], p.shape[0]
    b2 = max(float(np.vdot(b, b).real), 1e-300)

    def project(t):
        r = np.hypot(t[:, 0], t[:, 1])
        big = r > 0.999
        t[big, :2] *= (0.999 / r[big])[:, None]
        t[:, 2] = np.clip(t[:, 2], 1 / KAPPA_MAX, 1 / KAPPA_MIN)
        return t

    def evaluate(t):
        psi, dx, dy, dw = spatial_phase_unchecked(t, p, k0)
        S = np.exp(1j * psi)
        G = S.conj().T @ S
        g = solve_unchecked(G, S.conj().T @ b)
        r = b - S @ g
        return S, np.stack([dx, dy, dw], axis=2), G, g, r, float(np.vdot(r, r).real)

    th = project(th)
    cur = evaluate(th)
    lam = 1e-3
    system = None  # the damped system at the current point, kept while a step is rejected
    for _ in range(max_nfev):
        S, dpsi, G, g, r, cost = cur
        if system is None:
            D = (1j * dpsi * (S * g[None, :])[..., None]).reshape(m, 3 * n)
            DS = D.conj().T @ S
            A = (D.conj().T @ D - DS @ solve_unchecked(G, DS.conj().T)).real
            grad = (D.conj().T @ r).real
            lower = np.zeros((n, 3), bool)
            lower[:, 2] = th[:, 2] <= 1 / KAPPA_MAX
            upper = np.zeros((n, 3), bool)
            upper[:, 2] = th[:, 2] >= 1 / KAPPA_MIN
            free, dec = free_newton_unchecked(A, grad, lower.ravel(), upper.ravel())
            if dec <= 1e-6 * cost + 1e-14 * b2:
                break  # the full Gauss-Newton step would gain less than ftol = 1e-6
            system = damped_system_unchecked(A, grad, free)
        step = damped_solve_unchecked(system, lam)
        if step is None:
            lam *= 4.0
            continue
        th_new = project(th + step.reshape(n, 3))
        new = evaluate(th_new)
        if new[-1] < cost:
            th, cur, lam, system = th_new, new, max(lam / 3.0, 1e-9), None
        else:
            lam *= 4.0
            if lam > 1e10:
                break
    S = cur[0]
    g = np.linalg.lstsq(S, b, rcond=None)[0]  # exact projection at the optimum
    rel = float(np.linalg.norm(b - S @ g) ** 2 / b2)
    return th, g, rel


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
    max_sources = integer("max_sources", max_sources, minimum=1)
    fc = carrier("fc", fc)
    b = finite_array("b", b, ndim=1, dtype=complex)
    theta0 = _theta("theta0", theta0)
    p = check_element_positions("element_positions", element_positions, m=b.shape[0])
    tol, max_gain = positive("tol", tol), positive("max_gain", max_gain)
    min_separation = nonnegative("min_separation", min_separation)
    scale = float(np.sqrt(np.mean(np.abs(b) ** 2)))
    if scale == 0.0:
        raise ValueError("b: an all-zero spatial factor has no source to split")
    th, g, rel = _fit_sources(b, theta0, p, fc)
    while rel > tol and th.shape[0] < max_sources:
        S = spherical_steering(source_points(th), p, fc)
        u = scan_peak(b - S @ g, p, fc)
        start = np.vstack([th, [u[0], u[1], 1 / 30.0]])
        th2, g2, rel2 = _fit_sources(b, start, p, fc)
        du = np.linalg.norm(th2[:, None, :2] - th2[None, :, :2], axis=-1)
        distinct = np.min(du[np.triu_indices(len(th2), 1)]) >= min_separation
        if not (rel2 < 0.5 * rel and distinct and np.max(np.abs(g2)) <= max_gain * scale):
            break
        th, g, rel = th2, g2, rel2
    return th, g, rel


def _rows_to_roots(S, H, others=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gains and roots of the paths with steering ``S`` (M, n) in tensor ``H`` (M, Nf, Nt).

    ``S^+ H`` gives each path's (Nf, Nt) slice (less ``S^+`` of the ``others`` terms, a triple
    ``(A, F, T)`` of factor matrices, when given); its dominant rank-one term is the path's
    frequency and time factors, whose roots are eq. 13 polished to the periodogram peak.
    """
    M, nf, nt = H.shape
    Sp = np.linalg.pinv(S)
    X = (Sp @ H.reshape(M, nf * nt)).reshape(-1, nf, nt)
    if others is not None:
        A, F, T = others
        X = X - np.einsum("nl,sl,kl->nsk", Sp @ A, F, T)
    bf = np.empty((nf, S.shape[1]), complex)
    bt = np.empty((nt, S.shape[1]), complex)
    for j, Xj in enumerate(X):
        uu, ss, vh = np.linalg.svd(Xj, full_matrices=False)
        bf[:, j], bt[:, j] = uu[:, 0] * ss[0], vh[0]
    (_, bf, bt), alpha = normalize_factors((S, bf, bt))
    mu_f, beta_f = refine_roots(bf, vandermonde_roots(bf))
    mu_t, beta_t = refine_roots(bt, vandermonde_roots(bt))
    return alpha * beta_f * beta_t, mu_f, mu_t


def _point_source_path(theta, pos, fc) -> dict:
    """A candidate path's geometry from a fitted source ``(u_x, u_y, w)``."""
    q = source_points(theta)[0]
    kap = float(np.linalg.norm(q))
    near = bool(theta[2] > 1.001 / KAPPA_MAX)
    ang = angles_from_solution([[q[0], q[1], kap]], [theta[:2]])
    key = "nf" if near else "ff"
    return {
        "spatial": spherical_steering(q, pos, fc)[:, 0],
        "direction": ang[f"dir_{key}"][0],
        "phi": float(ang[f"phi_{key}"][0]),
        "psi": float(ang[f"psi_{key}"][0]),
        "near": near,
        "kappa_nf": kap,
        "delta": np.linalg.norm(q - pos, axis=1) - kap,
    }


def resolve_coherent(
    H,
    est: PathEstimates,
    array,
    srs,
    n_paths: int | None = None,
    *,
    max_sources: int = 3,
    tol: float = 1e-3,
    min_separation: float = 0.05,
    min_power: float = 0.01,
    max_coherence: float = 0.95,
) -> PathEstimates:
    """Separate coherent paths merged in the CPD components of ``est``: each component split into one
    to three point sources, one path per source.

    ``H`` is the tensor ``est`` was extracted from, ``array`` and ``srs`` its array and SRS
    configuration (as in :func:`~tunnelkit.extraction.extract_paths`), ``n_paths`` the number of
    paths to return (default ``len(est)``, at most the number of antennas); ``max_sources``,
    ``tol``, ``min_separation``, ``min_power`` and ``max_coherence`` are the split's thresholds. If
    fewer than ``n_paths`` candidates remain, the result is shorter and a ``RuntimeWarning`` says
    so. The algorithm, step by step: docs/internals/extraction-ml.md.
    """
    if not isinstance(est, PathEstimates):
        raise TypeError(f"est: expected PathEstimates, got {type(est).__name__}")
    H = check_tensor(H)
    M, nf, nt = H.shape
    pos = check_array(array, m=M)
    srs = check_srs(srs)
    fc, df, T0 = srs.fc, srs.tone_spacing, srs.symbol_period
    L = len(est) if n_paths is None else integer("n_paths", n_paths, minimum=1)
    if L > M:
        raise ValueError(f"n_paths: at most the {M} antennas can be separated, got {L}")
    max_sources = integer("max_sources", max_sources, minimum=1)
    positive("tol", tol)
    positive("min_separation", min_separation)
    nonnegative("min_power", min_power)
    max_coherence = probability("max_coherence", max_coherence)

    F = np.exp(1j * np.arange(nf)[:, None] * est.mu_f[None, :])
    T = np.exp(1j * np.arange(nt)[:, None] * est.mu_t[None, :])
    A = est.factors[0] * est.alpha[None, :]
    strong = np.abs(est.alpha) >= min_power * np.max(np.abs(est.alpha))

    # 1. candidates, component by component
    cands: list[dict] = []
    for l_ in range(len(est)):
        u = est.direction[l_]
        kap = est.kappa[l_] if np.isfinite(est.kappa[l_]) and est.kappa[l_] > 0 else 30.0
        th, g, rel = split_component(
            est.factors[0][:, l_],
            [u[0], u[1], float(np.clip(1 / kap, 1 / KAPPA_MAX, 1 / KAPPA_MIN))],
            pos,
            fc,
            max_sources=max_sources if strong[l_] else 1,
            tol=tol,
            min_separation=min_separation,
        )
        roots = {"mu_f": est.mu_f[l_], "mu_t": est.mu_t[l_]}
        if len(th) > 1:
            o = np.arange(len(est)) != l_
            geo = [_point_source_path(t, pos, fc) for t in th]
            S_l = np.stack([c["spatial"] for c in geo], 1)
            alpha, mu_f, mu_t = _rows_to_roots(S_l, H, (A[:, o], F[:, o], T[:, o]))
            cands += [
                {**c, "alpha": a, "mu_f": f, "mu_t": t}
                for c, a, f, t in zip(geo, alpha, mu_f, mu_t)
            ]
        else:  # one source: its fit is the single-source maximum-likelihood direction
            cands.append(
                {**_point_source_path(th[0], pos, fc), "alpha": est.alpha[l_] * g[0], **roots}
            )

    # 2. strongest first; the same path seen in two components is kept once
    def same(a, b):
        wrap = np.angle(np.exp(1j * np.array([a["mu_f"] - b["mu_f"], a["mu_t"] - b["mu_t"]])))
        close = np.linalg.norm(a["direction"][:2] - b["direction"][:2]) < min_separation
        return close and abs(wrap[0]) < 2 * np.pi / nf and abs(wrap[1]) < 2 * np.pi / nt

    kept: list[dict] = []
    for i in np.argsort([-abs(c["alpha"]) for c in cands]):
        if not any(same(cands[i], k) for k in kept):
            kept.append(cands[i])
        if len(kept) == L:
            break
    if len(kept) < L:
        warnings.warn(
            f"resolve_coherent: {len(kept)} distinct paths found, fewer than n_paths = {L}",
            RuntimeWarning,
            stacklevel=2,
        )

    # 3. all kept paths' gains and roots jointly from S^+ H, except where two steering vectors
    #    are too alike for the array to split the tensor between them (then step 1's stand)
    col = {key: np.array([k[key] for k in kept]) for key in kept[0]}
    S = col["spatial"].T
    alpha, mu_f, mu_t = _rows_to_roots(S, H)
    coh = np.abs(S.conj().T @ S) / np.outer(np.linalg.norm(S, axis=0), np.linalg.norm(S, axis=0))
    np.fill_diagonal(coh, 0.0)
    joint = coh.max(axis=1) < max_coherence
    for key, new in (("alpha", alpha), ("mu_f", mu_f), ("mu_t", mu_t)):
        col[key] = np.where(joint, new, col[key])
    d = -C / (2 * np.pi * df) * col["mu_f"]  # eq. 14
    v = C / (2 * np.pi * fc * T0) * col["mu_t"]  # eq. 15
    bs = col["spatial"].T
    bf = np.exp(1j * np.arange(nf)[:, None] * col["mu_f"][None, :])
    bt = np.exp(1j * np.arange(nt)[:, None] * col["mu_t"][None, :])
    rel = cp_rel_error(H, (bs * col["alpha"][None, :], bf, bt))
    ang = {  # per candidate the near/far choice is already made
        f"{key}_{side}": col[key if key != "dir" else "direction"]
        for key in ("dir", "phi", "psi")
        for side in ("nf", "ff")
    }
    ang["kappa_nf"] = col["kappa_nf"]
    return path_estimates(
        col["alpha"],
        d,
        v,
        ang,
        col["near"],
        col["delta"],
        col["mu_f"],
        col["mu_t"],
        (bs, bf, bt),
        rel,
        est.n_iter,
        est.converged,
    )
