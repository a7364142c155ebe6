"""The ideal weighting of :func:`tunnelkit.design.achievable.predicted_error`
(``weights="ideal"``): the channel's misspecified score mapped to the position through the ideal
Fisher information of the position, as the direct-position ML estimator that assumes eq. 1 weighs
every path.

How it works: docs/internals/design.md.
"""

from __future__ import annotations

import numpy as np

from .bounds import theta_fim, theta_jacobian
from .mcrb import scaled_inverse

#: nothing exported: the ideal branch of predicted_error, on arguments it checked
__all__: list[str] = []


def ideal_parts(cfg, fr, g, imp, peb: np.ndarray, chunks) -> tuple:
    """The squared calibration bias, the wideband bias and the squared diffuse excess (T,) of
    the position under ``imp`` with the ideal weights, on the compressed paths ``fr`` of route
    geometry ``g`` and the eta-space ``chunks`` of achievable's model (its ``_frame`` and
    ``_chunks``); an epoch whose position information is singular turns ``peb`` to ``inf``
    there (in place)."""
    T = fr.idx.shape[0]
    Tm, n_pos, n_nui, base = theta_jacobian(
        cfg,
        fr.s_loc,
        fr.d0,
        fr.src,
        g.origin,
        g.rotation,
        g,
        fr.idx,
        fr.mask,
        "unknown",
        True,
        True,
    )
    sph, sg = np.radians(imp.phase_error_deg), imp.gain_error_db
    cal2, wb, dif2 = np.zeros(T), np.zeros(T), np.zeros(T)
    if not imp.ideal:
        for ch in chunks:
            sl = ch["slice"]
            Tc = Tm[sl]
            Ginv, sing = scaled_inverse(theta_fim(ch["A"], Tc, fr.mask[sl], n_nui, base))
            Ginv = np.where(sing[:, None, None], 0.0, Ginv)
            peb[sl] = np.where(sing, np.inf, peb[sl])
            Pm = Ginv[:, :n_pos, :] @ Tc.transpose(0, 2, 1)  # d position / d score (n_pos, 7L)
            if ch["E"] is not None:
                dif2[sl] = np.trace(Pm @ ch["E"] @ Pm.transpose(0, 2, 1), axis1=1, axis2=2)
            if ch["s_wb"] is not None:
                wb[sl] = np.linalg.norm((Pm @ ch["s_wb"][..., None])[..., 0], axis=1)
            if ch["S_ph"] is not None:
                cal2[sl] = sph**2 * np.sum((Pm @ ch["S_ph"]) ** 2, axis=(1, 2))
                cal2[sl] += sg**2 * np.sum((Pm @ ch["S_g"]) ** 2, axis=(1, 2))
    return cal2, wb, dif2
