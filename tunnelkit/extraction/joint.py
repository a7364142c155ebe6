"""The joint maximum-likelihood refinement of the CPD's roots with free spatial factors (ours,
variable projection): :func:`refine_joint`, the ``refine="joint"`` step of
:func:`~tunnelkit.extraction.paper.paper_route`, loaded when that step runs.

How it works: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

import numpy as np

from .._checks import numeric_array
from .._validate import integer
from .numerics import contract_unchecked

__all__ = ["refine_joint"]


def refine_joint(H, mu_f, mu_t, n_steps: int = 6):
    """Joint ML refinement of all roots with free spatial factors (variable projection).

    Model ``H[m, s, k] = sum_l A[m, l] exp(j mu_f,l s) exp(j mu_t,l k)``: for fixed roots the
    spatial factors ``A`` are linear least squares; the roots take damped Gauss-Newton steps with
    the Kaufman Jacobian ``a_l o P_perp dw_l/dmu`` (``w_l = f_l kron t_l``). All Gram matrices
    factorise over the two Vandermonde modes, so one step costs three contractions of ``H``. This
    is the maximum-likelihood estimate of the model a CPD fits plus the Vandermonde structure; it
    approaches ``crlb_paths(spatial="free")`` where per-column estimates (eq. 13) do not.
    Returns ``(mu_f, mu_t, A)``.
    """
    H = numeric_array("H", H, (3,))
    for name, m in (("mu_f", mu_f), ("mu_t", mu_t)):
        if numeric_array(name, m, (1,)).shape != np.shape(mu_f):
            raise ValueError(f"{name}: mu_f and mu_t need one root per path each")
    n_steps = integer("n_steps", n_steps, minimum=0, maximum=1000)
    M, nf, nt = H.shape
    s = np.arange(nf)[:, None]
    k = np.arange(nt)[:, None]
    mu = np.concatenate([np.asarray(mu_f, float), np.asarray(mu_t, float)])
    L = mu.size // 2
    x2 = float(np.vdot(H, H).real)
    Hm = H.reshape(M * nf, nt)

    def fit(m):
        F, T = np.exp(1j * s * m[None, :L]), np.exp(1j * k * m[None, L:])
        G = (F.conj().T @ F) * (T.conj().T @ T)  # W^H W
        HT = (Hm @ T.conj()).reshape(M, nf, L)  # reused by the next gradient
        B = np.einsum("msl,sl->ml", HT, F.conj())  # X conj(W)
        A = np.linalg.solve(G, B.T).T
        return F, T, G, A, HT, x2 - float(np.sum(np.real(A.conj() * B)))

    F, T, G, A, HT, cost = fit(mu)
    max_step = np.concatenate([np.full(L, np.pi / (2 * nf)), np.full(L, np.pi / (2 * nt))])
    lam = 1e-6
    for _ in range(n_steps):
        Fs, Tk = s * F, k * T
        FF, TT = F.conj().T @ F, T.conj().T @ T
        WD = np.concatenate([1j * (F.conj().T @ Fs) * TT, 1j * FF * (T.conj().T @ Tk)], axis=1)
        XD = -1j * np.concatenate(
            [np.einsum("msl,sl->ml", HT, Fs.conj()), contract_unchecked(H, F.conj(), Tk.conj())],
            axis=1,
        )
        RD = XD - A @ WD.conj()  # R conj(D)
        Aa = np.concatenate([A, A], axis=1)
        grad = np.real(np.sum(Aa.conj() * RD, axis=0))
        Dff = (Fs.conj().T @ Fs) * TT
        Dft = (Fs.conj().T @ F) * (T.conj().T @ Tk)
        Dtt = FF * (Tk.conj().T @ Tk)
        DD = np.block([[Dff, Dft], [Dft.conj().T, Dtt]])
        PP = DD - WD.conj().T @ np.linalg.solve(G, WD)
        JtJ = np.real((Aa.conj().T @ Aa) * PP)
        improved = done = False
        for _ in range(10):
            step = np.linalg.solve(JtJ + lam * np.diag(np.diag(JtJ)), grad)
            step = np.clip(step, -max_step, max_step)  # trust region: a quarter of a bin
            out = fit(mu + step)
            if out[-1] <= cost:
                mu = mu + step
                F, T, G, A, HT, new = out
                # converged when the step is far below the noise-limited precision of the roots
                done = np.max(np.abs(step)) < 1e-9 or cost - new <= 1e-12 * cost
                cost, lam, improved = new, max(lam / 10, 1e-12), True
                break
            lam *= 10
        if not improved or done:
            break
    return mu[:L], mu[L:], A
