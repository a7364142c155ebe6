"""The misspecified Cramér-Rao bound (MCRB) of the ML extraction on a tensor eq. 1 does not hold.

The ML route (:mod:`tunnelkit.extraction.ml`) fits ``mu(phi) = sum_l c_l a_l (x) f_l (x) t_l``
(eq. 1) by least squares. When the noiseless tensor ``H`` is not of that form (a ray-traced epoch:
second-order bounces, diffuse paths, the spatial-wideband term, paths part of the array sees),
the estimate converges, as the noise vanishes, not to the true parameters ``phi`` but to the
**pseudo-true** ones (Richmond & Horowitz 2015; Fortunati et al. 2017)

    phi_0 = argmin ||H - mu(phi)||^2,        bias = phi_0 - phi,

and with white circular noise of power ``sigma^2`` per sample its covariance about ``phi_0`` is
the sandwich ``MCRB = A^-1 B A^-1`` with (``r = H - mu(phi_0)``, ``J = d mu / d phi`` at ``phi_0``)

    A = (2 / sigma^2) (Re J^H J - Re <d^2 mu / d phi_i d phi_j, r>),     B = (2 / sigma^2) Re J^H J,

``<x, r> = sum conj(r) x``. ``B`` is the Fisher information of eq. 1 at ``phi_0`` (the CRLB is
``B^-1``); the second term of ``A`` is what the model error does to the curvature of the
likelihood. With ``H`` of eq. 1's form, ``r = 0``, ``phi_0 = phi`` and the MCRB is the CRLB.
:mod:`tunnelkit.design.mcrb` has the first-order form of the same bound for impairments given
as a model (one Gauss-Newton step for the bias, ``A`` without its second term), factorised for a
whole drive; here the pseudo-true point is found by the extraction's own fit and ``A`` is exact,
which a tensor as far from eq. 1 as a ray-traced one needs.

Parameters per path, in this order (:data:`PARAMS`): ``Re c, Im c, u_x, u_y, w, mu_f, mu_t``
(the ML route's parametrisation: direction cosines in the array plane, curvature ``1 / kappa``,
the Vandermonde frequencies; ``c`` the complex gain with ``sqrt(P_t)``). Every inner product
factorises over the three modes (array, tones, symbols): ``J``'s columns and the second
derivatives are rank-one tensors, so no ``(M Nf Nt) x 7L`` matrix is formed. The spatial phase's
second derivatives are the central differences (step :data:`FD_STEP`) of its analytic first
derivatives (:func:`tunnelkit.extraction.numerics.spatial_phase`).
"""

from __future__ import annotations

import warnings

import numpy as np

from .._physical import carrier
from .._validate import finite_array, integer, positive
from ..arrays import check_element_positions
from ..constants import C
from ..extraction.decomposition import check_tensor
from ..extraction.ml import MAX_ITER, Problem, fit_problem, pair_separation
from ..extraction.ml.given_start import check_start
from ..extraction.ml.model import W_MAX, project_feasible
from ..extraction.numerics import spatial_phase

__all__ = [
    "FD_STEP",
    "PARAMS",
    "misspecified_bound",
    "parameter_vector",
    "pseudo_true",
]

#: the real parameters of one path, in the order of every (7L,) vector and (7L, 7L) matrix here
PARAMS = ("re_c", "im_c", "u_x", "u_y", "w", "mu_f", "mu_t")
#: step of the central differences of the spatial phase's analytic first derivatives
FD_STEP = 1e-5

# per parameter: its spatial / frequency / time mode vector (index into the mode sets below)
_SP = np.array([0, 0, 1, 2, 3, 0, 0])
_FR = np.array([0, 0, 0, 0, 0, 1, 0])
_TI = np.array([0, 0, 0, 0, 0, 0, 1])


def _check(H, element_positions, fc):
    H = check_tensor(H)
    pos = check_element_positions("element_positions", element_positions, m=H.shape[0])
    return Problem(H, pos, carrier("fc", fc))


def pseudo_true(
    H,
    element_positions,
    fc: float,
    start,
    *,
    noise_power: float,
    tolerance: float = 0.1,
    newton_iter: int = 100,
) -> dict:
    """The pseudo-true paths of the noiseless tensor ``H`` (M, Nf, Nt): the extraction's own
    Levenberg-Marquardt fit (:func:`tunnelkit.extraction.ml.fit_problem`, no re-seeding: the
    local minimum of ``||H - mu||^2`` reached from ``start``, normally the true first-order
    paths ``(theta (L, 3), mu_f (L,), mu_t (L,))``), converged to ``0.01 tolerance`` standard
    deviations at the noise power ``noise_power`` (its stopping rule, 0.01 standard deviations,
    run at ``tolerance^2 noise_power``), then refined by damped Newton steps with the exact
    Hessian (at most ``newton_iter``): the Gauss-Newton iteration crawls where the model error
    flattens the cost along a direction its own curvature does not see.

    Returns ``theta``, ``mu_f``, ``mu_t``, ``c`` (the least-squares gains), ``residual`` the
    tensor ``H - mu(phi_0)``, ``residual_power`` ``||r||^2 / N``, ``converged`` (a strict
    minimum reached: ``A`` positive definite and the Newton decrement below tolerance; False
    where the cost has no minimum near ``start``, only an infimum, or ``newton_iter`` ran out),
    ``lm_iterations``, ``newton_iterations``, ``held``
    (L,) the paths whose curvature the feasible set holds at its edge (``w = 0``, a far-field
    wave, or ``W_MAX``: the minimum lies beyond it, so ``phi_0`` is the constrained one) and
    ``separation`` the smallest distance of two paths in standard deviations of their difference
    (:func:`~tunnelkit.extraction.ml.pair_separation`; a pair a few apart, or a cancelling pair
    of nearly equal atoms, is a degenerate ``phi_0``)."""
    prob = _check(H, element_positions, fc)
    sigma2 = positive("noise_power", noise_power)
    tol = positive("tolerance", tolerance)
    newton_iter = integer("newton_iter", newton_iter, minimum=0)
    L = np.atleast_2d(np.asarray(start[0])).shape[0] if isinstance(start, tuple) else -1
    if L < 1:
        raise ValueError("start: expected a tuple (theta (L, 3), mu_f (L,), mu_t (L,))")
    start = check_start(start, L)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its tests judge a noisy fit; this one is noiseless
        fit = fit_problem(
            prob, start, noise_power=tol * tol * sigma2, max_iter=MAX_ITER, n_reseed=0
        )
    # the fit reports mu wrapped to (-pi, pi]; keep the branch of the start
    mu_f = start[1] + np.angle(np.exp(1j * (fit.mu_f - start[1])))
    mu_t = start[2] + np.angle(np.exp(1j * (fit.mu_t - start[2])))
    p = parameter_vector(fit.theta, mu_f, mu_t, fit.alpha)
    p, n_newton, converged = _newton(prob, p, sigma2, tol, newton_iter)
    theta, mu_f, mu_t, c = p[:, 2:5], p[:, 5], p[:, 6], p[:, 0] + 1j * p[:, 1]
    r = prob.H - prob.model(theta, mu_f, mu_t, c)
    return {
        "theta": theta,
        "mu_f": mu_f,
        "mu_t": mu_t,
        "c": c,
        "residual": r,
        "residual_power": float(np.vdot(r, r).real / r.size),
        "converged": converged,
        "lm_iterations": fit.n_iter,
        "newton_iterations": n_newton,
        "held": _held(theta),
        "separation": pair_separation(prob, theta, mu_f, mu_t, sigma2),
    }


def _held(theta) -> np.ndarray:
    return (theta[:, 2] <= 0.0) | (theta[:, 2] >= W_MAX)


def _full_cost(prob: Problem, p) -> float:
    r = prob.H - prob.model(p[:, 2:5], p[:, 5], p[:, 6], p[:, 0] + 1j * p[:, 1])
    return float(np.vdot(r, r).real)


def _newton(prob: Problem, p, sigma2, tol, max_iter):
    """Damped Newton on ``||H - mu||^2`` over all 7L parameters with the exact Hessian ``A``
    (:func:`misspecified_bound`), from the Levenberg-Marquardt fit ``p`` (L, 7): where the model
    error makes ``A`` much smaller than its Gauss-Newton part ``B`` along some direction, the
    Gauss-Newton steps crawl and their decrement (measured with ``B``) stops them far from the
    minimum. Stops when the Newton decrement ``g^T A^-1 g`` is below ``1e-4 tol^2`` (the minimum
    within ``0.01 tol`` standard deviations), or when no damping lowers the cost."""
    cost = _full_cost(prob, p)
    lam, converged, it = 1e-3, False, 0
    L = p.shape[0]
    for it in range(1, max_iter + 1):  # noqa: B007
        held = _held(p[:, 2:5])
        b = misspecified_bound(
            prob.H,
            prob.pos,
            prob.k0 * C / (2 * np.pi),
            p[:, 2:5],
            p[:, 5],
            p[:, 6],
            p[:, 0] + 1j * p[:, 1],
            sigma2,
            held=held,
        )
        free = np.ones((L, 7), bool)
        free[held, 4] = False
        free = free.ravel()
        A, g = b["A"][np.ix_(free, free)], b["gradient"][free]
        d = np.abs(np.diag(A))
        d = np.where(d > 0, d, 1.0)
        if b["definite"]:
            dec = float(g @ np.linalg.solve(A, g))
            if dec < 1e-4 * tol * tol:
                converged = True
                break
        moved = False
        while lam <= 1e10:
            step = np.linalg.solve(A + lam * np.diag(d), g)
            q = p.ravel().copy()
            q[free] += step
            q = q.reshape(L, 7)
            q[:, 2:5] = project_feasible(q[:, 2:5])
            cq = _full_cost(prob, q)
            if cq < cost:
                p, cost, moved = q, cq, True
                lam = max(lam / 3.0, 1e-9)
                break
            lam *= 4.0
        if not moved:
            converged = bool(b["definite"])
            break
    return p, it, converged


def _modes(prob: Problem, theta, mu_f, mu_t):
    """Mode vectors: spatial (M, L, 10) ``[a, j psi_x a, j psi_y a, j psi_w a]`` then the six
    ``(j psi_pq - psi_p psi_q) a`` (p <= q), frequency (Nf, L, 3) ``[f, j s f, -s^2 f]``, time
    (Nt, L, 3) ``[t, j k t, -k^2 t]``."""
    psi, *d1 = spatial_phase(theta, prob.pos, prob.k0)
    d1 = np.stack(d1, axis=-1)  # (M, L, 3)
    d2 = np.empty((*d1.shape, 3))
    for q in range(3):
        step = np.zeros(3)
        step[q] = FD_STEP
        hi = np.stack(spatial_phase(theta + step, prob.pos, prob.k0)[1:], axis=-1)
        lo = np.stack(spatial_phase(theta - step, prob.pos, prob.k0)[1:], axis=-1)
        d2[..., q] = (hi - lo) / (2 * FD_STEP)
    d2 = 0.5 * (d2 + np.swapaxes(d2, -1, -2))
    a = np.exp(1j * psi)
    pairs = [(p, q) for p in range(3) for q in range(p, 3)]
    S = np.concatenate(
        [
            a[..., None],
            1j * d1 * a[..., None],
            np.stack([(1j * d2[..., p, q] - d1[..., p] * d1[..., q]) * a for p, q in pairs], -1),
        ],
        axis=-1,
    )
    s, k = prob.s, prob.kk  # (Nf, 1), (Nt, 1)
    f = np.exp(1j * s * mu_f[None, :])
    t = np.exp(1j * k * mu_t[None, :])
    F = np.stack([f, 1j * s * f, -(s**2) * f], axis=-1)
    T = np.stack([t, 1j * k * t, -(k**2) * t], axis=-1)
    return S, F, T, pairs


def _second(pairs) -> np.ndarray:
    """(7, 7, 3) mode indices (spatial, frequency, time) of ``d^2 X / d phi_i d phi_j`` for the
    non-gain pairs (``X`` the atom with unit gain)."""
    idx = np.zeros((7, 7, 3), int)
    for i in range(2, 7):
        for j in range(2, 7):
            if i <= 4 and j <= 4:
                p, q = sorted((i - 2, j - 2))
                idx[i, j] = (4 + pairs.index((p, q)), 0, 0)
            else:
                idx[i, j] = (_SP[i] + _SP[j], _FR[i] + _FR[j], _TI[i] + _TI[j])
    return idx


def misspecified_bound(
    H, element_positions, fc: float, theta, mu_f, mu_t, c, noise_power: float, *, held=None
) -> dict:
    """The sandwich bound (module docstring) of the eq. 1 fit to the noiseless tensor ``H``
    (M, Nf, Nt) at the pseudo-true paths ``theta`` (L, 3), ``mu_f``, ``mu_t``, ``c`` (L,)
    (:func:`pseudo_true`), white noise of power ``noise_power`` per sample.

    Returns ``A``, ``B`` (7L, 7L) (:data:`PARAMS` per path), ``mcrb`` ``A^-1 B A^-1``,
    ``crlb`` ``B^-1`` (eq. 1's bound at ``phi_0``), their standard deviations ``mcrb_sd`` and
    ``crlb_sd`` (L, 7), ``gradient`` ``(2 / sigma^2) Re J^H r`` (7L,) (zero at an exact
    pseudo-true point, in score units) and ``definite`` (``A`` positive definite: ``phi_0`` a
    strict local minimum; not so where two atoms with large opposite gains stand in for a term
    eq. 1 lacks: the cost then has no minimum, only an infimum as they merge), ``condition``
    the condition number of ``B`` (Jacobi-scaled). ``held`` (L,) bool: paths whose curvature ``w`` the estimator's
    feasible set holds at its edge (:func:`pseudo_true`); their ``w`` is a known constant of the
    bound (rows and columns dropped from ``A`` and ``B``; its standard deviations reported as 0)."""
    prob = _check(H, element_positions, fc)
    sigma2 = positive("noise_power", noise_power)
    theta = finite_array("theta", theta, ndim=2)
    L = theta.shape[0]
    if theta.shape[1] != 3:
        raise ValueError(f"theta: expected shape (L, 3), got {theta.shape}")
    mu_f = finite_array("mu_f", mu_f, shape=(L,))
    mu_t = finite_array("mu_t", mu_t, shape=(L,))
    c = finite_array("c", c, dtype=complex, shape=(L,))
    S, F, T, pairs = _modes(prob, theta, mu_f, mu_t)
    M, nf, nt = prob.H.shape
    # first derivatives: column (l, i) = coef_i S[:, l, SP_i] (x) F[:, l, FR_i] (x) T[:, l, TI_i]
    coef = np.ones((L, 7), complex)
    coef[:, 1] = 1j
    coef[:, 2:] = c[:, None]
    li = np.repeat(np.arange(L), 7)
    si, fi, ti = (idx[None, :].repeat(L, 0).ravel() for idx in (_SP, _FR, _TI))
    Sx, Fx, Tx = S[:, li, si], F[:, li, fi], T[:, li, ti]  # (., 7L)
    JJ = (Sx.conj().T @ Sx) * (Fx.conj().T @ Fx) * (Tx.conj().T @ Tx)
    cf = coef.ravel()
    JJ = np.conj(cf)[:, None] * cf[None, :] * JJ
    # contractions of conj(r) with the mode vectors: K[l, x, y, z]
    r = prob.H - prob.model(theta, mu_f, mu_t, c)
    rf = np.conj(r).transpose(0, 2, 1).reshape(M * nt, nf) @ F.reshape(nf, 3 * L)
    rft = np.einsum("mklv,klz->mlvz", rf.reshape(M, nt, L, 3), T)
    K = np.einsum("mlx,mlvz->lxvz", S, rft)
    grad = cf * K[li, si, fi, ti]  # sum conj(r) d mu / d phi_i
    grad = 2.0 / sigma2 * grad.real
    idx = _second(pairs)
    D2 = np.zeros((L, 7, 7), complex)
    Kij = K[:, idx[..., 0], idx[..., 1], idx[..., 2]]  # (L, 7, 7)
    D2[:, 2:, 2:] = c[:, None, None] * Kij[:, 2:, 2:]
    first = K[:, _SP, _FR, _TI]  # (L, 7): <X_i', r> with unit gain
    for g, cg in ((0, 1.0), (1, 1j)):
        D2[:, g, 2:] = cg * first[:, 2:]
        D2[:, 2:, g] = cg * first[:, 2:]
    R = np.zeros((7 * L, 7 * L))
    for ll in range(L):
        R[7 * ll : 7 * ll + 7, 7 * ll : 7 * ll + 7] = D2[ll].real
    held = np.zeros(L, bool) if held is None else np.asarray(held, bool)
    if held.shape != (L,):
        raise ValueError(f"held: expected shape ({L},), got {held.shape}")
    free = np.ones((L, 7), bool)
    free[held, 4] = False
    free = free.ravel()
    B = 2.0 / sigma2 * JJ.real
    A = 2.0 / sigma2 * (JJ.real - R)
    A = 0.5 * (A + A.T)
    B = 0.5 * (B + B.T)
    sub = np.ix_(free, free)
    dB = np.sqrt(np.diag(B)[free])
    Ai = np.zeros_like(A)
    Ai[sub] = np.linalg.inv(A[sub])
    mcrb = Ai @ B @ Ai
    crlb = np.zeros_like(B)
    crlb[sub] = np.linalg.inv(B[sub])
    grad = np.where(free, grad, 0.0)
    return {
        "A": A,
        "B": B,
        "mcrb": 0.5 * (mcrb + mcrb.T),
        "crlb": 0.5 * (crlb + crlb.T),
        "mcrb_sd": np.sqrt(np.abs(np.diag(mcrb))).reshape(L, 7),
        "crlb_sd": np.sqrt(np.abs(np.diag(crlb))).reshape(L, 7),
        "gradient": grad,
        "definite": bool(np.all(np.linalg.eigvalsh(A[sub]) > 0)),
        "condition": float(np.linalg.cond(B[sub] / np.outer(dB, dB))),
    }


def parameter_vector(theta, mu_f, mu_t, c) -> np.ndarray:
    """The (L, 7) parameters of :data:`PARAMS` from ``theta`` (L, 3), ``mu_f``, ``mu_t``, ``c``."""
    theta = finite_array("theta", theta, shape=(None, 3))
    L = theta.shape[0]
    c = finite_array("c", c, dtype=complex, shape=(L,))
    return np.column_stack(
        [
            c.real,
            c.imag,
            theta,
            finite_array("mu_f", mu_f, shape=(L,)),
            finite_array("mu_t", mu_t, shape=(L,)),
        ]
    )
