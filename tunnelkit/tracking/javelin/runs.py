"""JAVELIN run from outside the tracker, as the studies run it: a start drawn as the open-sky fix
the tracker's ``P_0`` describes (:func:`draw_start`), and a whole measurement stream in one call
(:func:`run_javelin`). The tracker itself is :class:`~tunnelkit.tracking.javelin.tracker.Javelin`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..._validate import positive, rng_or_error, vector
from .measurement import PathMeasurements
from .roles import JavelinDesign
from .tracker import Javelin, JavelinRun

__all__ = ["draw_start", "run_javelin"]


def draw_start(
    truth, sigma: float, rng: np.random.Generator, sigma_height: float | None = None
) -> np.ndarray:
    """An open-sky fix (3,) [m] drawn from ``N(truth, diag(sigma^2, sigma^2, sigma_height^2))``
    (``sigma_height`` default ``sigma``): the start whose error the tracker's ``P_0``
    (``sigma_p0_ue``, ``sigma_p0_height``) describes, not the truth itself."""
    p = vector("truth", truth, 3)
    s = positive("sigma", sigma)
    sh = s if sigma_height is None else positive("sigma_height", sigma_height)
    rng = rng_or_error("rng", rng)
    return p + np.array([s, s, sh]) * rng.standard_normal(3)


def run_javelin(
    epochs: Sequence[PathMeasurements | None],
    speed,
    heading,
    dt: float,
    initial_position,
    design: JavelinDesign | None = None,
    *,
    keep_reports: bool = False,
) -> JavelinRun:
    """Run :class:`Javelin` (built from ``design``, default the paper's) over a measurement stream.

    ``speed[k]`` / ``heading[k]`` are the V2X message sent at epoch ``k`` (NaN = missing); as in
    Algorithm 4, line 7, the message of epoch ``k-1`` drives the prediction into epoch ``k`` (with
    ``motion_step="midpoint"`` the mean of the messages of ``k-1`` and ``k``: :meth:`Javelin.run`).
    Warnings about faults are collected and counted instead of printed.
    """
    return Javelin(initial_position, design).run(
        epochs, speed, heading, dt, keep_reports=keep_reports
    )
