"""Prediction step (eq. 62-63): velocity-sensor UE model and VUE random walk (or mirror motion).

:func:`predict` moves the state by the V2X speed and heading (:func:`ue_velocity`,
:func:`motion_increment`) with the sensor noise; a VUE follows a random walk (the paper's
:class:`RandomWalk`) or the mirrored UE displacement (ours, :class:`MirrorMotion`). Told an
odometry model with repeating errors, the state also carries its biases
(:func:`odometry_transition`); a ``"midpoint"`` step takes :func:`midpoint_messages`.

How it works: docs/internals/tracking.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._physical import speeds, step_seconds
from ..._validate import choice, instance, messages, positive, real
from .config import JavelinConfig
from .state import I_BIAS, JavelinState, first_vue

__all__ = ["midpoint_messages", "motion_increment", "odometry_transition", "predict", "ue_velocity"]

#: the VUE motion models (:class:`RandomWalk`, :class:`MirrorMotion`)
VUE_MOTIONS = ("random_walk", "mirror")


def ue_velocity(speed: float, heading: float) -> np.ndarray:
    """UE velocity (3,) from speed [m/s] and heading [rad] (angle from +x in the road plane)."""
    speeds("speed", speed), real("heading", heading)
    return float(speed) * np.array([np.cos(heading), np.sin(heading), 0.0])


def midpoint_messages(speed, heading) -> tuple[np.ndarray, np.ndarray]:
    """The V2X messages (``speed`` [m/s], ``heading`` [rad], (T,)) a ``"midpoint"`` step takes:
    entry ``k`` the mean of those of ``k`` and ``k + 1`` (headings along the shorter arc), read by
    the step into ``k + 1`` where eq. 62's held heading lags the chord by half the turn (notebook
    04); the message of ``k`` where either is missing (NaN) and at the last epoch."""
    v, th = messages("speed", speed), messages("heading", heading)
    if th.shape != v.shape:
        raise ValueError(f"speed, heading: expected one shape (T,), got {v.shape} and {th.shape}")
    speeds("speed", v[np.isfinite(v)], vectors=False)
    out_v, out_th = v.copy(), th.copy()
    both = np.isfinite(v[:-1]) & np.isfinite(v[1:]) & np.isfinite(th[:-1]) & np.isfinite(th[1:])
    half = np.angle(np.exp(1j * (th[1:] - th[:-1]))) / 2  # half the turn, on the shorter arc
    out_v[:-1] = np.where(both, (v[:-1] + v[1:]) / 2, v[:-1])
    out_th[:-1] = np.where(both, np.angle(np.exp(1j * (th[:-1] + half))), th[:-1])
    return out_v, out_th


def motion_increment(
    state: JavelinState, speed: float, heading: float, dt: float, vue_motion: str = "random_walk"
) -> tuple[np.ndarray, np.ndarray]:
    """State increment ``f(s) - s`` (D,) and its sensitivity ``G`` (D, 2) to ``(nu, theta)``
    (the motion of the UE and the VUEs; the odometry states' rows are zero)."""
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
    o = first_vue(state.n_odo)
    if vue_motion == "mirror" and state.n_vue:
        yz = state.x[o:].reshape(-1, 2)
        w = yz - state.x[1:3]
        nrm = np.linalg.norm(w, axis=1, keepdims=True)
        n = np.where(nrm > 1e-9, w / np.maximum(nrm, 1e-12), 0.0)  # (n, 2), x component is 0
        # mirrored displacement: the yz part of du - 2 (n . du) n
        dv = du[1:] - 2.0 * (n @ du[1:])[:, None] * n
        inc[o:] = dv.ravel()
        # same map applied to the columns of Gu (linear in du)
        Gv = Gu[None, 1:, :] - 2.0 * n[:, :, None] * np.einsum("nk,kc->nc", n, Gu[1:])[:, None, :]
        G[o:] = Gv.reshape(-1, 2)
    return inc, G


def odometry_transition(
    state: JavelinState, speed: float, heading: float, dt: float, vue_motion: str = "random_walk"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The prediction of a state with odometry states: the increment (D,), ``F`` (D, D) and
    ``G`` (D, 2) (:func:`~.odometrystates.odometry_prediction` on :func:`motion_increment`)."""
    from .odometrystates import odometry_prediction  # a tracker told the odometry

    return odometry_prediction(state, speed, heading, dt, vue_motion, motion_increment)


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
    """Predicted ``(x, P)`` (eq. 62-63) with ``F = I`` (the motion enters as a known input);
    with odometry states (``state.n_odo``), ``F`` of :func:`odometry_transition` and the heading
    bias's random walk (``config.heading_drift``).

    ``vue_motion`` as in :func:`motion_increment`; ``sigma_speed`` overrides the configured speed
    noise (used while the V2X message is missing and the last one is reused).
    """
    dt = step_seconds("dt", dt)
    instance("state", state, JavelinState)
    instance("config", config, JavelinConfig)
    if sigma_speed is not None:
        positive("sigma_speed", sigma_speed)
    if state.n_odo:
        inc, F, G = odometry_transition(state, speed, heading, dt, vue_motion)
    else:
        inc, G = motion_increment(state, speed, heading, dt, vue_motion)
    s_nu = config.sigma_speed if sigma_speed is None else sigma_speed
    Q = G @ np.diag([s_nu**2, config.sigma_heading**2]) @ G.T
    Q[2, 2] += config.sigma_height**2 * dt
    idx = np.arange(first_vue(state.n_odo), state.dim)
    Q[idx, idx] += config.sigma_vue_walk**2 * dt
    x = state.x + inc
    if state.n_odo:
        Q[I_BIAS, I_BIAS] += config.heading_drift**2 * dt
        P = F @ state.P @ F.T + Q
    else:
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
