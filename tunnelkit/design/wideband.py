"""The spatial-wideband term in the misspecified bound of eq. 1: its score ``J^H delta`` on the
modes of :class:`~tunnelkit.design.mcrb.EtaModes`, a series in each tone's offset from the band
centre truncated at :data:`WB_TOL` (loaded where the impairments hold the term and the
estimator does not model it).

How it works: docs/internals/design.md.
"""

from __future__ import annotations

import numpy as np

from .._physical import tone_step
from .._validate import instance, integer
from ..constants import C
from .mcrb import EtaModes, gram

__all__ = ["WB_TOL", "wideband_score", "wideband_terms"]

#: truncation of the spatial-wideband series (relative size of the first term left out)
WB_TOL = 1e-13


def wideband_terms(modes: EtaModes, tone_spacing: float) -> int:
    """Number of series terms the spatial-wideband ``delta`` of ``modes`` needs (``WB_TOL``)."""
    instance("modes", modes, EtaModes)
    tone_step("tone_spacing", tone_spacing)
    eps = 2 * np.pi * tone_spacing * np.abs(modes.offset).max() / C
    x = 0.5 * (modes.n_tones - 1) * eps
    n, term = 0, 1.0
    while term > WB_TOL and n < 200:
        n += 1
        term *= x / n
    return n


def wideband_score(modes: EtaModes, tone_spacing: float, n_terms: int | None = None) -> np.ndarray:
    """``J^H delta`` (T, 7L) complex of the spatial-wideband term (series in the tone's
    offset from the band centre, ``n_terms`` terms, :func:`wideband_terms` by default) of ``modes``."""
    instance("modes", modes, EtaModes)
    tone_step("tone_spacing", tone_spacing)
    if n_terms is not None:
        integer("n_terms", n_terms, minimum=1, maximum=200)
    N = wideband_terms(modes, tone_spacing) if n_terms is None else int(n_terms)
    sc = 0.5 * (modes.n_tones - 1)
    eps = 2 * np.pi * tone_spacing * modes.offset / C  # (T, M, L)
    n = np.arange(N + 1)
    fact = np.cumprod(np.concatenate([[1.0], np.arange(1, N + 1)]))
    # spatial: alpha_l a_lm eps^n; frequency: (-j (s - s_c))^n / n! f_l
    T, M, L = eps.shape
    x = np.empty((T, M, L, N + 1), complex)
    x[..., 0] = modes.alpha[:, None, :] * modes.a
    for k in range(1, N + 1):
        x[..., k] = x[..., k - 1] * eps
    ds = np.arange(modes.n_tones) - sc
    q = (-1j * ds[:, None]) ** n / fact  # (Nf, N+1)
    y = modes.F2[:, :, 0::2, None] * q[None, :, None, :]  # (T, Nf, L, N+1)
    # one BLAS product per mode: (X^H x) (T, 4L, L, N+1) and (F^H y) (T, 2L, L, N+1)
    PX = gram(modes.X, x.reshape(T, M, -1)).reshape(T, -1, L, N + 1)
    PF = gram(modes.F2, y.reshape(T, modes.n_tones, -1)).reshape(T, -1, L, N + 1)
    col = 2 * np.arange(L)
    _, Gf, Gt = modes.grams
    # the exact factor minus one: the series less the unperturbed atom
    PX0 = gram(modes.X, modes.alpha[:, None, :] * modes.a)
    S = np.einsum("tiln,tiln->til", PX[:, modes.si], PF[:, modes.fi])
    S = S - PX0[:, modes.si] * Gf[:, modes.fi][:, :, col]
    S = S * Gt[:, modes.ti][:, :, col]
    return np.conj(modes.coef) * S.sum(axis=2)
