"""Size an antenna array for a tunnel: bounds, predicted error, the tracker's Monte-Carlo over
manufactured units and a recommendation by unit yield.

For every candidate array (ULA ``n``, URA ``n x m``, spacing in wavelengths) placed at the
scenario's base-station mount (refused if an element lies outside the cross-section), along the
scenario's route, the design computes the exact SR-NF validity of every path, the ideal position
error bound (PEB, a bound), the predicted error under the stated impairments (a first-order
misspecified-model prediction, not a bound), and the Monte-Carlo of the design's tracker over
manufactured units, one calibration draw each, with the bounds over the drive beside it; a
candidate is met when the share of units that meet the target on their own (the unit yield)
reaches the required yield with 95 % confidence. One job per module:

* :mod:`~tunnelkit.design.setup`: candidate arrays (:class:`ArraySpec`, :func:`parse_array`)
  and the scenario reduced to tunnel, mounts, route and radio (:class:`DesignSetup`);
* :mod:`~tunnelkit.design.geometry`: the image method for a whole route at once
  (:func:`trace_route`, :class:`RouteGeometry`);
* :mod:`~tunnelkit.design.bounds`: exact SR-NF validity, the PEB from the joint Fisher
  information of eq. 1 and the per-path CRLBs (:func:`route_bounds`, :func:`path_bounds`);
* :mod:`~tunnelkit.design.impairments` and :mod:`~tunnelkit.design.achievable`: impairments as
  design inputs (:class:`DesignImpairments`), the extraction's per-path error model along the
  route (:func:`path_error_model`, :class:`PathErrorModel`) and the predicted position error
  beside the PEB (:func:`predicted_error`; its misspecified part is :mod:`~tunnelkit.design.mcrb`);
* :mod:`~tunnelkit.design.drivebound`: over the drive, every unit's posterior CRLB and the one
  pooled over units (:func:`unit_pcrlb`, bounds) and the tracker's predicted error
  (:func:`drive_bound`, a prediction);
* :mod:`~tunnelkit.design.montecarlo` (with :mod:`~tunnelkit.design.arrayjob`, what one array's
  drives share and one drive): JAVELIN on the design, every array x drive of a batch as one
  task set on the full signal chain or the bound-driven route (:func:`sweep_montecarlo`,
  :class:`MonteCarloResult`); :mod:`~tunnelkit.design.fastroute`: the bound-driven drive;
  :mod:`~tunnelkit.design.traced`: the channel route on the ray-traced channel;
* :mod:`~tunnelkit.design.units`: manufactured units (their generators) and the unit yield
  with its Wilson interval; :mod:`~tunnelkit.design.verdict`: the criterion, the error quantile
  with its interval, the verdict by the yield and the recommendation (:func:`judge`,
  :func:`recommend`);
* :mod:`~tunnelkit.design.report` and :mod:`~tunnelkit.design.records`: the sweep with its
  sequential rule and its table (:func:`design_sweep`, :class:`DesignReport`).

    >>> import tunnelkit as tk
    >>> setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    >>> b = tk.design.route_bounds(setup, "10x10")
    >>> float(np.median(b.peb)), b.srnf_valid.mean()          # doctest: +SKIP
"""

from __future__ import annotations

from .achievable import DesignImpairments, PredictedError, path_error_model, predicted_error
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
from .impairments import PRESETS as IMPAIRMENT_PRESETS
from .impairments import preset_impairments
from .montecarlo import (
    MODES,
    SETTLE_S,
    START_HEIGHT_SIGMA_M,
    START_SIGMA_M,
    STARTS,
    MonteCarloResult,
    javelin_config,
    sweep_montecarlo,
)
from .report import DesignReport, DesignRow, design_sweep, over_target, smallest_meeting
from .setup import ArraySpec, DesignSetup, Mount, parse_array
from .units import unit_quantiles, unit_yield, wilson_interval
from .verdict import (
    CRITERIA,
    MIN_RUNS_CI,
    STATUSES,
    bootstrap_quantile_ci,
    cluster_quantile_ci,
    counted_epochs,
    gate,
    judge,
    recommend,
    share_quantile,
)

__all__ = [
    "CRITERIA",
    "IMPAIRMENT_PRESETS",
    "KINDS",
    "MIN_RUNS_CI",
    "MODES",
    "SETTLE_S",
    "STARTS",
    "START_HEIGHT_SIGMA_M",
    "START_SIGMA_M",
    "STATUSES",
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
    "PredictedError",
    "RouteBounds",
    "RouteGeometry",
    "bootstrap_quantile_ci",
    "bound_drive",
    "bound_route",
    "cluster_quantile_ci",
    "confirm_on_channel",
    "confirmation_candidates",
    "counted_epochs",
    "design_planes",
    "design_sweep",
    "drive_bound",
    "drive_pcrlb",
    "gate",
    "javelin_config",
    "judge",
    "over_target",
    "parse_array",
    "path_bounds",
    "path_error_model",
    "position_bias_rms",
    "position_information",
    "predicted_error",
    "preset_impairments",
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
