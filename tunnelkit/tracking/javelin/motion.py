"""Prediction step (eq. 62-63): velocity-sensor UE model and VUE random walk (or mirror motion).

The UE moves by the speed ``nu`` and heading ``theta`` shared over V2X:
``p_u,k = p_u,k-1 + T nu [cos theta, sin theta, 0]``. The sensor noise (``sigma_nu``,
``sigma_theta``) enters through ``G = d(displacement)/d(nu, theta)``:
``Q_u = T^2 G diag(sigma_nu^2, sigma_theta^2) G^T`` plus a small height drift. A VUE follows a
random walk, ``Q_v = sigma_w^2 T I_2`` (the paper's choice, section 3.5).

``vue_motion="mirror"`` (ours): a VUE of a surface running along the tunnel is the UE mirrored in
that surface, so it moves by the mirrored UE displacement ``Delta_v = Delta_u - 2 (n . Delta_u) n``
with ``n`` the unit vector from UE to VUE. The same speed/heading noise then drives UE and VUEs,
correlated through one ``G``; the random walk stays on top for curved surfaces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._physical import speeds, step_seconds
from ..._validate import choice, instance, positive, real
from .config import JavelinConfig
from .state import JavelinState

__all__ = ["motion_increment", "predict", "ue_velocity"]

#: the VUE motion models (:class:`RandomWalk`, :class:`MirrorMotion`)
VUE_MOTIONS = ("random_walk", "mirror")


def ue_velocity(speed: float, heading: float) -> np.ndarray:
    """UE velocity (3,) from speed [m/s] and heading [rad] (angle from +x in the road plane)."""
    speeds("speed", speed), real("heading", heading)
    return float(speed) * np.array([np.cos(heading), np.sin(heading), 0.0])


def motion_increment(
    state: JavelinState, speed: float, heading: float, dt: float, vue_motion: str = "random_walk"
) -> tuple[np.ndarray, np.ndarray]:
    """State increment ``f(s) - s`` (D,) and its sensitivity ``G`` (D, 2) to ``(nu, theta)``."""
    instance("state", state, JavelinState)
    speeds("speed", speed), real("heading", heading), step_seconds("dt", dt)
    choice("vue_motion", vue_motion, VUE_MOTIONS)
    D = state.dim
    du = dt * ue_velocity(speed, heading)
    Gu = dt * np.array(
        [
            [np.cos(heading), -speed * np.sin(heading)],
            [np.sin(heading), speed * np.cos(heading)],
            [0.0, 0.0],
        ]
    )
    inc = np.zeros(D)
    G = np.zeros((D, 2))
    inc[:3] = du
    G[:3] = Gu
    if vue_motion == "mirror" and state.n_vue:
        yz = state.x[3:].reshape(-1, 2)
        w = yz - state.x[1:3]
        nrm = np.linalg.norm(w, axis=1, keepdims=True)
        n = np.where(nrm > 1e-9, w / np.maximum(nrm, 1e-12), 0.0)  # (n, 2), x component is 0
        # mirrored displacement: the yz part of du - 2 (n . du) n
        dv = du[1:] - 2.0 * (n @ du[1:])[:, None] * n
        inc[3:] = dv.ravel()
        # same map applied to the columns of Gu (linear in du)
        Gv = Gu[None, 1:, :] - 2.0 * n[:, :, None] * np.einsum("nk,kc->nc", n, Gu[1:])[:, None, :]
        G[3:] = Gv.reshape(-1, 2)
    return inc, G


def predict(
    state: JavelinState,
    speed: float,
    heading: float,
    dt: float,
    config: JavelinConfig,
    *,
    vue_motion: str = "random_walk",
    sigma_speed: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Predicted ``(x, P)`` (eq. 62-63) with ``F = I`` (the motion enters as a known input).

    ``vue_motion`` as in :func:`motion_increment`; ``sigma_speed`` overrides the configured speed
    noise (used while the V2X message is missing and the last one is reused).
    """
    dt = step_seconds("dt", dt)
    instance("state", state, JavelinState)
    instance("config", config, JavelinConfig)
    if sigma_speed is not None:
        positive("sigma_speed", sigma_speed)
    inc, G = motion_increment(state, speed, heading, dt, vue_motion)
    s_nu = config.sigma_speed if sigma_speed is None else sigma_speed
    Q = G @ np.diag([s_nu**2, config.sigma_heading**2]) @ G.T
    Q[2, 2] += config.sigma_height**2 * dt
    idx = np.arange(3, state.dim)
    Q[idx, idx] += config.sigma_vue_walk**2 * dt
    x = state.x + inc
    P = state.P + Q
    return x, 0.5 * (P + P.T)


@dataclass(frozen=True)
class RandomWalk:
    """Each VUE follows a random walk, ``Q_v = sigma_w^2 T I_2`` (the paper, section 3.5)."""

    name = "random_walk"

    def increment(self, state, speed: float, heading: float, dt: float):
        """State increment ``f(s) - s`` (D,) and its sensitivity ``G`` (D, 2) to the motion."""
        return motion_increment(state, speed, heading, dt, self.name)


@dataclass(frozen=True)
class MirrorMotion(RandomWalk):
    """A wall-fixed VUE moves by the UE displacement mirrored in its surface (ours), with the
    random walk on top for curved surfaces."""

    name = "mirror"
