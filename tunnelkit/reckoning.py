"""Dead reckoning on the V2X odometry messages (:mod:`tunnelkit.odometry`) and its bound.

:func:`dead_reckoning` integrates the messages from a start (a lost message holds the last
one); :func:`dead_reckoning_bound` is the posterior CRLB (Tichavský et al. 1998) of that position
given the messages alone, with the scale factor and the heading biases as states;
:func:`posterior_bound` the same recursion with a radio's position information per epoch beside
the messages (the bound over a drive of a tracker told the odometry model).
"""

from __future__ import annotations

import math

import numpy as np

from ._physical import speeds
from ._validate import finite_array, messages, nonnegative
from .odometry import Odometry, epoch_times

__all__ = ["dead_reckoning", "dead_reckoning_bound", "posterior_bound"]

#: the order of the bound's state: position error (2), scale, heading bias, yaw-rate bias, and the
#: errors of the message held (speed [m/s], heading [rad])
_X, _Y, _S, _B, _R, _EV, _ET = range(7)
_N = 7


def _held(name: str, x) -> np.ndarray:
    """``x`` (..., T) with every NaN replaced by the last message before it (a missing start by
    the first message)."""
    x = messages(name, x, batched=True)
    ok = np.isfinite(x)
    if not ok.any(axis=-1).all():
        raise ValueError(f"{name}: a drive without any message: nothing to dead-reckon on")
    T = x.shape[-1]
    idx = np.maximum.accumulate(np.where(ok, np.arange(T), -1), axis=-1)
    idx = np.where(idx < 0, np.argmax(ok, axis=-1)[..., None], idx)
    return np.take_along_axis(x, idx, axis=-1)


def dead_reckoning(t, speed_msg, heading_msg, start) -> np.ndarray:
    """Positions (..., T, 2) [m] integrated from ``start`` (..., 2) with the messages (..., T)
    (NaN: missing, the last one held): ``p_k = p_{k-1} + (t_k - t_{k-1}) nu_{k-1} (cos theta_{k-1},
    sin theta_{k-1})``, ``p_0 = start``. Leading axes are drives."""
    t = epoch_times(t)
    T = t.size
    v = _held("speed_msg", speed_msg)
    th = _held("heading_msg", heading_msg)
    if v.shape[-1] != T or th.shape != v.shape:
        raise ValueError(
            f"speed_msg, heading_msg: expected shape (..., {T}) each, got {v.shape} and {th.shape}"
        )
    start = finite_array("start", start)
    if start.shape[-1:] != (2,):
        raise ValueError(f"start: expected shape (..., 2), got {start.shape}")
    dt = np.diff(t)
    step = (dt * v[..., :-1])[..., None] * np.stack([np.cos(th), np.sin(th)], -1)[..., :-1, :]
    zero = np.zeros((*step.shape[:-2], 1, 2))
    return start[..., None, :] + np.concatenate([zero, np.cumsum(step, axis=-2)], axis=-2)


def _transition(dt: float, v_prev: float, th_prev: float, v: float, fresh) -> tuple:
    """``(F, G)`` of one step of the linearised error state into an epoch (speed ``v``) from the
    previous one (``v_prev``, ``th_prev``): the position moves with the message held, the bias
    with the yaw-rate bias, and a fresh message (``fresh`` (...,) bool) resets the held errors to
    ``s v + n_v`` and ``b + n_theta``. ``F`` (..., 7, 7), ``G`` (..., 7, 3) for the noise
    ``(w_b, n_v, n_theta)``."""
    fresh = np.asarray(fresh, bool)
    P = np.eye(_N)
    c, s = math.cos(th_prev), math.sin(th_prev)
    P[_X, _EV], P[_Y, _EV] = dt * c, dt * s
    P[_X, _ET], P[_Y, _ET] = -dt * v_prev * s, dt * v_prev * c
    P[_B, _R] = dt
    reset = np.eye(_N)
    reset[_EV] = 0.0
    reset[_ET] = 0.0
    reset[_EV, _S] = v
    reset[_ET, _B] = 1.0
    Rm = np.where(fresh[..., None, None], reset, np.eye(_N))
    G = np.zeros((*fresh.shape, _N, 3))
    G[..., :, 0] = Rm[..., :, _B]
    G[..., _EV, 1] = fresh
    G[..., _ET, 2] = fresh
    return Rm @ P, G


def _step(x, w, dt: float, v_prev: float, th_prev: float, v: float, fresh: bool) -> np.ndarray:
    """The error state's step without linearisation (what :func:`_transition` linearises at 0):
    the position error of dead reckoning's step ``dt (v + e_v) u(theta + e_theta)`` against the
    true ``dt v u(theta)``."""
    x = np.array(x, dtype=float)
    th = th_prev + x[_ET]
    x[_X] += dt * ((v_prev + x[_EV]) * math.cos(th) - v_prev * math.cos(th_prev))
    x[_Y] += dt * ((v_prev + x[_EV]) * math.sin(th) - v_prev * math.sin(th_prev))
    x[_B] += x[_R] * dt + w[0]
    if fresh:
        x[_EV] = x[_S] * v + w[1]
        x[_ET] = x[_B] + w[2]
    return x


def dead_reckoning_bound(
    t, speed, heading, odometry: Odometry, sigma_start: float = 0.0, arrived=None
) -> np.ndarray:
    """2-D position RMSE bound [m] (T,) of any estimator of the position from the odometry
    messages alone, from a start known to ``sigma_start`` [m] per axis, along the true ``speed``
    [m/s] and ``heading`` [rad] (T,) at times ``t`` [s].

    The posterior CRLB (Tichavský et al. 1998) of the linearised error state ``[x, y, s, b, r,
    e_v, e_theta]`` (position, scale factor, heading bias, yaw-rate bias, errors of the message
    held): with no measurement of it, the recursion ``J_k^-1 = F_k J_{k-1}^-1 F_k^T + G_k Q_k
    G_k^T`` (covariance form: ``Q`` singular is allowed), ``Q_k = diag(q^2 dt, sigma_v^2,
    sigma_theta^2)``. Dead reckoning's error is this linear combination of the draws to first
    order (the heading errors enter through their sine and cosine); it is the estimator that
    attains the bound. ``arrived`` (T,) or (N, T) bool: the epochs whose message arrived (one
    pattern per drive, result (N, T)); ``None``: the odometry's schedule with no loss. Epoch 0
    counts as arrived (dead reckoning starts from the first message). A message held over epochs
    where the truth turns adds a model error the bound does not hold."""
    return posterior_bound(t, speed, heading, odometry, None, sigma_start, arrived)


def posterior_bound(
    t, speed, heading, odometry: Odometry, info=None, sigma_start: float = 0.0, arrived=None
) -> np.ndarray:
    """2-D position RMSE bound [m] (T,) (or (N, T), ``arrived`` as in
    :func:`dead_reckoning_bound`) of any estimator of the position from the odometry messages
    and a measurement whose Fisher information about the horizontal position at epoch ``k`` is
    ``info[k]`` (T, 2, 2) [1/m^2] (a radio's fixes; zero where it has none): the posterior CRLB
    (Tichavský et al. 1998) of :func:`dead_reckoning_bound`'s error state with the measurement
    entering its position block, ``J_k = (F_k J_{k-1}^-1 F_k^T + G_k Q_k G_k^T)^-1 + I_k``,
    computed in covariance form ``P_k = (I + P_k^- I_k)^-1 P_k^-`` (``Q`` and ``I_k`` may be
    singular), epoch 0 updated too. The scale factor and the heading biases are states the
    measurement makes observable: a tracker told the model can learn them. ``info=None``: no
    measurement (:func:`dead_reckoning_bound`). The bound of the message schedule without
    losses (``arrived=None``) lies below that of any loss pattern: a lower bound with losses
    too."""
    if not isinstance(odometry, Odometry):
        raise TypeError(f"odometry: expected an Odometry, got {type(odometry).__name__}")
    t = epoch_times(t)
    T = t.size
    v = speeds("speed", finite_array("speed", speed, shape=(T,)), vectors=False)
    th = finite_array("heading", heading, shape=(T,))
    sigma_start = nonnegative("sigma_start", sigma_start)
    if info is not None:
        info = finite_array("info", info, shape=(T, 2, 2))
        if np.any(
            np.linalg.eigvalsh(0.5 * (info + np.swapaxes(info, 1, 2)))
            < -1e-9 * (1.0 + np.abs(info).max())
        ):
            raise ValueError("info: expected positive semi-definite information matrices")
    if arrived is None:
        fresh = odometry.schedule(t)
    else:
        fresh = np.asarray(arrived)
        if fresh.dtype != bool or fresh.shape[-1:] != (T,) or fresh.ndim > 2:
            raise ValueError(f"arrived: expected a bool array (T,) or (N, T), T = {T}")
    fresh = fresh.copy()
    fresh[..., 0] = True
    o = odometry
    P = np.zeros((*fresh.shape[:-1], _N, _N))
    P[..., _X, _X] = P[..., _Y, _Y] = sigma_start**2
    P[..., _S, _S], P[..., _B, _B] = o.speed_scale**2, o.heading_bias**2
    P[..., _R, _R] = o.yaw_rate_bias**2
    P[..., _EV, _EV] = (o.speed_scale * v[0]) ** 2 + o.speed_noise**2
    P[..., _ET, _ET] = o.heading_bias**2 + o.heading_noise**2
    P[..., _EV, _S] = P[..., _S, _EV] = o.speed_scale**2 * v[0]
    P[..., _ET, _B] = P[..., _B, _ET] = o.heading_bias**2
    out = np.empty(fresh.shape)
    for k in range(T):
        if k:
            dt = float(t[k] - t[k - 1])
            F, G = _transition(dt, float(v[k - 1]), float(th[k - 1]), float(v[k]), fresh[..., k])
            Q = np.diag([o.heading_drift**2 * dt, o.speed_noise**2, o.heading_noise**2])
            P = F @ P @ np.swapaxes(F, -1, -2) + G @ Q @ np.swapaxes(G, -1, -2)
        if info is not None and np.any(info[k]):
            M = np.zeros((_N, _N))
            M[:2, :2] = 0.5 * (info[k] + info[k].T)
            P = np.linalg.solve(np.eye(_N) + P @ M, P)
            P = 0.5 * (P + np.swapaxes(P, -1, -2))
        out[..., k] = np.sqrt(np.maximum(P[..., _X, _X] + P[..., _Y, _Y], 0.0))
    return out
