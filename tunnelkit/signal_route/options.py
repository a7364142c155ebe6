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
    (the paper's SR-NF approximation, :func:`tunnelkit.channel.synthesize`).
    ``second_order`` (0: the first-order model): the route's model also carries the
    ``second_order`` strongest second-order specular paths the image method predicts at each
    epoch (:func:`tunnelkit.propagation.second_order_paths`, by ``|gain|`` at the reference
    antenna; fewer when fewer exist). They are in ``Epoch.paths`` after the first-order ones, so
    the extraction fits them (``L`` = first-order + second-order paths) and, on the image
    channel, they are synthesised too; they are nuisance paths for the tracker: the estimates
    matched to them (by range and direction, :func:`tunnelkit.evaluation.match_paths`, against
    the geometry's prediction, as ``L`` itself is) are left out of the measurements.
    ``report_covariance``: each epoch's measurements carry the CRLB at the estimate
    (:func:`~tunnelkit.signal_route.measurements.reported_covariance`), what the ML route's error
    follows.
    ``bias_aware_delay_check``: Algorithm 1 drops only ``d < -c b_max`` (the clock bias's
    support) instead of the printed ``d < 0`` (:func:`tunnelkit.extraction.algorithm1`).
    ``wideband_model``: the extraction models the spatial-wideband term (the ML route's
    ``wideband=True``, :func:`tunnelkit.extraction.extract_paths`) in every epoch.
    ``diffuse_floor`` (ray-traced channel only): the ML extraction judges its own fit
    (``fit_ok``: residual, periodogram peak, significance) against the noise power plus the
    epoch's diffuse power (the ray tracer's mean power per element of the paths with a diffuse
    interaction, times the transmit power; :meth:`SignalRoute.ml_noise_power`) instead of the
    noise alone: the diffuse paths as a known noise-like nuisance. The fitted parameters are the
    same least-squares fit; only the tests and the re-seeding they trigger change.
    ``model_error_floor``: an ML fit that fails its white-noise test (``fit_ok = False``) is
    judged again against noise plus the impairment power the route was told about (its
    ``impairments``: the diffuse share and the calibration levels'
    :func:`~tunnelkit.signal_route.judging.calibration_floor`, the share one drawn array leaves at
    a 1 % false-alarm rate over the draw; nothing to re-judge when
    :func:`~tunnelkit.signal_route.judging.impairment_share` is zero, nor when the extraction
    models the wideband term), ``Epoch.rejudged`` the test and ``Epoch.fit_ok`` its verdict; a
    fit that passes it reports the CRLB at its estimate
    (:func:`~tunnelkit.signal_route.measurements.reported_covariance` with ``judged=False``).
    ``bias_budget`` (a :class:`~tunnelkit.signal_route.judging.BiasBudget` over the route's
    epochs, None by default): every epoch's reported covariances get the budget of the slot
    each estimate matches (:func:`~tunnelkit.signal_route.judging.apply_budget`; by direction
    and delay) and its repeating share as ``bias_cov``.
    ``centroid_unresolved`` (with ``report_covariance``): a path whose curvature its reported
    covariance (the budget included) leaves unresolved is reported as a far-field path seen from
    the array's centroid (under a calibration error an unresolved curvature is biased the same
    way every epoch and, seen from the reference antenna at the array's corner, moves every
    direction with it; :func:`tunnelkit.signal_route.route._centroid_far_field`).

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
