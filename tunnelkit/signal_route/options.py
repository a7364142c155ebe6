"""How a :class:`~tunnelkit.signal_route.SignalRoute` synthesises, extracts and reports
(:class:`RouteOptions`): one record of switches, all off by default (eq. 1, the paper's route).

A lesson builds a route without it; the design's route and the studies of the ray-traced channel
set the few they need, e.g. ``SignalRoute.from_scenario(name, options=RouteOptions(
report_covariance=True))`` or, on an existing route, ``route.with_options(second_order=2)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

from .._validate import boolean, choice, instance, integer

__all__ = ["MAX_SECOND_ORDER", "RouteOptions"]

#: the most second-order paths a route models (:attr:`RouteOptions.second_order`)
MAX_SECOND_ORDER = 32


@dataclass(frozen=True)
class RouteOptions:
    """A route's switches (all off by default).

    ``model``: the image channel's synthesis model, ``"exact"`` (eq. 1, default) or ``"srnf"``
    (:func:`tunnelkit.channel.synthesize`).
    ``second_order``: how many of the strongest second-order specular paths the route's model adds
    at each epoch (0: the first-order model); nuisance paths, left out of the measurements.
    ``report_covariance``: each epoch's measurements carry the CRLB at the estimate.
    ``bias_aware_delay_check``: Algorithm 1 drops only ``d < -c b_max`` instead of ``d < 0``.
    ``wideband_model``: the extraction models the spatial-wideband term in every epoch.
    ``diffuse_floor`` (ray-traced channel only): the ML fit is judged against the noise plus the
    epoch's diffuse power.
    ``model_error_floor``: a fit that fails its white-noise test is judged again against the noise
    plus the impairment power the route was told about.
    ``bias_budget`` (a :class:`~tunnelkit.signal_route.judging.BiasBudget`): its repeating share
    goes into each reported covariance as ``bias_cov``.
    ``centroid_unresolved`` (with ``report_covariance``): a path with an unresolved curvature is
    reported as a far-field path seen from the array's centroid.
    What each switch does, in full: docs/internals/scenarios.md.

    >>> RouteOptions(second_order=-1)
    Traceback (most recent call last):
    ...
    ValueError: second_order: must be >= 0, got -1
    """

    model: str = "exact"
    second_order: int = 0
    report_covariance: bool = False
    bias_aware_delay_check: bool = False
    wideband_model: bool = False
    diffuse_floor: bool = False
    model_error_floor: bool = False
    bias_budget: object = field(default=None, repr=False, compare=False)
    centroid_unresolved: bool = False

    def __post_init__(self) -> None:
        choice("model", self.model, ("exact", "srnf"))
        integer("second_order", self.second_order, minimum=0, maximum=MAX_SECOND_ORDER)
        for f in fields(self):
            if f.type == "bool":
                boolean(f.name, getattr(self, f.name))
        if self.bias_budget is not None:
            from .judging import BiasBudget

            instance("bias_budget", self.bias_budget, BiasBudget)
