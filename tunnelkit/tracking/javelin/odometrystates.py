"""The odometry states of a tracker told an odometry model (:data:`~.state.ODOMETRY_STATES`):
the config told it (:func:`told_config`, what :meth:`~.config.JavelinConfig.told` gives), and
the states kept out of the measurement model, which does not depend on them: the state without
them (:func:`kinematic`) and a measurement Jacobian with their zero columns put back
(:func:`odometry_columns`); their prediction (:func:`odometry_prediction`, what
:func:`~tunnelkit.tracking.javelin.motion.odometry_transition` gives). The paper's state
(``n_odo = 0``) needs none of this module.
"""

from __future__ import annotations

import numpy as np

from ..._physical import speeds
from ..._validate import finite_array, instance, real
from ...odometry import Odometry
from .state import I_BIAS, I_RATE, I_SCALE, JavelinState, first_vue

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


def odometry_prediction(
    state: JavelinState, speed: float, heading: float, dt: float, vue_motion: str, increment
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The prediction of a state with odometry states (docs/internals): the increment (D,),
    ``F`` (D, D) and the sensitivity ``G`` (D, 2) to the message's white noise ``(n_v,
    n_theta)``, for the message ``speed`` [m/s], ``heading`` [rad] over ``dt`` [s]. With
    ``nu_c = speed / (1 + s)`` and ``theta_c = heading - b`` the motion of ``increment``
    (:func:`~.motion.motion_increment`) at ``(nu_c, theta_c)``: ``d/ds = -G_c[:, 0] speed /
    (1 + s)^2``, ``d/db = -G_c[:, 1]``, ``d/dn_v = G_c[:, 0] / (1 + s)``; ``b`` grows by
    ``r dt``."""
    instance("state", state, JavelinState)
    if state.n_odo != 3:
        raise ValueError(f"state: expected the odometry states (n_odo = 3), got {state.n_odo}")
    speeds("speed", speed), real("heading", heading)
    i_s, i_b, i_r = I_SCALE, I_BIAS, I_RATE
    s, b, r = state.x[i_s], state.x[i_b], state.x[i_r]
    if not s > -1.0:
        raise ValueError(f"state: the speed scale factor must exceed -1, got {s}")
    inc, Gc = increment(state, speed / (1.0 + s), heading - b, dt, vue_motion)
    inc[i_b] = r * dt
    F = np.eye(state.dim)
    F[:, i_s] -= Gc[:, 0] * speed / (1.0 + s) ** 2
    F[:, i_b] -= Gc[:, 1]
    F[i_b, i_r] = dt
    G = Gc * np.array([1.0 / (1.0 + s), 1.0])
    return inc, F, G
