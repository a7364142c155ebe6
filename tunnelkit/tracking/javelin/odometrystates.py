"""The odometry states of a tracker told an odometry model (:data:`~.state.ODOMETRY_STATES`):
the config told it (:func:`told_config`, what :meth:`~.config.JavelinConfig.told` gives), and
the states kept out of the measurement model, which does not depend on them: the state without
them (:func:`kinematic`) and a measurement Jacobian with their zero columns put back
(:func:`odometry_columns`). Their prediction is
:func:`~tunnelkit.tracking.javelin.motion.odometry_transition`; the paper's state (``n_odo = 0``)
needs none of this module.
"""

from __future__ import annotations

import numpy as np

from ..._validate import finite_array
from ...odometry import Odometry
from .state import first_vue

__all__ = ["kinematic", "odometry_columns"]


def told_config(config, odometry):
    """A copy of the tracker's ``config`` (:class:`~.config.JavelinConfig`) told the odometry
    model ``odometry`` (:class:`tunnelkit.odometry.Odometry`):
    its white speed and heading noise and its repeating errors (the scale factor, the heading
    bias, its random walk and the yaw-rate bias). Told the paper's white model it is the
    paper's config with that white noise. The message rate and losses are not numbers of
    the config: a missing message is the tracker's to handle (the last one, inflated)."""
    if not isinstance(odometry, Odometry):
        raise TypeError(f"odometry: expected an Odometry, got {type(odometry).__name__}")
    o = odometry
    return config.with_(
        sigma_speed=o.speed_noise,
        sigma_heading=o.heading_noise,
        sigma_speed_scale=o.speed_scale,
        sigma_heading_bias=o.heading_bias,
        heading_drift=o.heading_drift,
        sigma_yaw_rate_bias=o.yaw_rate_bias,
    )


def kinematic(x: np.ndarray, n_odo: int = 0) -> np.ndarray:
    """The state vector ``x`` without its odometry states: ``[x_u, y_u, z_u, y_v1, ...]`` of
    eq. 43, what the measurement model reads (``x`` itself when ``n_odo = 0``)."""
    o = first_vue(n_odo)
    x = finite_array("x", x, ndim=1)
    if x.size < o:
        raise ValueError(f"x: expected at least {o} entries (UE and odometry states), got {x.size}")
    return x if o == 3 else np.concatenate([x[:3], x[o:]])


def odometry_columns(J: np.ndarray, n_odo: int = 0) -> np.ndarray:
    """A measurement Jacobian (..., D_kin) of :func:`kinematic`'s state with ``n_odo`` zero
    columns inserted after the UE (no measurement depends on the odometry states): ``J`` (L, 4,
    D_kin) as :func:`~.measurement.track_model` gives it (only a curvature row may be NaN)."""
    first_vue(n_odo)
    if isinstance(J, str | bytes) or np.asarray(J).dtype.kind not in "iuf":
        raise TypeError(f"J: expected a real array (L, 4, D) from track_model, got {J!r:.40}")
    J = np.asarray(J, dtype=float)
    if J.ndim != 3 or J.shape[1] != 4 or J.shape[2] < 3:
        raise ValueError(f"J: expected shape (L, 4, D >= 3) (track_model), got {J.shape}")
    if not np.isfinite(J[:, [0, 1, 3]]).all():  # phi, psi and the range rows
        raise ValueError("J: the angle and delay rows must be finite")
    return J if not n_odo else np.insert(J, [3] * n_odo, 0.0, axis=-1)
