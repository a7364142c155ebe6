"""The measurement route of notebooks 03-04: scenario -> propagation -> channel tensor ->
extraction -> Algorithm 1.

:class:`SignalRoute` builds the scenario's objects once and :meth:`SignalRoute.epoch` runs one
SRS slot into an :class:`Epoch` (its ``measurements`` what the trackers take, its ``paths`` the
truth); :func:`simulate_epoch` does it in a single call. :class:`RouteOptions` holds the route's
switches, :func:`measurements_from_estimates` applies Algorithm 1's checks.

How it works, with a worked call: docs/internals/scenarios.md.
"""

from __future__ import annotations

from .measurements import Epoch, measurements_from_estimates
from .options import RouteOptions
from .route import CHANNELS, MAX_SECOND_ORDER, SignalRoute, simulate_epoch

__all__ = [
    "CHANNELS",
    "MAX_SECOND_ORDER",
    "Epoch",
    "RouteOptions",
    "SignalRoute",
    "measurements_from_estimates",
    "simulate_epoch",
]
