"""Size an antenna array for a tunnel: bounds, achievable accuracy, the tracker's Monte-Carlo and
a recommendation from what the system achieves.

For every candidate array (ULA ``n``, URA ``n x m``, spacing in wavelengths) placed at the
scenario's base-station mount (refused if an element lies outside the cross-section), along the
scenario's route, the design computes the exact SR-NF validity of every path, the ideal position
error bound (PEB), the achievable (misspecified) bound under the stated impairments, and the
Monte-Carlo error of the design's tracker; a candidate is met when the 95 % interval of its error
quantile lies below the target. One job per module:

* :mod:`~tunnelkit.design.setup`: candidate arrays (:class:`ArraySpec`, :func:`parse_array`)
  and the scenario reduced to tunnel, mounts, route and radio (:class:`DesignSetup`);
* :mod:`~tunnelkit.design.geometry`: the image method for a whole route at once
  (:func:`trace_route`, :class:`RouteGeometry`);
* :mod:`~tunnelkit.design.bounds`: exact SR-NF validity, the PEB from the joint Fisher
  information of eq. 1 and the per-path CRLBs (:func:`route_bounds`, :func:`path_bounds`);
* :mod:`~tunnelkit.design.achievable`: impairments as design inputs
  (:class:`DesignImpairments`), the extraction's per-path error model along the route
  (:func:`path_error_model`, :class:`PathErrorModel`) and the achievable (misspecified) position
  bound beside the PEB (:func:`achievable_bound`); the misspecified bound itself is
  :mod:`~tunnelkit.design.mcrb`;
* :mod:`~tunnelkit.design.montecarlo`: JAVELIN on the design, every array x run as one task
  set on the full signal chain or the bound-driven route (:func:`sweep_montecarlo`,
  :class:`MonteCarloResult` with the posterior CRLB and the bound over the drive with the bias
  that does not average down, :func:`drive_bound`; :func:`javelin_rmse` for one array,
  :mod:`~tunnelkit.design.onearray`); :mod:`~tunnelkit.design.fastroute`: the bound-driven
  drive (:func:`bound_drive`, its per-array share computed once by :func:`bound_route`);
  :mod:`~tunnelkit.design.traced`: the channel route on the ray-traced channel (the geometry
  pre-filter and each array's own traced errors, cached with their provenance);
* :mod:`~tunnelkit.design.verdict`: the criterion, the error quantile with its bootstrap
  interval, the verdict per array and the recommendation (:func:`judge`, :func:`recommend`);
* :mod:`~tunnelkit.design.report`: the sweep and its table (:func:`design_sweep`,
  :func:`smallest_meeting`).

    >>> import tunnelkit as tk
    >>> setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    >>> b = tk.design.route_bounds(setup, "10x10")
    >>> float(np.median(b.peb)), b.srnf_valid.mean()          # doctest: +SKIP
"""

from __future__ import annotations

from .achievable import AchievableBound, DesignImpairments, achievable_bound, path_error_model
from .arrayjob import design_planes
from .bounds import RouteBounds, path_bounds, route_bounds, route_geometry
from .confirm import ConfirmedReport, confirm_on_channel, confirmation_candidates
from .drivebound import (
    drive_bound,
    drive_pcrlb,
    position_bias_rms,
    position_information,
    unit_pcrlb,
)
from .errormodel import PathErrorModel
from .fastroute import BoundRoute, bound_drive, bound_route
from .geometry import KINDS, RouteGeometry, trace_route
from .montecarlo import (
    MODES,
    SETTLE_S,
    START_HEIGHT_SIGMA_M,
    START_SIGMA_M,
    STARTS,
    VUES,
    MonteCarloResult,
    javelin_config,
    sweep_montecarlo,
)
from .onearray import javelin_rmse
from .report import DesignReport, DesignRow, design_sweep, over_target, smallest_meeting
from .setup import ArraySpec, DesignSetup, Mount, parse_array
from .units import unit_quantiles, unit_yield, wilson_interval
from .verdict import (
    CRITERIA,
    MIN_RUNS_CI,
    STATUSES,
    bootstrap_quantile_ci,
    counted_epochs,
    gate,
    implied_quantile,
    judge,
    recommend,
    share_quantile,
)

__all__ = [
    "CRITERIA",
    "KINDS",
    "MIN_RUNS_CI",
    "MODES",
    "SETTLE_S",
    "STARTS",
    "START_HEIGHT_SIGMA_M",
    "START_SIGMA_M",
    "STATUSES",
    "VUES",
    "AchievableBound",
    "ArraySpec",
    "BoundRoute",
    "ConfirmedReport",
    "DesignImpairments",
    "DesignReport",
    "DesignRow",
    "DesignSetup",
    "MonteCarloResult",
    "Mount",
    "PathErrorModel",
    "RouteBounds",
    "RouteGeometry",
    "achievable_bound",
    "bootstrap_quantile_ci",
    "bound_drive",
    "bound_route",
    "confirm_on_channel",
    "confirmation_candidates",
    "counted_epochs",
    "design_planes",
    "design_sweep",
    "drive_bound",
    "drive_pcrlb",
    "gate",
    "implied_quantile",
    "javelin_config",
    "javelin_rmse",
    "judge",
    "over_target",
    "parse_array",
    "path_bounds",
    "path_error_model",
    "position_bias_rms",
    "position_information",
    "recommend",
    "route_bounds",
    "route_geometry",
    "share_quantile",
    "smallest_meeting",
    "sweep_montecarlo",
    "trace_route",
    "unit_pcrlb",
    "unit_quantiles",
    "unit_yield",
    "wilson_interval",
]
