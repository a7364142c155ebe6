"""The measurement route of notebooks 03-04: scenario -> propagation -> channel tensor ->
extraction -> Algorithm 1.

:class:`SignalRoute` builds the scenario's objects once and :meth:`SignalRoute.epoch` runs one
SRS slot into an :class:`Epoch` (its ``measurements`` what the trackers take, its ``paths`` the
truth); :func:`simulate_epoch` (:mod:`.oneshot`) does it in a single call. :class:`RouteOptions` holds the route's
switches, :func:`measurements_from_estimates` applies Algorithm 1's checks.

How it works, with a worked call: docs/internals/scenarios.md.
"""

from __future__ import annotations

from .._lazy import lazy_exports

_EXPORTS = {
    "CHANNELS": "route",
    "MAX_SECOND_ORDER": "options",
    "Epoch": "measurements",
    "RouteOptions": "options",
    "SignalRoute": "route",
    "measurements_from_estimates": "measurements",
    "simulate_epoch": "oneshot",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
