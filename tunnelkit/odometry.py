"""Odometry as a model: the V2X speed and heading messages of a drive.

Italiano et al. (2026, section 4.2) draw the messages as white noise, speed ``+ N(0, 0.2 m/s)``
and heading ``+ N(0, 1 deg)`` per epoch (:data:`WHITE`). Real odometry has errors that repeat
(a wheel-speed scale factor, a heading bias that starts off, grows with a gyro's yaw-rate bias
and drifts with its angle random walk), messages come at a rate and some are lost:
:class:`Odometry` draws them, :data:`AUTOMOTIVE` holds published automotive figures
(``REFERENCES.md``, "Odometry"); :mod:`tunnelkit.reckoning` integrates them and bounds the result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._physical import MAX_SPEED, speeds
from ._validate import finite_array, nonnegative, positive, record, rng_or_error

__all__ = [
    "AUTOMOTIVE",
    "MODELS",
    "SIGMA_HEADING",
    "SIGMA_SPEED",
    "WHITE",
    "Odometry",
    "epoch_times",
]

#: the most messages per second a model may send (a CAM is sent at 1-10 Hz)
MAX_RATE_HZ = 10_000.0

#: V2X message noise of section 4.2: speed [m/s] and heading [rad]
SIGMA_SPEED, SIGMA_HEADING = 0.2, float(np.radians(1.0))


@dataclass(frozen=True)
class Odometry:
    """The error model of a drive's V2X speed and heading messages. The message of epoch ``k``
    (time ``t_k``, true speed ``v_k``, heading ``theta_k``; NaN when none arrived)::

        speed_k   = (1 + s) v_k + n_v,k               s ~ N(0, speed_scale^2), one per drive
        heading_k = theta_k + b(t_k) + n_theta,k      b(t) = b_0 + r (t - t_0) + q W(t - t_0)

    ``b_0 ~ N(0, heading_bias^2)``, ``r ~ N(0, yaw_rate_bias^2)``, ``q = heading_drift``, ``W`` a
    standard Wiener process.

    ``speed_scale``: sigma of the wheel-speed scale-factor error (a fraction, one draw per drive,
    ``< 1``); ``speed_noise`` [m/s] white noise per message; ``heading_bias`` [rad] sigma of the
    heading bias at the start (one draw per drive); ``heading_drift`` [rad/sqrt(s)] density of
    the heading bias's random walk (a gyro's angle random walk); ``yaw_rate_bias`` [rad/s] sigma
    of a constant yaw-rate bias (one draw per drive: the heading bias grows by ``r t``);
    ``heading_noise`` [rad] white noise per message; ``rate`` [Hz] (``None``: one message per
    epoch; an epoch with none generated since the last gets NaN); ``dropout`` the loss per message.

    >>> Odometry(heading_drift=-1e-4)
    Traceback (most recent call last):
    ...
    ValueError: heading_drift: must be >= 0, got -0.0001
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
        for name in (
            "speed_noise",
            "heading_bias",
            "heading_drift",
            "yaw_rate_bias",
            "heading_noise",
        ):
            nonnegative(name, getattr(self, name))
        if self.speed_noise >= MAX_SPEED:
            raise ValueError(
                f"speed_noise: a speed error of {self.speed_noise:g} m/s is no car's odometry "
                f"(below {MAX_SPEED:g} m/s, faster than any road vehicle)"
            )
        for name, unit in (
            ("heading_bias", "rad"),
            ("heading_noise", "rad"),
            ("heading_drift", "rad/sqrt(s)"),
            ("yaw_rate_bias", "rad/s"),
        ):
            if getattr(self, name) > np.pi:
                raise ValueError(
                    f"{name}: a sigma of at most pi {unit} (half a turn), got "
                    f"{getattr(self, name):g} (radians, not degrees?)"
                )
        if not 0.0 <= self.speed_scale < 1.0:
            raise ValueError(f"speed_scale: a sigma in [0, 1) (a fraction), got {self.speed_scale}")
        if self.rate is not None and positive("rate", self.rate) > MAX_RATE_HZ:
            raise ValueError(
                f"rate: at most {MAX_RATE_HZ:g} messages per second, got {self.rate:g}"
            )
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"dropout: a probability in [0, 1) per message, got {self.dropout}")

    @classmethod
    def white(cls, speed_noise: float = SIGMA_SPEED, heading_noise: float = SIGMA_HEADING):
        """The paper's model: white noise only (0.2 m/s, 1 deg by default), a message per epoch."""
        return cls(speed_noise=speed_noise, heading_noise=heading_noise)

    @property
    def label(self) -> str:
        """The name of :data:`MODELS` this model is, or ``"custom"``."""
        return next((name for name, m in MODELS.items() if m == self), "custom")

    @property
    def is_white(self) -> bool:
        """Nothing but white noise and a message every epoch (the paper's model)."""
        return self == type(self).white(self.speed_noise, self.heading_noise)

    def schedule(self, t) -> np.ndarray:
        """(T,) bool: epochs of ``t`` [s] with a message generated since the last (0 always)."""
        t = epoch_times(t)
        if self.rate is None:
            return np.ones(t.size, bool)
        n = np.floor((t - t[0]) * self.rate + 1e-9)
        return np.concatenate([[True], n[1:] > n[:-1]])

    def draw(self, t, speed, heading, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """The messages of one drive: ``(speed_msg, heading_msg)`` (T,) from the true ``speed``
        [m/s] and ``heading`` [rad] (T,) at epoch times ``t`` [s], NaN where no message arrived.
        Drawn in order: the white speed and heading noise (T each: all the white model draws),
        then for the terms the model has the scale, bias, yaw-rate bias, walk (T - 1), losses (T)."""
        rng = rng_or_error("rng", rng)
        t = epoch_times(t)
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

#: automotive defaults (``REFERENCES.md``, "Odometry"): 1 % wheel-speed scale factor, 1 deg
#: heading bias at the start, a MEMS gyro's 0.3 deg/sqrt(h) and 10 deg/h, the paper's white
#: noise, CAMs at 10 Hz, 10 % of them lost
AUTOMOTIVE = Odometry(
    speed_scale=0.01, heading_bias=float(np.radians(1.0)), heading_drift=float(np.radians(0.3) / 60),
    yaw_rate_bias=float(np.radians(10.0) / 3600), rate=10.0, dropout=0.1,
)  # fmt: skip


#: the named models (``tunnelkit reproduce javelin-table1|2 --odometry NAME``)
MODELS = {"white": WHITE, "automotive": AUTOMOTIVE}


def epoch_times(t) -> np.ndarray:
    """``t`` [s] checked: a 1-D array of one or more strictly increasing epoch times."""
    t = finite_array("t", t, ndim=1)
    if t.size < 1 or np.any(np.diff(t) <= 0):
        raise ValueError(f"t: expected one or more strictly increasing epoch times, got {t!r:.60}")
    return t
