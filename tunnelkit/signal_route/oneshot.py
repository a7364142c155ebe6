"""One SRS slot of a scenario in a single call (:func:`simulate_epoch`); a loop over epochs
builds a :class:`~tunnelkit.signal_route.route.SignalRoute` once instead."""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from .measurements import Epoch
from .options import RouteOptions
from .route import SignalRoute

__all__ = ["simulate_epoch"]


def simulate_epoch(scenario, k: int, rng: np.random.Generator, **kw) -> Epoch:
    """One-call signal route: ``simulate_epoch("italiano2026-straight", 10, rng).measurements``.

    Keyword arguments go to :class:`SignalRoute` (``kinds``, ``snr_offset_db``, ``options``) or
    to :meth:`SignalRoute.epoch` (``n_paths``, ``tunnel``, ``clock_bias``, extraction options).
    For loops over epochs build a :class:`SignalRoute` once instead.
    """
    moved = sorted(set(kw) & {f.name for f in fields(RouteOptions)})
    if moved:
        raise TypeError(
            f"{', '.join(moved)}: a route option, pass options=RouteOptions({moved[0]}=...)"
        )
    route_kw = {key: kw.pop(key) for key in ("kinds", "snr_offset_db", "options") if key in kw}
    return SignalRoute.from_scenario(scenario, **route_kw).epoch(k, rng, **kw)
