"""A VUE's birth linearised (ours): the Jacobian of Algorithm 3's intersection
(:func:`~.manage.intersection`) in the path's angles and the UE's ``x``
(:func:`intersection_jacobian`), which :func:`~.measuredbirth.birth_covariance` carries the
birth's covariance through, and the cross-covariance of a VUE born so with every track's
normalised bias under a bias-aware tracker (:func:`birth_bias_cross`,
:class:`~.consider.ConsiderNoise`), which the track management asks for
(:func:`~.manage.manage_tracks`). The paper's births (``sigma_P^2 I``) need none of this module.
"""

from __future__ import annotations

import numpy as np

from .config import JavelinConfig
from .measurement import PathMeasurements
from .state import JavelinState


def intersection_jacobian(phi: float, psi: float, x_u: float, bs=(0.0, 0.0, 0.0)) -> np.ndarray:
    """d(y, z) / d(phi, psi, x_u) of :func:`~.manage.intersection` (2, 3): with ``h = x_u - b_x``,
    ``y = b_y + h tan(phi)`` and ``z = b_z + h tan(psi) / cos(phi)``."""
    h = x_u - float(np.asarray(bs, dtype=float)[0])
    c, t = np.cos(phi), np.tan(phi)
    tp = np.tan(psi)
    return np.array(
        [
            [h / c**2, 0.0, t],
            [h * tp * t / c, h / (np.cos(psi) ** 2 * c), tp / c],
        ]
    )


def birth_bias_cross(
    state: JavelinState, meas: PathMeasurements, j: int, config: JavelinConfig, noise
) -> np.ndarray:
    """The cross-covariance (2, 4 L_hat + 4) of a VUE born from path ``j`` with every track's
    normalised bias (consider parameters, :class:`~.consider.ConsiderNoise`), the new track's own
    last: through the UE's ``x`` (``f C[0]``) and through the path's angles, whose repeating
    error is ``L_j[:2] u_new`` (``F_z L_j[:2]``), as :func:`~.measuredbirth.birth_covariance`
    linearises :func:`~.manage.intersection`."""
    F = intersection_jacobian(meas.phi[j], meas.psi[j], state.x[0], config.bs)
    out = np.zeros((2, state.C.shape[1] + 4))
    out[:, :-4] = F[:, 2:3] @ state.C[0:1, :]
    out[:, -4:] = F[:, :2] @ noise.factors(meas)[j, :2, :]
    return out
