"""Eq. 1 with each path's amplitude varying across the aperture: :class:`ApertureProblem`.

On the ray-traced channel part of a first-order path's field reaches only some elements (a road
marking seen by 53 of 100, a ceiling path cut by the ridge between two facets:
``docs/raytraced-channel.md``), which eq. 1's one gain per path cannot describe. This model gives
path ``l`` a real amplitude profile over the array,

    X_l[m, s, k] = exp(j psi_l(m)) h_l(m) exp(j s mu_f,l) exp(j k mu_t,l),
    h_l(m) = 1 + sum_j beta_lj w_j(m),

with ``w_j`` the centred polynomials of the element's in-plane coordinates up to ``order``
(:func:`taper_basis`: ``x, y`` for order 1, and ``x^2, x y, y^2`` for order 2, coordinates scaled
to [-1, 1]), ``beta_lj`` real and ``h_l >= 0`` on the array. The profile is real on purpose: a
complex linear profile ``1 + j k0 du x`` is, to first order, the path's phase front turned by
``du``, so a complex taper would take the direction away from the geometry and the angles would
no longer be identifiable; an amplitude cannot turn a phase front.

The gains stay linear and are projected out as in eq. 1's fit (docs/internals/extraction-ml.md,
Kaufman's Gauss-Newton model); the ``beta`` are ``K`` more nonlinear parameters per path, with
derivative atoms ``exp(j psi_l) w_j`` (no ``h``), and every atom still factorises into (element) x
(tone) x (symbol). With ``order = 0`` the problem is eq.
1's :class:`~tunnelkit.extraction.ml.model.Problem`, number for number (tested).
:meth:`ApertureProblem.fit` is Levenberg-Marquardt over all ``(5 + K) L`` parameters from a
start (normally eq. 1's fit with ``beta = 0``). Measured in ``docs/results/traced-models.md``
(:mod:`tunnelkit.studies.nuisance`).
"""

from __future__ import annotations

import numpy as np

from ..._validate import boolean, finite_array, integer, positive
from ..ml import Problem, project_feasible
from ..numerics import solve_unchecked, spatial_phase_unchecked

__all__ = ["MAX_ORDER", "ApertureProblem", "taper_basis"]

#: the highest polynomial order of the amplitude profile
MAX_ORDER = 2


def taper_basis(element_positions, order: int) -> np.ndarray:
    """The profile's basis ``w`` (M, K) over the elements' in-plane coordinates ``x, y`` (the
    array's local frame), centred on the array and scaled by its half-aperture: ``x, y``
    (``order`` 1) and also ``x^2, x y, y^2`` each less its mean (``order`` 2); (M, 0) for 0.

    >>> taper_basis([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0], [0.01, 0.01, 0]], 1).tolist()
    [[-1.0, -1.0], [1.0, -1.0], [-1.0, 1.0], [1.0, 1.0]]
    """
    pos = finite_array("element_positions", element_positions)
    if pos.ndim != 2 or pos.shape[1] != 3 or pos.shape[0] < 2:
        raise ValueError(f"element_positions: expected shape (M >= 2, 3), got {pos.shape}")
    order = integer("order", order, minimum=0, maximum=MAX_ORDER)
    x, y = pos[:, 0] - pos[:, 0].mean(), pos[:, 1] - pos[:, 1].mean()
    half = max(np.ptp(x), np.ptp(y)) / 2
    x, y = x / half, y / half
    cols = [x, y] if order >= 1 else []
    if order >= 2:
        cols += [x * x - np.mean(x * x), x * y - np.mean(x * y), y * y - np.mean(y * y)]
    return np.stack(cols, 1) if cols else np.zeros((len(x), 0))


class ApertureProblem(Problem):
    """The tensor ``H`` (M, Nf, Nt), the array (local positions (M, 3)), the carrier ``fc`` and
    the profile's ``order`` (0 to :data:`MAX_ORDER`): eq. 1 with a real amplitude profile per
    path (module docstring). ``K`` profile parameters per path, ``basis`` (M, K)."""

    def __init__(self, H, element_positions, fc: float, order: int = 1):
        super().__init__(H, element_positions, fc)
        self.basis = taper_basis(self.pos, order)
        self.order = int(order)
        self.K = self.basis.shape[1]

    def _check(self, theta, mu_f, mu_t, beta=None) -> tuple:
        """The paths' parameters as arrays of matching shapes (``beta`` None: zero)."""
        theta = finite_array("theta", theta, shape=(None, 3))
        L = theta.shape[0]
        if L < 1:
            raise ValueError("theta: expected at least one path, got shape (0, 3)")
        mu_f = finite_array("mu_f", mu_f, shape=(L,))
        mu_t = finite_array("mu_t", mu_t, shape=(L,))
        beta = (
            np.zeros((L, self.K)) if beta is None else finite_array("beta", beta, shape=(L, self.K))
        )
        return theta, mu_f, mu_t, beta

    def profile(self, beta) -> np.ndarray:
        """``h`` (M, L) of the profile parameters ``beta`` (L, K)."""
        return self._profile(finite_array("beta", beta, shape=(None, self.K)))

    def _profile(self, beta: np.ndarray) -> np.ndarray:
        return 1.0 + self.basis @ beta.T

    def evaluate_profile(self, theta, mu_f, mu_t, beta, *, derivatives: bool = True) -> dict:
        """As :meth:`Problem.evaluate` with the profile ``beta`` (L, K): the gains ``c``, the
        cost; with ``derivatives`` the Gauss-Newton matrix ``A`` ((5 + K) L square) and the
        descent direction ``g`` over ``(u_x, u_y, w, mu_f, mu_t, beta_1..K)`` per path."""
        if beta is None:
            raise TypeError(f"beta: expected the profile parameters (L, {self.K}), got None")
        theta, mu_f, mu_t, beta = self._check(theta, mu_f, mu_t, beta)
        return self._evaluate(theta, mu_f, mu_t, beta, boolean("derivatives", derivatives))

    def _evaluate(self, theta, mu_f, mu_t, beta, derivatives: bool = True) -> dict:
        L, K = theta.shape[0], self.K
        n = 5 + K
        psi, dx, dy, dw = spatial_phase_unchecked(theta, self.pos, self.k0)
        a0 = np.exp(1j * psi)
        a = a0 * self._profile(beta)
        F = np.exp(1j * self.s * mu_f[None, :])
        T = np.exp(1j * self.kk * mu_t[None, :])
        if not derivatives:
            b = np.einsum("ml,ml->l", a.conj(), self._contract(T, F))
            G = (a.conj().T @ a) * (F.conj().T @ F) * (T.conj().T @ T)
            c, cost = self._gains(G, b)
            return {"c": c, "cost": cost}
        sF, kT = 1j * self.s * F, 1j * self.kk * T
        W_ft, W_sft, W_fkt = self._contract(T, F, sF, kT)
        # per path: (u_x, u_y, w, mu_f, mu_t, beta_1..K), each an element x tone x symbol atom
        space = [1j * dx * a, 1j * dy * a, 1j * dw * a, a, a]
        space += [a0 * self.basis[:, j : j + 1] for j in range(K)]
        tone = [F, F, F, sF, F] + [F] * K
        symbol = [T, T, T, T, kT] + [T] * K
        data = [W_ft, W_ft, W_ft, W_sft, W_fkt] + [W_ft] * K
        X = np.concatenate([a, np.stack(space, 2).reshape(self.M, n * L)], 1)
        Y = np.concatenate([F, np.stack(tone, 2).reshape(self.nf, n * L)], 1)
        Z = np.concatenate([T, np.stack(symbol, 2).reshape(self.nt, n * L)], 1)
        Gram = (X.conj().T @ X) * (Y.conj().T @ Y) * (Z.conj().T @ Z)
        Pd = np.stack([np.sum(u.conj() * w, 0) for u, w in zip(space, data, strict=True)], 1)
        b = np.sum(a.conj() * W_ft, 0)
        G = Gram[:L, :L]
        c, cost = self._gains(G, b)
        cd = np.repeat(c, n)  # the gain of each derivative atom's path
        Dr = cd.conj() * (Pd.ravel() - Gram[L:, :L] @ c)
        DB = cd.conj()[:, None] * Gram[L:, :L]
        DD = np.outer(cd.conj(), cd) * Gram[L:, L:]
        JJ = DD - DB @ solve_unchecked(G, DB.conj().T)
        return {"c": c, "cost": cost, "A": JJ.real, "g": Dr.real}

    def _feasible(self, p: np.ndarray) -> np.ndarray:
        """Parameters ``p`` (L, 5 + K) projected onto the feasible set: eq. 1's for ``theta``
        (:func:`~tunnelkit.extraction.ml.project_feasible`), and each profile scaled down until
        ``h >= 0`` on every element (a copy)."""
        p = p.copy()
        p[:, :3] = project_feasible(p[:, :3])
        if self.K:
            low = np.min(self._profile(p[:, 5:]), axis=0)
            p[:, 5:] *= (1.0 / (1.0 - np.minimum(low, 0.0)))[:, None]
        return p

    def fit(self, theta, mu_f, mu_t, noise_power: float, *, beta=None, max_iter: int = 200):
        """Levenberg-Marquardt from ``theta`` (L, 3), ``mu_f``, ``mu_t`` (L,) and ``beta`` (L, K;
        zero by default) until the Newton decrement is below ``1e-4 noise_power`` (0.01
        standard deviations) or ``max_iter``. Returns ``theta``, ``mu_f``, ``mu_t``, ``beta``,
        ``c``, ``cost``, ``iterations``, ``converged``."""
        theta, mu_f, mu_t, beta = self._check(theta, mu_f, mu_t, beta)
        L = theta.shape[0]
        sigma2 = positive("noise_power", noise_power)
        max_iter = integer("max_iter", max_iter, minimum=1, maximum=1000)
        p = self._feasible(np.column_stack([theta, mu_f, mu_t, beta]))

        def ev_of(q, derivatives=True):
            return self._evaluate(q[:, :3], q[:, 3], q[:, 4], q[:, 5:], derivatives)

        ev, lam, converged, it = ev_of(p), 1e-3, False, 0
        for it in range(1, max_iter + 1):  # noqa: B007
            A, g = ev["A"], ev["g"]
            d = np.maximum(np.abs(np.diag(A)), 1e-300)
            newton = np.linalg.lstsq(A, g, rcond=1e-12)[0]
            if float(g @ newton) < 1e-4 * sigma2:
                converged = True
                break
            while lam <= 1e10:
                q = self._feasible(p + np.linalg.solve(A + lam * np.diag(d), g).reshape(L, -1))
                ev_q = ev_of(q)
                if ev_q["cost"] < ev["cost"]:
                    p, ev, lam = q, ev_q, max(lam / 3.0, 1e-9)
                    break
                lam *= 4.0
            else:
                converged = True  # no descent direction left at working precision
                break
        return {
            "theta": p[:, :3],
            "mu_f": p[:, 3],
            "mu_t": p[:, 4],
            "beta": p[:, 5:],
            "c": ev["c"],
            "cost": float(ev["cost"]),
            "iterations": it,
            "converged": converged,
        }
