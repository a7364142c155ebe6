"""The model of the maximum-likelihood stage: the concentrated cost of eq. 1 and its Gauss-Newton
model (:class:`Problem`), the feasible set (:func:`project_feasible`) and the model-free noise
floor (:func:`noise_floor`). The parametrisation and the variable projection are described in
docs/internals/extraction-ml.md."""

from __future__ import annotations

import numpy as np
from scipy.linalg.blas import zherk

from ..._physical import carrier
from ..._validate import boolean, finite_array, integer
from ...arrays import check_element_positions
from ...constants import C
from ..decomposition import check_tensor
from ..numerics import solve_unchecked, spatial_phase_unchecked

__all__ = ["U_MAX", "W_FAR", "W_MAX", "Problem", "noise_floor", "project_feasible"]

#: feasible set: direction cosines within U_MAX of the array plane's unit disc (u_z >= 0.0045,
#: 0.26 deg from end-fire: a ceiling image seen from a tilted array can lie at u_z = 0.011),
#: curvature <= W_MAX
U_MAX = 0.99999
W_MAX = 2.0  # kappa >= 0.5 m
#: curvature below which a path is reported far-field (kappa = NaN), as in the coherent split
W_FAR = 1e-3


def _check_theta(theta) -> np.ndarray:
    th = finite_array("theta", theta)
    if th.ndim != 2 or th.shape[1] != 3:
        raise ValueError(f"theta: expected shape (L, 3), got {th.shape}")
    return th


def project_feasible(theta) -> np.ndarray:
    """``theta`` (L, 3) = ``(u_x, u_y, w)`` projected onto the feasible set ``|u| <= U_MAX``,
    ``0 <= w <= W_MAX`` (front half-space, away from end-fire); a copy."""
    th = _check_theta(theta).copy()
    r = np.hypot(th[:, 0], th[:, 1])
    big = r > U_MAX
    th[big, :2] *= (U_MAX / r[big])[:, None]
    th[:, 2] = np.clip(th[:, 2], 0.0, W_MAX)
    return th


def check_paths(theta, mu_f, mu_t) -> None:
    """``ValueError`` unless ``theta`` is (L, 3) and ``mu_f``, ``mu_t`` are (L,)."""
    L = _check_theta(theta).shape[0]
    if np.shape(mu_f) != (L,) or np.shape(mu_t) != (L,):
        raise ValueError(
            f"mu_f, mu_t: expected shape ({L},) each, got {np.shape(mu_f)}, {np.shape(mu_t)}"
        )
    finite_array("mu_f", mu_f)
    finite_array("mu_t", mu_t)


class Problem:
    """The tensor ``H`` (M, Nf, Nt), the array (local positions (M, 3)) and the carrier ``fc``:
    the evaluation of the concentrated cost and its Gauss-Newton model
    (docs/internals/extraction-ml.md).

    Attributes used by the fit: ``H``, ``pos``, ``k0 = 2 pi fc / c``, ``h2 = ||H||^2``, ``N``
    the number of samples; :meth:`evaluate`, :meth:`model` and :meth:`noise_floor`."""

    def __init__(self, H, element_positions, fc: float):
        H = check_tensor(H)
        self.H = H
        self.M, self.nf, self.nt = H.shape
        # H as (M Nt) x Nf, conjugated: the contraction's BLAS product (:meth:`_contract`)
        self.Hpc = np.conj(H.transpose(0, 2, 1)).reshape(self.M * self.nt, self.nf)
        self.pos = check_element_positions("element_positions", element_positions, m=self.M)
        self.k0 = 2 * np.pi * carrier("fc", fc) / C
        self.s = np.arange(self.nf, dtype=float)[:, None]
        self.kk = np.arange(self.nt, dtype=float)[:, None]
        self.h2 = float(np.vdot(H, H).real)
        self.N = H.size

    def evaluate(self, theta, mu_f, mu_t, *, derivatives: bool = True) -> dict:
        """The gains ``c``, the cost ``||r||^2``, the Gram ``G`` and ``b = <X_l, H>`` at
        ``theta`` (L, 3), ``mu_f``, ``mu_t`` (L,); with ``derivatives`` also the Gauss-Newton
        matrix ``A = Re J^H J`` (5L, 5L), the descent direction ``g = Re D^H r`` (5L,) and the
        steering vectors ``a`` (M, L)."""
        check_paths(theta, mu_f, mu_t)
        derivatives = boolean("derivatives", derivatives)
        L = theta.shape[0]
        psi, dx, dy, dw = spatial_phase_unchecked(theta, self.pos, self.k0)
        a = unit_phasors(psi)
        F = unit_phasors(self.s * mu_f[None, :])
        T = unit_phasors(self.kk * mu_t[None, :])
        if not derivatives:
            b = np.einsum("ml,ml->l", a.conj(), self._contract(T, F))
            G = (a.conj().T @ a) * (F.conj().T @ F) * (T.conj().T @ T)
            c, cost = self._gains(G, b)
            return {"c": c, "cost": cost, "G": G, "b": b}
        sF = 1j * self.s * F
        kT = 1j * self.kk * T
        W_ft, W_sft, W_fkt = self._contract(T, F, sF, kT)
        ax, ay, aw = 1j * dx * a, 1j * dy * a, 1j * dw * a
        # atoms: L model atoms, then per path (u_x, u_y, w, mu_f, mu_t)
        X = np.concatenate([a, np.stack([ax, ay, aw, a, a], axis=2).reshape(self.M, 5 * L)], 1)
        Y = np.concatenate([F, np.stack([F, F, F, sF, F], axis=2).reshape(self.nf, 5 * L)], 1)
        Z = np.concatenate([T, np.stack([T, T, T, T, kT], axis=2).reshape(self.nt, 5 * L)], 1)
        Gram = (X.conj().T @ X) * (Y.conj().T @ Y) * (Z.conj().T @ Z)
        ac = a.conj()
        P = np.concatenate(
            [
                np.sum(ac * W_ft, 0),
                np.stack(
                    [
                        np.sum(ax.conj() * W_ft, 0),
                        np.sum(ay.conj() * W_ft, 0),
                        np.sum(aw.conj() * W_ft, 0),
                        np.sum(ac * W_sft, 0),
                        np.sum(ac * W_fkt, 0),
                    ],
                    axis=1,
                ).ravel(),
            ]
        )
        G, b = Gram[:L, :L], P[:L]
        c, cost = self._gains(G, b)
        cd = np.repeat(c, 5)  # the gain of each derivative atom's path
        Dr = cd.conj() * (P[L:] - Gram[L:, :L] @ c)  # <D_i, r>
        DB = cd.conj()[:, None] * Gram[L:, :L]
        DD = np.outer(cd.conj(), cd) * Gram[L:, L:]
        JJ = DD - DB @ solve_unchecked(G, DB.conj().T)
        return {"c": c, "cost": cost, "G": G, "b": b, "A": JJ.real, "g": Dr.real, "a": a}

    def _contract(self, T, F, sF=None, kT=None):
        """``W[m, l] = sum_{s,k} H[m, s, k] conj(F[s, l] T[k, l])`` (M, L); with ``sF`` and ``kT``
        also the same with ``sF`` for ``F`` and with ``kT`` for ``T``. ``H``, stored once
        conjugated as (M Nt) x Nf, meets the frequency vectors first (one BLAS product with a
        long inner dimension, ``conj(W)`` exactly), then each path its time vectors (small)."""
        L = T.shape[1]
        if kT is None:
            Hf = (self.Hpc @ F).reshape(self.M, self.nt, L)
            return np.einsum("mkl,kl->ml", Hf, T).conj()
        Hf = (self.Hpc @ np.concatenate([F, sF], axis=1)).reshape(self.M, self.nt, 2 * L)
        W_ft = np.einsum("mkl,kl->ml", Hf[:, :, :L], T).conj()
        W_sft = np.einsum("mkl,kl->ml", Hf[:, :, L:], T).conj()
        W_fkt = np.einsum("mkl,kl->ml", Hf[:, :, :L], kT).conj()
        return W_ft, W_sft, W_fkt

    def model(self, theta, mu_f, mu_t, c) -> np.ndarray:
        """The model tensor ``sum_l c_l X_l`` (M, Nf, Nt) of the paths ``theta``, ``mu_f``,
        ``mu_t`` with gains ``c`` (L,)."""
        check_paths(theta, mu_f, mu_t)
        c = finite_array("c", c, shape=(len(theta),), dtype=complex)
        a = np.exp(1j * spatial_phase_unchecked(theta, self.pos, self.k0)[0])
        F = np.exp(1j * self.s * mu_f[None, :])
        T = np.exp(1j * self.kk * mu_t[None, :])
        return np.einsum("ml,sl,kl->msk", a * c[None, :], F, T, optimize=True)

    def _gains(self, G, b):
        """The gains ``c = G^-1 b`` and the concentrated cost ``||H||^2 - Re b^H c``."""
        return _solve_gains(G, b, self.h2)

    def noise_floor(self, n_paths: int) -> float:
        """:func:`noise_floor` of this problem's tensor."""
        return _noise_floor(self.H, integer("n_paths", n_paths, minimum=0))


def unit_phasors(phase) -> np.ndarray:
    """``exp(1j * phase)`` for a real array ``phase``, from its cosine and sine (what the complex
    exponential of a purely imaginary argument computes, bit for bit, without its exponential)."""
    out = np.empty(phase.shape, complex)
    parts = out.view(float).reshape(*phase.shape, 2)
    np.cos(phase, out=parts[..., 0])
    np.sin(phase, out=parts[..., 1])
    return out


def _solve_gains(G, b, h2):
    c = solve_unchecked(G, b)
    return c, max(h2 - float(np.real(np.vdot(b, c))), 0.0)


def noise_floor(H, n_paths: int) -> float:
    """Noise power per sample estimated without the model (docs/internals/extraction-ml.md)."""
    return _noise_floor(check_tensor(H), integer("n_paths", n_paths, minimum=0))


def _noise_floor(H, L: int) -> float:
    """:func:`noise_floor` on checked arguments."""
    M, nf, nt = H.shape
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
