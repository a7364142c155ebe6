"""Odometry as a model: the V2X speed and heading messages a vehicle sends, and dead reckoning.

Italiano et al. (2026, section 4.2) draw the messages JAVELIN predicts on as white noise, speed
``+ N(0, 0.2 m/s)`` and heading ``+ N(0, 1 deg)`` per epoch (:data:`WHITE`). Real odometry has
errors that repeat: a wheel-speed scale factor (the tyre's rolling radius, worn or under-inflated:
one draw per drive), a heading bias at the start (the heading the drive begins from), a gyro's
yaw-rate bias (the heading bias grows linearly) and its angle random walk (the heading bias drifts
as a random walk); messages come at a rate (a CAM every 100 ms at best) and some are lost.
:class:`Odometry` draws the messages of one drive under such a model; :data:`AUTOMOTIVE` holds
defaults from published automotive figures (``REFERENCES.md``, "Odometry").

The message of epoch ``k`` (time ``t_k``, true speed ``v_k``, true heading ``theta_k``)::

    speed_k   = (1 + s) v_k + n_v,k               s ~ N(0, speed_scale^2), one per drive
    heading_k = theta_k + b(t_k) + n_theta,k      b(t) = b_0 + r (t - t_0) + q W(t - t_0)

``b_0 ~ N(0, heading_bias^2)``, ``r ~ N(0, yaw_rate_bias^2)``, ``W`` a standard Wiener process,
``q = heading_drift`` [rad/sqrt(s)]; NaN where no message arrived. :func:`dead_reckoning`
integrates the messages (a missing one holds the last), :func:`dead_reckoning_bound` is the
posterior CRLB of that position given the messages alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._physical import speeds
from ._validate import finite_array, nonnegative, positive, real, record, rng_or_error

__all__ = [
    "AUTOMOTIVE",
    "SIGMA_HEADING",
    "SIGMA_SPEED",
    "WHITE",
    "Odometry",
    "dead_reckoning",
    "dead_reckoning_bound",
    "resolve",
]

#: V2X message noise of section 4.2: speed [m/s] and heading [rad]
SIGMA_SPEED, SIGMA_HEADING = 0.2, float(np.radians(1.0))

#: the order of the bound's state: position error (2), scale, heading bias, yaw-rate bias, and the
#: errors of the message held (speed [m/s], heading [rad])
_X, _Y, _S, _B, _R, _EV, _ET = range(7)
_N = 7


@dataclass(frozen=True)
class Odometry:
    """The error model of a drive's V2X speed and heading messages.

    ``speed_scale``: sigma of the wheel-speed scale-factor error (a fraction, one draw per drive,
    ``< 1``); ``speed_noise`` [m/s] white noise per message; ``heading_bias`` [rad] sigma of the
    heading bias at the start (one draw per drive); ``heading_drift`` [rad/sqrt(s)] density of
    the heading bias's random walk (a gyro's angle random walk); ``yaw_rate_bias`` [rad/s] sigma
    of a constant yaw-rate bias (one draw per drive: the heading bias grows by ``r t``);
    ``heading_noise`` [rad] white noise per message; ``rate`` [Hz] the message rate (``None``:
    one message per epoch; an epoch with no message generated since the last one gets NaN);
    ``dropout`` the probability that a message is lost (NaN), independently per message.

    >>> Odometry(heading_drift=-1e-4)
    Traceback (most recent call last):
    ...
    ValueError: heading_drift: must be >= 0, got -0.0001
    >>> Odometry(speed_scale=1.0)
    Traceback (most recent call last):
    ...
    ValueError: speed_scale: a scale-factor sigma must lie in [0, 1) (a fraction), got 1.0
    """

    speed_scale: float = 0.0
    speed_noise: float = SIGMA_SPEED
    heading_bias: float = 0.0
    heading_drift: float = 0.0
    yaw_rate_bias: float = 0.0
    heading_noise: float = SIGMA_HEADING
    rate: float | None = None
    dropout: float = 0.0

    def __post_init__(self) -> None:
        record(self)
        for name in ("speed_noise", "heading_bias", "heading_drift", "yaw_rate_bias"):
            nonnegative(name, getattr(self, name))
        nonnegative("heading_noise", self.heading_noise)
        if not 0.0 <= self.speed_scale < 1.0:
            raise ValueError(
                "speed_scale: a scale-factor sigma must lie in [0, 1) (a fraction), got "
                f"{self.speed_scale}"
            )
        if self.rate is not None:
            positive("rate", self.rate)
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"dropout: a probability in [0, 1) per message, got {self.dropout}")

    @classmethod
    def white(cls, speed_noise: float = SIGMA_SPEED, heading_noise: float = SIGMA_HEADING):
        """The paper's model: white noise only (0.2 m/s, 1 deg by default), a message per epoch."""
        return cls(speed_noise=speed_noise, heading_noise=heading_noise)

    @property
    def is_white(self) -> bool:
        """Nothing but white noise and a message every epoch (the paper's model)."""
        return not (
            self.speed_scale or self.heading_bias or self.heading_drift or self.yaw_rate_bias
        ) and (self.rate is None and self.dropout == 0.0)

    def schedule(self, t) -> np.ndarray:
        """(T,) bool: epochs of ``t`` [s] with a message generated since the previous epoch
        (every epoch without a ``rate``; epoch 0 always), before any loss."""
        t = _times(t)
        if self.rate is None:
            return np.ones(t.size, bool)
        n = np.floor((t - t[0]) * self.rate + 1e-9)
        return np.concatenate([[True], n[1:] > n[:-1]])

    def draw(self, t, speed, heading, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """The messages of one drive: ``(speed_msg, heading_msg)`` (T,) from the true ``speed``
        [m/s] and ``heading`` [rad] (T,) at epoch times ``t`` [s], NaN where no message arrived.

        The draws, in order: the white speed noise (T), the white heading noise (T) — all the
        white model draws, as the drive simulator always drew them — then, only for the terms
        the model has, the scale factor, the heading bias, the yaw-rate bias, the random walk
        (T - 1) and the losses (T)."""
        rng = rng_or_error("rng", rng)
        t = _times(t)
        T = t.size
        speed = speeds("speed", finite_array("speed", speed, shape=(T,)), vectors=False)
        heading = finite_array("heading", heading, shape=(T,))
        speed_msg = speed + self.speed_noise * rng.standard_normal(T)
        heading_msg = heading + self.heading_noise * rng.standard_normal(T)
        if self.is_white:
            return speed_msg, heading_msg
        if self.speed_scale:
            speed_msg = speed_msg + self.speed_scale * rng.standard_normal() * speed
        bias = np.zeros(T)
        if self.heading_bias:
            bias += self.heading_bias * rng.standard_normal()
        if self.yaw_rate_bias:
            bias += self.yaw_rate_bias * rng.standard_normal() * (t - t[0])
        if self.heading_drift:
            steps = self.heading_drift * np.sqrt(np.diff(t)) * rng.standard_normal(T - 1)
            bias[1:] += np.cumsum(steps)
        heading_msg = heading_msg + bias
        arrived = self.schedule(t)
        if self.dropout:
            arrived &= rng.random(T) >= self.dropout
        return np.where(arrived, speed_msg, np.nan), np.where(arrived, heading_msg, np.nan)


#: the paper's white model (section 4.2): 0.2 m/s, 1 deg, a message every epoch, nothing else
WHITE = Odometry.white()

#: automotive defaults (``REFERENCES.md``, "Odometry"): a 1 % wheel-speed scale factor (tyre
#: wear alone changes the rolling circumference by up to 2 %), the paper's 1 deg as the bias of
#: the heading the drive starts from, a MEMS gyro's 0.3 deg/sqrt(h) angle random walk and a
#: 10 deg/h yaw-rate bias (about twice its 4.6 deg/h bias stability), the paper's white noise,
#: CAMs at 10 Hz (T_GenCamMin = 100 ms) and 10 % lost (a 90 % reliability requirement)
AUTOMOTIVE = Odometry(
    speed_scale=0.01,
    heading_bias=float(np.radians(1.0)),
    heading_drift=float(np.radians(0.3) / 60.0),
    yaw_rate_bias=float(np.radians(10.0) / 3600.0),
    rate=10.0,
    dropout=0.1,
)


def resolve(
    odometry: Odometry | None,
    sigma_speed: float = SIGMA_SPEED,
    sigma_heading: float = SIGMA_HEADING,
) -> Odometry:
    """The model a simulator draws the messages with: ``odometry``, or without one the white
    model of ``sigma_speed`` [m/s] / ``sigma_heading`` [rad]; both a model and sigmas other than
    the paper's are refused (the model holds its own noise)."""
    sigma_speed = nonnegative("sigma_speed", sigma_speed)
    sigma_heading = nonnegative("sigma_heading", sigma_heading)
    if odometry is None:
        return Odometry.white(sigma_speed, sigma_heading)
    if not isinstance(odometry, Odometry):
        raise TypeError(f"odometry: expected an Odometry or None, got {type(odometry).__name__}")
    if (sigma_speed, sigma_heading) != (SIGMA_SPEED, SIGMA_HEADING):
        raise ValueError(
            "odometry, sigma_speed / sigma_heading: give the messages' model or the white "
            "noise's sigmas, not both"
        )
    return odometry


def _times(t) -> np.ndarray:
    t = finite_array("t", t, ndim=1)
    if t.size < 1:
        raise ValueError("t: expected one or more epoch times, got none")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t: epoch times must increase strictly")
    return t


def _held(name: str, x: np.ndarray) -> np.ndarray:
    """``x`` (..., T) with every NaN replaced by the last message before it (a missing start by
    the first message)."""
    if np.isinf(x).any():
        raise ValueError(f"{name}: contains infinite values (NaN marks a missing message)")
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
    t = _times(t)
    T = t.size
    v = _held("speed_msg", np.asarray(speed_msg, dtype=float))
    th = _held("heading_msg", np.asarray(heading_msg, dtype=float))
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
    if not isinstance(odometry, Odometry):
        raise TypeError(f"odometry: expected an Odometry, got {type(odometry).__name__}")
    t = _times(t)
    T = t.size
    v = speeds("speed", finite_array("speed", speed, shape=(T,)), vectors=False)
    th = finite_array("heading", heading, shape=(T,))
    sigma_start = nonnegative("sigma_start", real("sigma_start", sigma_start))
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
    out[..., 0] = np.sqrt(P[..., _X, _X] + P[..., _Y, _Y])
    for k in range(1, T):
        dt = float(t[k] - t[k - 1])
        F, G = _transition(dt, float(v[k - 1]), float(th[k - 1]), float(v[k]), fresh[..., k])
        Q = np.diag([o.heading_drift**2 * dt, o.speed_noise**2, o.heading_noise**2])
        P = F @ P @ np.swapaxes(F, -1, -2) + G @ Q @ np.swapaxes(G, -1, -2)
        out[..., k] = np.sqrt(np.maximum(P[..., _X, _X] + P[..., _Y, _Y], 0.0))
    return out
