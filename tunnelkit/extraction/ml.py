"""Joint maximum-likelihood path extraction on the full eq. 1 model (ours, beyond Italiano et al. 2026).

Model
-----
With white circular Gaussian noise of power ``sigma^2`` per sample, the log-likelihood of the
tensor ``H`` (M x Nf x Nt) is, up to constants, ``-||H - sum_l c_l X_l||^2 / sigma^2`` with the
rank-one atoms of eq. 1

    X_l = a(u_l, w_l) o f(mu_f,l) o t(mu_t,l),
    a_m = exp(j k0 (||q_l - p_m|| - ||q_l||)),  f_s = exp(j s mu_f,l),  t_k = exp(j k mu_t,l),

``q_l = u_l / w_l`` the wave origin in the array's local frame (elements ``p_m`` in the plane
``z = 0``, ``p_0 = 0``), ``k0 = 2 pi fc / c`` and ``c_l`` the complex gain (``sqrt(P_t) alpha_l``).

Parametrisation
---------------
Per path five real numbers ``theta_l = (u_x, u_y, w, mu_f, mu_t)``: the direction cosines in the
array plane, the curvature ``w = 1 / kappa`` and the two Vandermonde frequencies
(``d = -c mu_f / (2 pi Df)``, ``v = c mu_t / (2 pi fc T0)``). Since ``p_z = 0``, the spatial phase
depends on ``u`` only through ``u . p = u_x p_x + u_y p_y``; with ``D = ||u - w p|| =
sqrt(1 - 2 w u.p + w^2 |p|^2)`` (> ``u_z`` > 0 in the front half-space) it reads, in a form that is
smooth through the far field ``w = 0``,

    psi_m = k0 (||q - p_m|| - ||q||) = k0 N / Q,   N = w |p|^2 - 2 u.p,   Q = 1 + D,

    d psi / d u_x = k0 p_x (-2 / Q + N w / (Q^2 D))         (likewise u_y with p_y),
    d psi / d w   = k0 (|p|^2 / Q - N (w |p|^2 - u.p) / (Q^2 D)).

The feasible set is ``|u| <= U_MAX`` (front half-space, away from end-fire) and
``0 <= w <= W_MAX``; every step is projected onto it, so no estimate leaves the front half-space,
and ``w = 0`` is an exact far-field wave (reported as ``kappa = NaN``).

Variable projection
-------------------
For fixed ``theta`` the gains are linear least squares: ``c = G^{-1} b`` with ``b_l = <X_l, H>``
and the Gram ``G = (A^H A) * (F^H F) * (T^H T)`` (Hadamard product of the three modes' Grams,
because inner products of rank-one tensors factorise). The concentrated cost is
``phi(theta) = ||H||^2 - b^H G^{-1} b = ||r||^2`` (``r = P_perp h``, ``P_perp`` the projector off
the span of the atoms). Its Gauss-Newton model uses Kaufman's simplification of the
Golub-Pereyra Jacobian, ``J = -P_perp D`` with ``D_i = c_l dX_l / d theta_i`` (one rank-one term
per parameter). Then

    J^H J = D^H D - (D^H B) G^{-1} (B^H D),      J^H r = -D^H r = -conj(c_l) (<dX_i, H> - (B^H dX_i)^H c),

every inner product again a Hadamard product of mode Grams, and ``<dX_i, H>`` a contraction of
``H`` with mode vectors: ``H``, stored once as an (M Nt) x Nf matrix, is multiplied by the
``2L`` frequency vectors ``conj(f_l)``, ``conj(s f_l)`` (one BLAS product with a long inner
dimension, ``M Nf Nt 2L`` products), then each path meets its time and spatial vectors (small).
One iteration therefore costs one pass over ``H`` and a ``5L x 5L`` solve; no
``(M Nf Nt) x 5L`` matrix is ever formed. Levenberg-Marquardt: ``(Re J^H J + lambda diag(Re J^H J)) delta = Re(D^H r)``, a step
is kept only if the cost drops, ``lambda`` shrinks by 3 on success and grows by 4 on failure.

Stopping rule
-------------
The Newton decrement ``g^T (Re J^H J)^{-1} g`` (``g = Re D^H r``) is the cost decrease a full
Gauss-Newton step promises; in units of ``sigma^2`` it is the squared distance to the optimum
measured in standard deviations of the estimate (the Fisher information of the concentrated
model is ``2 Re(J^H J) / sigma^2``). The iteration stops when it is below ``STEP_TOL``
(0.01 sigma in every direction together), or when ``lambda`` exceeds ``1e10`` (no descent left
at working precision: the cost is resolved to about ``1e-5 sigma^2``).

Noise floor and basin test
--------------------------
The noise power is estimated without the model from the time-mode unfolding ``H_(3)`` (Nt x
M Nf): the signal occupies at most ``L`` of its ``Nt`` dimensions, so the ``Nt - L`` smallest
eigenvalues of ``H_(3) H_(3)^H`` hold noise only, ``sigma^2 ~ sum / ((Nt - L)(M Nf - L))`` (the
space mode is used when ``L >= Nt``); or it is given by the caller. The estimate runs low by up
to about ``L sqrt(Nt / (M Nf)) / (Nt - L)`` (1 % for five paths) when paths share a Doppler bin
(the ``L`` largest eigenvalues then include noise maxima); half of that is added to the
threshold below. At the maximum-likelihood
estimate of the right model, ``2 ||r||^2 / sigma^2`` is chi-square with ``2N - 5L`` degrees of
freedom (``N = M Nf Nt``, the gains included), so ``rho = ||r||^2 / ((N - 2.5 L) sigma^2)`` is
``1 +- sqrt(1 / N)``. A fit with ``rho`` above ``1 + RHO_Z sqrt(1 / N + 1 / N_sigma)`` (plus
the allowance) has not found the right basin
(a path missed, merged or counted twice) and is re-seeded, SAGE-like, alternating two moves,
each kept only if the likelihood rises:

- *birth and death*: one path more, sought in the pure residual ``r``, all ``L + 1`` fitted
  jointly, the least significant one out and the ``L`` fitted again;
- *replace the weakest*: the path whose removal raises the cost least (``|c_l|^2 /
  [G^{-1}]_ll``) is dropped and sought again in ``H`` less the other paths (the residual plus
  its own contribution).

A search takes the dominant rank-one term of its tensor (power iterations), the periodogram peaks
of its frequency and time vectors for ``mu_f`` and ``mu_t``, a far-field beam scan of its spatial
vector for ``u``, a 1-D scan of ``w`` and a local single-source fit.

Each path's significance ``|c_l|^2 / ([G^{-1}]_ll sigma^2)`` is its log-likelihood ratio; a path
below ``MIN_SIGNIFICANCE`` is indistinguishable from noise: it is returned with ``valid = False``
and a :class:`MLDetectionWarning` says how many of the ``n_paths`` were found. If the fit cannot
improve on its start it keeps the start and warns (:class:`MLConvergenceWarning`); so does a
fit whose residual still fails the basin test after the re-seedings.

References: Fleury et al., "Channel parameter estimation in mobile radio environments using the
SAGE algorithm", IEEE JSAC 17(3), 1999; Richter, "Estimation of radio channel parameters: models
and algorithms (RIMAX)", PhD thesis, TU Ilmenau, 2005; Golub & Pereyra, SIAM J. Numer. Anal.
10(2), 1973; Kaufman, BIT 15, 1975.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.linalg.blas import zherk

from .._validate import integer, positive
from ..arrays import check_element_positions
from ..constants import C
from .decomposition import check_rank, check_tensor
from .estimates import PathEstimates, path_estimates
from .paper import angles_from_solution, refine_roots

__all__ = [
    "MLConvergenceWarning",
    "MLDetectionWarning",
    "MLFit",
    "fit_ml",
    "ml_paths",
    "noise_floor",
    "spatial_phase",
    "start_from_estimates",
]

#: feasible set: direction cosines within U_MAX of the array plane's unit disc, curvature <= W_MAX
U_MAX = 0.999
W_MAX = 2.0  # kappa >= 0.5 m
#: curvature below which a path is reported far-field (kappa = NaN), as in the coherent split
W_FAR = 1e-3
STEP_TOL = 1e-4  # Newton decrement in units of sigma^2 (0.01 standard deviations)
RHO_Z = 6.0  # basin test: sigmas of the chi-square statistic
MIN_SIGNIFICANCE = 25.0  # log-likelihood ratio of a path against noise


class MLConvergenceWarning(RuntimeWarning):
    """The maximum-likelihood stage could not improve on its start (the start is returned), or
    its residual stays above the noise floor after the re-seedings (basin test failed)."""


class MLDetectionWarning(RuntimeWarning):
    """Fewer paths than ``n_paths`` stand above the noise (the rest have ``valid = False``)."""


@dataclass(frozen=True)
class MLFit:
    """The joint fit: ``theta`` (L, 3) = ``(u_x, u_y, w = 1/kappa)``, ``mu_f``, ``mu_t`` (rad),
    ``alpha`` the gains, ``cost = ||r||^2``, ``noise_power`` (estimated or given), ``rho`` the
    residual over the noise floor (1 at the right optimum), ``rho_max`` the basin test's
    threshold, ``significance`` (L,) each path's log-likelihood ratio against noise,
    ``n_iter`` Levenberg-Marquardt iterations in all, ``n_reseed`` kept re-seedings,
    ``converged`` the stopping rule was met."""

    theta: np.ndarray
    mu_f: np.ndarray
    mu_t: np.ndarray
    alpha: np.ndarray
    cost: float
    noise_power: float
    rho: float
    rho_max: float
    significance: np.ndarray
    n_iter: int
    n_reseed: int
    converged: bool
    history: list = field(default_factory=list, repr=False)


def spatial_phase(theta, element_positions, k0: float):
    """Spatial phase ``psi`` (M, L) and its derivatives (M, L) for ``u_x, u_y, w``.

    ``theta`` (L, 3) = ``(u_x, u_y, w)``; the elements lie in ``z = 0`` (see the module text)."""
    th = np.atleast_2d(np.asarray(theta, float))
    p = np.asarray(element_positions, float)
    p2 = np.sum(p**2, axis=1)[:, None]
    up = p[:, :2] @ th[:, :2].T
    w = th[None, :, 2]
    D = np.sqrt(np.maximum(1.0 - 2.0 * w * up + w * w * p2, 1e-300))
    Q = 1.0 + D
    N = w * p2 - 2.0 * up
    psi = k0 * N / Q
    common = k0 * (-2.0 / Q + N * w / (Q * Q * D))
    dx = common * p[:, 0:1]
    dy = common * p[:, 1:2]
    dw = k0 * (p2 / Q - N * (w * p2 - up) / (Q * Q * D))
    return psi, dx, dy, dw


def _project(theta: np.ndarray) -> np.ndarray:
    """Onto the feasible set: ``|u| <= U_MAX``, ``0 <= w <= W_MAX`` (front half-space)."""
    th = theta.copy()
    r = np.hypot(th[:, 0], th[:, 1])
    big = r > U_MAX
    th[big, :2] *= (U_MAX / r[big])[:, None]
    th[:, 2] = np.clip(th[:, 2], 0.0, W_MAX)
    return th


class _Problem:
    """The tensor, the array and the evaluation of the concentrated cost and its GN model."""

    def __init__(self, H, pos, fc):
        self.H = H
        self.M, self.nf, self.nt = H.shape
        self.Hp = np.ascontiguousarray(H.transpose(0, 2, 1)).reshape(self.M * self.nt, self.nf)
        self.pos = pos
        self.k0 = 2 * np.pi * fc / C
        self.s = np.arange(self.nf, dtype=float)[:, None]
        self.kk = np.arange(self.nt, dtype=float)[:, None]
        self.h2 = float(np.vdot(H, H).real)
        self.N = H.size

    def evaluate(self, theta, mu_f, mu_t, *, derivatives: bool = True) -> dict:
        L = theta.shape[0]
        psi, dx, dy, dw = spatial_phase(theta, self.pos, self.k0)
        a = np.exp(1j * psi)
        F = np.exp(1j * self.s * mu_f[None, :])
        T = np.exp(1j * self.kk * mu_t[None, :])
        if not derivatives:
            b = np.einsum("ml,ml->l", a.conj(), self._contract(T, F))
            G = (a.conj().T @ a) * (F.conj().T @ F) * (T.conj().T @ T)
            c, cost = _solve_gains(G, b, self.h2)
            return {"c": c, "cost": cost, "G": G, "b": b}
        sF = 1j * self.s * F
        kT = 1j * self.kk * T
        W_ft, W_sft, W_fkt = self._contract(T, F, sF, kT)
        ax, ay, aw = 1j * dx * a, 1j * dy * a, 1j * dw * a
        # atoms: L model atoms, then per path (u_x, u_y, w, mu_f, mu_t)
        X = np.concatenate([a, np.stack([ax, ay, aw, a, a], axis=2).reshape(self.M, 5 * L)], 1)
        Y = np.concatenate([F, np.stack([F, F, F, sF, F], axis=2).reshape(self.nf, 5 * L)], 1)
        Z = np.concatenate([T, np.stack([T, T, T, T, kT], axis=2).reshape(self.nt, 5 * L)], 1)
        P = np.concatenate(
            [
                np.sum(a.conj() * W_ft, 0),
                np.stack(
                    [
                        np.sum(ax.conj() * W_ft, 0),
                        np.sum(ay.conj() * W_ft, 0),
                        np.sum(aw.conj() * W_ft, 0),
                        np.sum(a.conj() * W_sft, 0),
                        np.sum(a.conj() * W_fkt, 0),
                    ],
                    axis=1,
                ).ravel(),
            ]
        )
        Gram = (X.conj().T @ X) * (Y.conj().T @ Y) * (Z.conj().T @ Z)
        G, b = Gram[:L, :L], P[:L]
        c, cost = _solve_gains(G, b, self.h2)
        cd = np.repeat(c, 5)  # the gain of each derivative atom's path
        Dr = cd.conj() * (P[L:] - Gram[L:, :L] @ c)  # <D_i, r>
        DB = cd.conj()[:, None] * Gram[L:, :L]
        DD = np.outer(cd.conj(), cd) * Gram[L:, L:]
        JJ = DD - DB @ _solve(G, DB.conj().T)
        return {"c": c, "cost": cost, "G": G, "b": b, "A": JJ.real, "g": Dr.real, "a": a}

    def _contract(self, T, F, sF=None, kT=None):
        """``W[m, l] = sum_{s,k} H[m, s, k] conj(F[s, l] T[k, l])`` (M, L); with ``sF`` and ``kT``
        also the same with ``sF`` for ``F`` and with ``kT`` for ``T``. ``H``, stored once as
        (M Nt) x Nf, meets the frequency vectors first (one BLAS product with a long inner
        dimension), then each path its time vectors (small)."""
        L = T.shape[1]
        if kT is None:
            Hf = (self.Hp @ F.conj()).reshape(self.M, self.nt, L)
            return np.einsum("mkl,kl->ml", Hf, T.conj())
        Hf = (self.Hp @ np.concatenate([F, sF], axis=1).conj()).reshape(self.M, self.nt, 2 * L)
        W_ft = np.einsum("mkl,kl->ml", Hf[:, :, :L], T.conj())
        W_sft = np.einsum("mkl,kl->ml", Hf[:, :, L:], T.conj())
        W_fkt = np.einsum("mkl,kl->ml", Hf[:, :, :L], kT.conj())
        return W_ft, W_sft, W_fkt

    def model(self, theta, mu_f, mu_t, c) -> np.ndarray:
        a = np.exp(1j * spatial_phase(theta, self.pos, self.k0)[0])
        F = np.exp(1j * self.s * mu_f[None, :])
        T = np.exp(1j * self.kk * mu_t[None, :])
        return np.einsum("ml,sl,kl->msk", a * c[None, :], F, T, optimize=True)


def _solve(G, B):
    try:
        return np.linalg.solve(G, B)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(G, B, rcond=None)[0]


def _solve_gains(G, b, h2):
    c = _solve(G, b)
    return c, max(h2 - float(np.real(np.vdot(b, c))), 0.0)


def noise_floor(H, n_paths: int) -> float:
    """Noise power per sample estimated without the model (see the module text)."""
    H = check_tensor(H)
    M, nf, nt = H.shape
    L = integer("n_paths", n_paths, minimum=0)
    if L < nt:
        # time-mode Gram by a rank-k update (zherk): conj(H_(3) H_(3)^H), same eigenvalues
        G = zherk(1.0, H.reshape(M * nf, nt).T, trans=0)
        ev = np.linalg.eigvalsh(G, UPLO="U")[: nt - L]
        return float(max(np.sum(ev), 0.0) / ((nt - L) * (M * nf - L)))
    if L < M:
        U = H.reshape(M, nf * nt)
        ev = np.linalg.eigvalsh(U @ U.conj().T)[: M - L]
        return float(max(np.sum(ev), 0.0) / ((M - L) * (nf * nt - L)))
    raise ValueError(f"n_paths: {L} leaves no noise-only subspace to estimate the noise from")


def _lm(prob: _Problem, theta, mu_f, mu_t, sigma2, max_iter: int):
    """Levenberg-Marquardt on the concentrated cost; returns the best point and its evaluation."""
    L = theta.shape[0]
    ev = prob.evaluate(theta, mu_f, mu_t)
    lam, it, converged = 1e-3, 0, False
    for it in range(1, max_iter + 1):  # noqa: B007
        lower = np.zeros((L, 5), bool)
        lower[:, 2] = theta[:, 2] <= 0.0
        upper = np.zeros((L, 5), bool)
        upper[:, 2] = theta[:, 2] >= W_MAX
        # Newton decrement: the cost decrease a full Gauss-Newton step promises, in sigma^2
        free, dec = _free_newton(ev["A"], ev["g"], lower.ravel(), upper.ravel())
        if dec < STEP_TOL * sigma2:
            converged = True
            break
        step = _damped_step(ev["A"], ev["g"], free, lam)
        if step is None:
            lam *= 4.0
            continue
        st = step.reshape(L, 5)
        th_new = _project(theta + st[:, :3])
        mf_new, mt_new = mu_f + st[:, 3], mu_t + st[:, 4]
        ev_new = prob.evaluate(th_new, mf_new, mt_new)
        if ev_new["cost"] < ev["cost"]:
            theta, mu_f, mu_t, ev = th_new, mf_new, mt_new, ev_new
            lam = max(lam / 3.0, 1e-9)
        else:
            lam *= 4.0
            if lam > 1e10:
                converged = True  # no descent direction left at working precision
                break
    return theta, mu_f, mu_t, ev, it, converged


def _birth_death(prob: _Problem, theta, mu_f, mu_t, ev, sigma2, max_iter):
    """One path more, sought in the pure residual; all ``L + 1`` fitted jointly; the least
    significant one out and the ``L`` fitted again (a path missed while another was counted
    twice, or two paths merged, leave a structured residual that this move picks up)."""
    r = prob.H - prob.model(theta, mu_f, mu_t, ev["c"])
    th_n, mf_n, mt_n = _search_path(r, prob)
    big = _lm(
        prob,
        np.vstack([theta, th_n]),
        np.append(mu_f, mf_n),
        np.append(mu_t, mt_n),
        sigma2,
        max_iter,
    )
    keep = np.arange(theta.shape[0] + 1) != int(np.argmin(_significance(big[3], sigma2)))
    res = _lm(prob, big[0][keep], big[1][keep], big[2][keep], sigma2, max_iter)
    return res, big[4] + res[4]


def _free_newton(A, g, lower, upper):
    """Coordinates free to move and the Newton decrement ``g^T A^{-1} g`` over them.

    A coordinate at its lower (upper) bound whose Gauss-Newton step points down (up) is held:
    the projection would undo its step. ``A`` is Jacobi-scaled before the solve (the
    parameters differ by orders of magnitude)."""
    free = np.ones(g.size, bool)
    for _ in range(3):
        sc = 1.0 / np.sqrt(np.maximum(np.diag(A)[free], 1e-300))
        As = sc[:, None] * A[np.ix_(free, free)] * sc[None, :]
        gs = sc * g[free]
        newton = np.zeros(g.size)
        newton[free] = sc * np.linalg.lstsq(As, gs, rcond=1e-12)[0]
        out = (lower & (newton < 0)) | (upper & (newton > 0))
        if not out.any():
            break
        free &= ~out
    return free, float(g[free] @ newton[free])


def _damped_step(A, g, free, lam):
    """Levenberg-Marquardt step on the ``free`` coordinates (Marquardt's diagonal scaling)."""
    sc = 1.0 / np.sqrt(np.maximum(np.diag(A)[free], 1e-300))
    As = sc[:, None] * A[np.ix_(free, free)] * sc[None, :]
    try:
        sub = sc * np.linalg.solve(As + lam * np.eye(As.shape[0]), sc * g[free])
    except np.linalg.LinAlgError:
        return None
    step = np.zeros(g.size)
    step[free] = sub
    return step


def _significance(ev, sigma2) -> np.ndarray:
    """Per path: the cost increase if it were removed (gains re-projected), over ``sigma2``."""
    Gi = np.linalg.pinv(ev["G"])
    return np.abs(ev["c"]) ** 2 / np.maximum(np.real(np.diag(Gi)), 1e-300) / sigma2


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


def _spatial_search(x, prob: _Problem, n_grid: int = 61):
    """Direction and curvature of one wave from a spatial vector ``x`` (M,): far-field beam scan,
    then a 1-D scan in ``w``, then a local single-source fit."""
    from .coherent import _scan_peak, fit_sources

    p = prob.pos
    fc = prob.k0 * C / (2 * np.pi)
    u = _scan_peak(x, p, fc, n_grid=n_grid)
    u = u * min(1.0, 0.98 / max(np.linalg.norm(u), 1e-12))
    ws = np.concatenate([[0.0], 1.0 / np.geomspace(0.6, 300.0, 40)])
    th = np.column_stack([np.tile(u, (ws.size, 1)), ws])
    a = np.exp(1j * spatial_phase(th, p, prob.k0)[0])
    w0 = ws[int(np.argmax(np.abs(a.conj().T @ x)))]
    th_fit, _, _ = fit_sources(x, [u[0], u[1], min(max(w0, 1e-3 + 1e-9), 0.999)], p, fc)
    th_fit = _project(th_fit)
    # the curvature bound of the single-source fit (1 m .. 1 km) is narrower than ours
    return th_fit[0]


def _search_path(R, prob: _Problem):
    """One path ``(theta (3,), mu_f, mu_t)`` from the strongest rank-one term of ``R``."""
    x, y, z = _power_rank_one(R)
    mf0 = float(np.angle(np.sum(y[1:] * y[:-1].conj())))
    mt0 = float(np.angle(np.sum(z[1:] * z[:-1].conj())))
    mf, _ = refine_roots(y[:, None] / y[0], np.array([mf0]), n_steps=6)
    mt, _ = refine_roots(z[:, None] / z[0], np.array([mt0]), n_steps=6)
    th = _spatial_search(x, prob)
    return th, float(mf[0]), float(mt[0])


def start_from_estimates(est: PathEstimates) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(theta (L, 3), mu_f, mu_t)`` from any route's estimates, projected onto the feasible set
    (far-field or non-finite curvature -> ``w = 0``; directions behind the array plane are
    mirrored into the front half-space before the projection)."""
    u = np.asarray(est.direction, float)
    kap = np.asarray(est.kappa, float)
    w = np.where(np.isfinite(kap) & (kap > 0), 1.0 / np.where(kap > 0, kap, 1.0), 0.0)
    th = np.column_stack([np.nan_to_num(u[:, 0]), np.nan_to_num(u[:, 1]), w])
    return (
        _project(th),
        np.nan_to_num(est.mu_f).astype(float),
        np.nan_to_num(est.mu_t).astype(float),
    )


def _check_start(start, L):
    th, mf, mt = (np.asarray(v, float) for v in start)
    th = np.atleast_2d(th)
    if th.shape != (L, 3) or mf.shape != (L,) or mt.shape != (L,):
        raise ValueError(
            f"start: expected theta ({L}, 3), mu_f ({L},), mu_t ({L},); got "
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
    return _project(th), mf, mt


def fit_ml(
    H,
    start,
    element_positions,
    fc: float,
    *,
    noise_power: float | None = None,
    max_iter: int = 60,
    n_reseed: int | None = None,
) -> MLFit:
    """Joint maximum-likelihood fit of ``L`` paths started at ``start = (theta, mu_f, mu_t)``.

    ``theta`` (L, 3) is ``(u_x, u_y, 1/kappa)`` per path (local frame, ``|u| < 1``, ``w >= 0``);
    ``mu_f``, ``mu_t`` (L,) the Vandermonde frequencies. ``noise_power`` per sample (default:
    estimated, :func:`noise_floor`). ``n_reseed`` bounds the SAGE-like re-seedings (default
    ``L``; 0 = local fit only). See the module text for the algorithm.
    """
    H = check_tensor(H)
    M = H.shape[0]
    pos = check_element_positions("element_positions", element_positions, m=M)
    fc = positive("fc", fc)
    L = np.atleast_2d(np.asarray(start[0])).shape[0]
    theta, mu_f, mu_t = _check_start(start, L)
    max_iter = integer("max_iter", max_iter, minimum=1)
    n_reseed = L if n_reseed is None else integer("n_reseed", n_reseed, minimum=0)
    prob = _Problem(H, pos, fc)
    bias = 0.0
    if noise_power is None:
        sigma2 = noise_floor(H, L)
        nt, rest = (H.shape[2], M * H.shape[1]) if L < H.shape[2] else (M, H.shape[1] * H.shape[2])
        n_sigma = (nt - L) * (rest - L)
        # the L largest eigenvalues also take the largest noise eigenvalues of the directions
        # the signal barely occupies (paths sharing a Doppler bin): up to ~ L sqrt(nt/rest)/(nt-L)
        bias = 0.5 * L * np.sqrt(nt / rest) / (nt - L)
    else:
        sigma2 = positive("noise_power", noise_power)
        n_sigma = np.inf
    sigma2 = max(sigma2, 1e-300 * max(prob.h2, 1e-300))
    dof = prob.N - 2.5 * L
    rho_max = 1.0 + RHO_Z * np.sqrt(1.0 / prob.N + 1.0 / n_sigma) + bias

    ev0 = prob.evaluate(theta, mu_f, mu_t, derivatives=False)
    cost0 = ev0["cost"]
    best = _lm(prob, theta, mu_f, mu_t, sigma2, max_iter)
    n_it, kept = best[4], 0
    history = [best[3]["cost"] / (dof * sigma2)]
    tried: set = set()
    for attempt in range(n_reseed):
        theta, mu_f, mu_t, ev = best[:4]
        if ev["cost"] / (dof * sigma2) <= rho_max:
            break
        if attempt % 2 == 0:  # birth and death: a path from the residual, then the weakest out
            cand, its = _birth_death(prob, theta, mu_f, mu_t, ev, sigma2, max_iter)
        else:  # the weakest path re-sought in the residual plus its own contribution
            sig = _significance(ev, sigma2)
            order = [int(i) for i in np.argsort(sig) if int(i) not in tried]
            if not order:
                continue
            worst = order[0]
            tried.add(worst)
            keep = np.arange(L) != worst
            R = H - prob.model(theta[keep], mu_f[keep], mu_t[keep], ev["c"][keep])
            th_n, mf_n, mt_n = _search_path(R, prob)
            th2, mf2, mt2 = theta.copy(), mu_f.copy(), mu_t.copy()
            th2[worst], mf2[worst], mt2[worst] = th_n, mf_n, mt_n
            cand = _lm(prob, th2, mf2, mt2, sigma2, max_iter)
            its = cand[4]
        n_it += its
        history.append(cand[3]["cost"] / (dof * sigma2))
        if cand[3]["cost"] < ev["cost"]:
            best, kept = cand, kept + 1
            tried = set()
    theta, mu_f, mu_t, ev, _, converged = best
    if not ev["cost"] < cost0 and not np.isclose(ev["cost"], cost0, rtol=1e-12, atol=0):
        warnings.warn(
            "fit_ml: the fit did not improve the likelihood of its start; the start is kept",
            MLConvergenceWarning,
            stacklevel=2,
        )
        theta, mu_f, mu_t, ev = (*_check_start(start, L), ev0)
    if not np.all(np.isfinite(ev["c"])):
        raise FloatingPointError("fit_ml: non-finite gains (degenerate paths)")
    rho = float(ev["cost"] / (dof * sigma2))
    if rho > rho_max:
        warnings.warn(
            f"fit_ml: the residual stays {rho:.4f} times the noise floor (test: {rho_max:.4f}) "
            "after the re-seedings: a path may be missed or merged, or n_paths is too small",
            MLConvergenceWarning,
            stacklevel=2,
        )
    return MLFit(
        theta,
        np.angle(np.exp(1j * mu_f)),
        np.angle(np.exp(1j * mu_t)),
        ev["c"],
        float(ev["cost"]),
        float(sigma2),
        rho,
        float(rho_max),
        _significance(ev, sigma2),
        int(n_it),
        int(kept),
        bool(converged),
        history,
    )


def estimates_from_fit(
    fit: MLFit,
    element_positions,
    fc: float,
    subcarrier_spacing: float,
    symbol_period: float,
    nf: int,
    nt: int,
    rel_error: float,
) -> PathEstimates:
    """:class:`PathEstimates` of a fit (see :func:`ml_paths` for what each field means)."""
    th = fit.theta
    w = th[:, 2]
    near = w > W_FAR
    uz = np.sqrt(np.clip(1.0 - th[:, 0] ** 2 - th[:, 1] ** 2, 0.0, None))
    kap = np.where(w > 0, 1.0 / np.where(w > 0, w, 1.0), np.inf)
    ff = angles_from_solution(np.zeros((len(w), 3)), th[:, :2])  # angles of u (eq. 19 convention)
    ang = {
        f"{key}_{side}": ff[f"{key}_ff"] for key in ("dir", "phi", "psi") for side in ("nf", "ff")
    }
    ang["dir_nf"] = ang["dir_ff"] = np.column_stack([th[:, 0], th[:, 1], uz])
    ang["kappa_nf"] = kap
    k0 = 2 * np.pi * fc / C
    psi = spatial_phase(th, element_positions, k0)[0]
    A = np.exp(1j * psi)
    F = np.exp(1j * np.arange(nf)[:, None] * fit.mu_f[None, :])
    T = np.exp(1j * np.arange(nt)[:, None] * fit.mu_t[None, :])
    d = -C / (2 * np.pi * subcarrier_spacing) * fit.mu_f  # eq. 14
    v = C / (2 * np.pi * fc * symbol_period) * fit.mu_t  # eq. 15
    est = path_estimates(
        fit.alpha,
        d,
        v,
        ang,
        near,
        (psi / k0).T,
        fit.mu_f,
        fit.mu_t,
        (A, F, T),
        rel_error,
        fit.n_iter,
        fit.converged,
    )
    signif = fit.significance[np.argsort(d)]
    return replace(
        est, valid=est.valid & (signif >= MIN_SIGNIFICANCE), fit=fit, significance=signif
    )


def ml_paths(
    H,
    n_paths: int,
    element_positions,
    fc: float,
    subcarrier_spacing: float,
    symbol_period: float,
    *,
    start: PathEstimates | tuple | None = None,
    noise_power: float | None = None,
    max_iter: int = 60,
    n_reseed: int | None = None,
) -> PathEstimates:
    """Joint maximum-likelihood extraction (module text); the default of ``extract_paths``.

    ``start``: a :class:`PathEstimates` (any route; projected onto the front half-space), a tuple
    ``(theta (L, 3), mu_f, mu_t)`` (checked: ``ValueError`` outside the front half-space), or
    ``None`` — the CPD, the paper's roots and the coherent split (:func:`resolve_coherent`).

    The returned :class:`PathEstimates` reads like the other routes': ``alpha`` the gains
    (``sqrt(P_t) alpha_l``), ``d``, ``v``, ``direction`` (unit, local frame), ``kappa`` the
    distance of the wave origin (``1/w``; NaN where ``w <= W_FAR``, i.e. beyond 1 km: far field),
    ``near_field = kappa`` finite, ``phi``/``psi`` the local angles, ``kappa_nf`` = ``1/w``
    (``inf`` at ``w = 0``), ``delta`` (L, M) the model's path-length offsets
    ``||q - p_m|| - ||q||``, ``factors`` the model's unit-gain mode vectors ``(a, f, t)``,
    ``rel_error`` = ``||r||^2 / ||H||^2``, ``valid`` = ``d >= 0`` (Algorithm 1: with a
    negative clock bias a near vehicle can have ``d < 0``) and significant against the noise
    (``significance >= MIN_SIGNIFICANCE``), ``significance`` each path's log-likelihood ratio,
    ``fit`` the :class:`MLFit` (noise power, basin test).
    """
    H = check_tensor(H)
    M, nf, nt = H.shape
    L = check_rank(H.shape, n_paths)
    pos = check_element_positions("element_positions", element_positions, m=M)
    fc = positive("fc", fc)
    df = positive("subcarrier_spacing", subcarrier_spacing)
    T0 = positive("symbol_period", symbol_period)
    if L >= M:
        raise ValueError(
            f"n_paths: at most {M - 1} paths can be told apart by {M} antennas, got {L}"
        )
    if start is None:
        from . import _paper_route
        from .coherent import resolve_coherent

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            est0 = _paper_route(H, L, pos, fc, df, T0, refine="column")
            est0 = resolve_coherent(H, est0, pos, fc, df, T0, L)
        theta, mu_f, mu_t = start_from_estimates(est0)
        if len(est0) < L:  # the split found fewer distinct paths: seed the rest from the residual
            theta, mu_f, mu_t = _complete(H, pos, fc, theta, mu_f, mu_t, L)
        start = (theta, mu_f, mu_t)
    elif isinstance(start, PathEstimates):
        if len(start) != L:
            raise ValueError(f"start: has {len(start)} paths, n_paths = {L}")
        start = start_from_estimates(start)
    else:
        start = _check_start(start, L)
    fit = fit_ml(H, start, pos, fc, noise_power=noise_power, max_iter=max_iter, n_reseed=n_reseed)
    n_sig = int(np.sum(fit.significance >= MIN_SIGNIFICANCE))
    if n_sig < L:
        warnings.warn(
            f"ml_paths: {n_sig} of n_paths = {L} paths stand above the noise; the others are "
            "returned with valid = False",
            MLDetectionWarning,
            stacklevel=2,
        )
    return estimates_from_fit(
        fit, pos, fc, df, T0, nf, nt, fit.cost / max(float(np.vdot(H, H).real), 1e-300)
    )


def _complete(H, pos, fc, theta, mu_f, mu_t, L):
    """Add paths found in the residual until there are ``L`` (successive cancellation)."""
    prob = _Problem(H, pos, fc)
    while theta.shape[0] < L:
        if theta.shape[0]:
            ev = prob.evaluate(theta, mu_f, mu_t, derivatives=False)
            R = H - prob.model(theta, mu_f, mu_t, ev["c"])
        else:
            R = H
        th, mf, mt = _search_path(R, prob)
        theta = np.vstack([theta, th])
        mu_f, mu_t = np.append(mu_f, mf), np.append(mu_t, mt)
    return theta, mu_f, mu_t
