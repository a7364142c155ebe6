"""The measurement route of notebooks 03-04: scenario -> propagation -> channel tensor -> extraction -> Algorithm 1.

:class:`SignalRoute` builds the scenario's objects once; :meth:`SignalRoute.epoch` traces the paths
of one SRS slot (:mod:`tunnelkit.propagation`), synthesises the tensor with noise and clock bias
(:mod:`tunnelkit.channel`), extracts the path parameters (:mod:`tunnelkit.extraction`) and applies
Algorithm 1's checks (:func:`measurements_from_estimates`). Matching estimates to the truth lives in
:mod:`tunnelkit.evaluation`. In one line::

    import numpy as np
    from tunnelkit import signal_route
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")   # build once
    ep = route.epoch(k=10, rng=np.random.default_rng(0))                     # one SRS slot
    ep.measurements.z            # eq. 54: [phi; psi; kappa; Delta d] of the kept paths
    ep.measurements.origin       # world position of the array's reference antenna
    ep.paths                     # ground truth (tunnelkit.propagation.Path list)

or ``signal_route.simulate_epoch("italiano2026-straight", 10, rng)`` for a single call. Angles in
``ep.measurements`` (a :class:`tunnelkit.tracking.javelin.PathMeasurements`, what the trackers
take) are world-frame azimuth/elevation (eq. 46-47, 49-50) seen from ``origin``.

The package's modules follow its jobs: :mod:`~tunnelkit.signal_route.measurements` (Algorithm 1's
world-frame measurements of one epoch and the covariance the extraction reports),
:mod:`~tunnelkit.signal_route.route` (:class:`SignalRoute`: propagation -> channel ->
extraction), :mod:`~tunnelkit.signal_route.options` (:class:`RouteOptions`, the route's switches) and :mod:`~tunnelkit.signal_route.judging` (a fit judged against noise plus the impairment power
the route was told about).
"""

from __future__ import annotations

from .measurements import Epoch, measurements_from_estimates, reported_covariance
from .options import RouteOptions
from .route import CHANNELS, MAX_SECOND_ORDER, SignalRoute, simulate_epoch

__all__ = [
    "CHANNELS",
    "MAX_SECOND_ORDER",
    "Epoch",
    "RouteOptions",
    "SignalRoute",
    "measurements_from_estimates",
    "reported_covariance",
    "simulate_epoch",
]
