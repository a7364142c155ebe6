"""The maximum-likelihood model with the spatial-wideband term: :class:`WidebandProblem`.

Each element gets its own delay across the band (:func:`tunnelkit.channel.channel_tensor` with
``spatial_wideband=True``), with the same five parameters per path and the same gains as eq. 1.
:class:`WidebandProblem` is a :class:`~.model.Problem`: :func:`~.fitting.fit_problem` runs on it
unchanged, and :func:`~.paths.ml_paths` with ``wideband=True`` refines its eq. 1 fit on it.

How it works: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

import numpy as np

from ..._physical import carrier, tone_step
from ..._validate import boolean, finite_array
from ..numerics import solve_unchecked, spatial_phase_unchecked
from .model import Problem, check_paths

__all__ = ["WidebandProblem"]


class WidebandProblem(Problem):
    """:class:`~.model.Problem` of the model with the spatial-wideband term (docs/internals):
    the tensor ``H`` (M, Nf, Nt), the array (local positions (M, 3)), the band centre ``fc`` and
    the tone spacing ``tone_spacing`` [Hz]."""

    def __init__(self, H, element_positions, fc: float, tone_spacing: float):
        super().__init__(H, element_positions, fc)
        rho = tone_step("tone_spacing", tone_spacing) / carrier("fc", fc)
        self.tone_spacing = float(tone_spacing)
        #: the per-tone scale of the spatial phase, g_s = f_s / fc
        self.g = 1.0 - rho * (np.arange(self.nf) - 0.5 * (self.nf - 1))
        self.Hm = self.H.reshape(self.M * self.nf, self.nt)

    def _atoms(self, theta, mu_f):
        """``B`` (M, Nf, L) the (element x tone) part of each atom, and the spatial phase and
        its derivatives (M, L) each."""
        psi, dx, dy, dw = spatial_phase_unchecked(theta, self.pos, self.k0)
        ph = psi[:, None, :] * self.g[None, :, None] + self.s[None, :, :] * mu_f[None, None, :]
        return np.exp(1j * ph), (psi, dx, dy, dw)

    def evaluate(self, theta, mu_f, mu_t, *, derivatives: bool = True) -> dict:
        """As :meth:`Problem.evaluate`, on the wideband atoms."""
        check_paths(theta, mu_f, mu_t)
        derivatives = boolean("derivatives", derivatives)
        L = theta.shape[0]
        MF = self.M * self.nf
        B, (psi, dx, dy, dw) = self._atoms(theta, mu_f)
        T = np.exp(1j * self.kk * mu_t[None, :])
        Bm = B.reshape(MF, L)
        if not derivatives:
            Ht = self.Hm @ T.conj()  # (M Nf, L)
            b = np.sum(Bm.conj() * Ht, axis=0)
            G = (Bm.conj().T @ Bm) * (T.conj().T @ T)
            c, cost = self._gains(G, b)
            return {"c": c, "cost": cost, "G": G, "b": b}
        kT = 1j * self.kk * T
        Ht2 = self.Hm @ np.concatenate([T, kT], axis=1).conj()  # (M Nf, 2L)
        Ht, Htk = Ht2[:, :L], Ht2[:, L:]
        g = self.g[None, :, None]
        Bx = (1j * dx[:, None, :] * g * B).reshape(MF, L)
        By = (1j * dy[:, None, :] * g * B).reshape(MF, L)
        Bw = (1j * dw[:, None, :] * g * B).reshape(MF, L)
        Bf = (1j * self.s[None, :, :] * B).reshape(MF, L)
        # atoms: L model atoms, then per path (u_x, u_y, w, mu_f, mu_t)
        X = np.concatenate([Bm, np.stack([Bx, By, Bw, Bf, Bm], axis=2).reshape(MF, 5 * L)], 1)
        Z = np.concatenate([T, np.stack([T, T, T, T, kT], axis=2).reshape(self.nt, 5 * L)], 1)
        ip = lambda U, V: np.sum(U.conj() * V, axis=0)  # noqa: E731
        P = np.concatenate(
            [
                ip(Bm, Ht),
                np.stack(
                    [ip(Bx, Ht), ip(By, Ht), ip(Bw, Ht), ip(Bf, Ht), ip(Bm, Htk)], axis=1
                ).ravel(),
            ]
        )
        Gram = (X.conj().T @ X) * (Z.conj().T @ Z)
        G, b = Gram[:L, :L], P[:L]
        c, cost = self._gains(G, b)
        cd = np.repeat(c, 5)
        Dr = cd.conj() * (P[L:] - Gram[L:, :L] @ c)
        DB = cd.conj()[:, None] * Gram[L:, :L]
        DD = np.outer(cd.conj(), cd) * Gram[L:, L:]
        JJ = DD - DB @ solve_unchecked(G, DB.conj().T)
        return {
            "c": c,
            "cost": cost,
            "G": G,
            "b": b,
            "A": JJ.real,
            "g": Dr.real,
            "a": np.exp(1j * psi),
        }

    def model(self, theta, mu_f, mu_t, c) -> np.ndarray:
        """The model tensor ``sum_l c_l X_l`` (M, Nf, Nt) on the wideband atoms."""
        check_paths(theta, mu_f, mu_t)
        c = finite_array("c", c, shape=(len(theta),), dtype=complex)
        B, _ = self._atoms(theta, mu_f)
        T = np.exp(1j * self.kk * mu_t[None, :])
        return np.einsum("msl,kl->msk", B * c[None, None, :], T, optimize=True)
