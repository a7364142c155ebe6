"""The messages a JAVELIN prediction steps on (:data:`~.config.MOTION_STEPS`).

Eq. 62 steps from epoch k-1 into k on the V2X message of k-1, held over the step; on a drive that
turns, the held heading lags the chord by half a step (on the slalom drive 0.33 m RMS of dead
reckoning's error with noise-free messages). ``"midpoint"`` steps on the mean of the messages of
k-1 and k (:func:`midpoint_messages`), the chord's heading on a steady turn. The step's message
is also the velocity the tracker's Doppler test and track management read at epoch k. Where the
message of k-1 or of k is missing the step takes the held one: with messages slower than the
epochs (a 5 Hz odometry at 10 Hz epochs) every step is held, and 10 % of messages lost leave
about a fifth of the steps held. The tracker is told the messages' white noise per step as for
eq. 62 (the mean of two has half the variance, correlated between neighbouring steps).
"""

from __future__ import annotations

import numpy as np

from ..._physical import speeds

__all__ = ["midpoint_messages"]


def midpoint_messages(speed, heading) -> tuple[np.ndarray, np.ndarray]:
    """The V2X messages a ``"midpoint"`` prediction steps on (:data:`~.config.MOTION_STEPS`):
    entry ``k`` of each (T,) is the mean of the messages of epochs ``k`` and ``k + 1`` (the speeds'
    mean, the headings' mean along the shorter arc), so the step from ``k`` into ``k + 1`` reads
    entry ``k`` as eq. 62 reads the message of ``k``. On a steady turn the mean heading is the
    chord's, where the held one lags by half a step. Where either message is missing (NaN), and
    at the last epoch, the message of ``k`` as it is. ``speed`` [m/s], ``heading`` [rad] (T,)."""
    v, th = _messages("speed", speed), _messages("heading", heading)
    if th.shape != v.shape:
        raise ValueError(
            f"speed, heading: expected two arrays of one shape (T,), got {v.shape} and {th.shape}"
        )
    speeds("speed", v[np.isfinite(v)], vectors=False)
    out_v, out_th = v.copy(), th.copy()
    both = np.isfinite(v[:-1]) & np.isfinite(v[1:]) & np.isfinite(th[:-1]) & np.isfinite(th[1:])
    half = np.angle(np.exp(1j * (th[1:] - th[:-1]))) / 2  # half the turn, on the shorter arc
    out_v[:-1] = np.where(both, (v[:-1] + v[1:]) / 2, v[:-1])
    out_th[:-1] = np.where(both, np.angle(np.exp(1j * (th[:-1] + half))), th[:-1])
    return out_v, out_th


def _messages(name: str, x) -> np.ndarray:
    """A V2X series (T,): real numbers, NaN where a message is missing, none infinite."""
    if isinstance(x, str | bytes) or np.asarray(x).dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected real numbers (NaN: a message lost), got {x!r:.40}")
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"{name}: expected one message per epoch (T,), got shape {x.shape}")
    if np.isinf(x).any():
        raise ValueError(f"{name}: contains infinite values (NaN marks a missing message)")
    return x
