"""Builders of Jiang et al. (2023)'s scenarios: the 2-D tunnel of two wall lines and the
piecewise-constant-acceleration trajectory (registered as ``walls2d`` and
``piecewise_acceleration``)."""

from __future__ import annotations

import itertools

import numpy as np

from ..schema import ScenarioError
from ..tunnel2d import Tunnel2D
from .registry import Trajectory, register_trajectory, register_tunnel

__all__: list[str] = []


@register_tunnel("walls2d")
def _walls2d(sec: dict, get) -> Tunnel2D:
    walls = get("walls", shape=(2, 3))
    try:
        return Tunnel2D.from_lines(walls[0], walls[1])
    except ValueError as exc:
        raise ScenarioError(f"tunnel.walls: {exc}") from None


@register_trajectory("piecewise_acceleration")
def _piecewise(sec: dict, get, tunnel) -> Trajectory:
    """Constant acceleration per segment, given in the tunnel frame (along, across) [m/s^2].

    ``start`` [m] and ``velocity`` [m/s] are in global (x, y); ``segments = [[duration, a_along,
    a_across], ...]``; samples every ``period`` seconds for ``steps`` samples.
    """
    start = get("start", shape=(2,))
    vel = get("velocity", shape=(2,))
    period = get("period")
    steps = get("steps", int)
    if period <= 0:
        raise ScenarioError("trajectory.period: must be > 0")
    if steps < 2:
        raise ScenarioError("trajectory.steps: must be >= 2")
    segs = get("segments", shape=(None, 3), default=np.zeros((0, 3)))
    if np.any(segs[:, 0] <= 0) if len(segs) else False:
        raise ScenarioError("trajectory.segments: durations must be > 0")
    t = np.arange(steps) * period
    # acceleration as a function of time (zero after the last segment)
    edges = np.concatenate([[0.0], np.cumsum(segs[:, 0])]) if len(segs) else np.array([0.0])
    acc_tf = np.zeros((steps, 2))
    for (t0, t1), (_, a_al, a_ac) in zip(itertools.pairwise(edges), segs):
        acc_tf[(t >= t0) & (t < t1)] = (a_al, a_ac)
    if isinstance(tunnel, Tunnel2D):
        basis = np.stack([tunnel.axis, tunnel.across])  # rows: along, across
    else:
        basis = np.eye(2)
    acc = acc_tf @ basis
    # exact integration of piecewise-constant acceleration on the sample grid
    vel_t = np.vstack([vel, vel + np.cumsum(acc[:-1] * period, axis=0)])
    pos = np.vstack(
        [start, start + np.cumsum(vel_t[:-1] * period + 0.5 * acc[:-1] * period**2, axis=0)]
    )
    if isinstance(tunnel, Tunnel2D) and not np.all(tunnel.contains(pos)):
        k = int(np.argmin(tunnel.contains(pos)))
        raise ScenarioError(
            f"trajectory: leaves the tunnel at sample {k} (t = {t[k]:.2f} s, position {pos[k]})"
        )
    return Trajectory(t=t, position=pos, velocity=vel_t)
