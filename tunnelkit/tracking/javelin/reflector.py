"""The curvature of a reflected path as eq. 45 and 51 give it (the paper's SR-NF model,
:class:`~tunnelkit.tracking.javelin.measurement.ReflectorCurvature`): the distance ``||p_r||`` to
the reflection point, written as ``||p_v|| A / B`` (:mod:`~tunnelkit.tracking.javelin.measurement`)
for its closed-form gradients (:func:`reflector_kappa`). ``track_model`` loads it for
``kappa_model = "reflector"``; the VUE curvature (``"vue"``) needs none of it.
"""

from __future__ import annotations

import numpy as np

__all__: list[str] = []


def reflector_kappa(qu: np.ndarray, qv: np.ndarray):
    """``||p_r||`` of eq. 45 for VUEs ``qv`` (n, 3) of UE ``qu`` (3,), with its gradients.

    Returns kappa (n,), d kappa / d q_u (n, 3) (lateral and vertical entries used) and
    d kappa / d q_v (n, 3) (the x entry carries the shared ``x_u`` dependence).
    """
    w = qv - qu  # x component is zero by construction
    A = 0.5 * (np.sum(qv[:, 1:] ** 2, axis=1) - np.sum(qu[1:] ** 2))
    B = np.sum(w * qv, 1)
    rv = np.linalg.norm(qv, axis=1)
    degenerate = (np.abs(B) < 1e-9) | (np.linalg.norm(w, axis=1) < 1e-9)
    Bs = np.where(degenerate, 1.0, B)
    kap = np.where(degenerate, rv, rv * A / Bs)
    # A = 1/2 (|q_v,yz|^2 - |q_u,yz|^2); B = (q_v - q_u)_yz . q_v,yz
    dA_u = np.zeros_like(qv)
    dA_u[:, 1:] = -qu[1:]
    dA_v = np.zeros_like(qv)
    dA_v[:, 1:] = qv[:, 1:]
    dB_u = np.zeros_like(qv)
    dB_u[:, 1:] = -qv[:, 1:]
    dB_v = np.zeros_like(qv)
    dB_v[:, 1:] = 2.0 * qv[:, 1:] - qu[1:]
    drv_v = qv / rv[:, None]
    g_u = (rv[:, None] * dA_u) / Bs[:, None] - (rv * A / Bs**2)[:, None] * dB_u
    g_v = (rv[:, None] * dA_v + A[:, None] * drv_v) / Bs[:, None] - (rv * A / Bs**2)[:, None] * dB_v
    sgn = np.where(kap < 0, -1.0, 1.0)[:, None]  # ||p_r|| = |t| ||p_v||
    g_u = np.where(degenerate[:, None], 0.0, sgn * g_u)
    g_v = np.where(degenerate[:, None], drv_v, sgn * g_v)
    return np.abs(kap), g_u, g_v
