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
  :class:`MonteCarloResult`); :mod:`~tunnelkit.design.fastroute`: the bound-driven drive
  (how it weighs the paths and the error that follows: :mod:`~tunnelkit.design.trackerfix`);
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

from .._lazy import lazy_exports

_EXPORTS = {
    "PredictedError": "achievable",
    "path_error_model": "achievable",
    "predicted_error": "achievable",
    "START_HEIGHT_SIGMA_M": "arrayjob",
    "design_planes": "arrayjob",
    "javelin_config": "arrayjob",
    "RouteBounds": "bounds",
    "path_bounds": "bounds",
    "route_bounds": "bounds",
    "route_geometry": "bounds",
    "ConfirmedReport": "confirm",
    "confirm_on_channel": "confirm",
    "confirmation_candidates": "confirm",
    "START_SIGMA_M": "trackerfix",
    "drive_bound": "drivebound",
    "drive_pcrlb": "drivebound",
    "position_bias_rms": "drivebound",
    "position_information": "drivebound",
    "unit_pcrlb": "drivebound",
    "PathErrorModel": "errormodel",
    "BoundRoute": "trackerfix",
    "bound_drive": "fastroute",
    "bound_route": "fastroute",
    "KINDS": "geometry",
    "RouteGeometry": "geometry",
    "trace_route": "geometry",
    "DesignImpairments": "impairments",
    "preset_impairments": "impairments",
    "IMPAIRMENT_PRESETS": "impairments:PRESETS",
    "MODES": "trackerfix",
    "MonteCarloResult": "montecarlo",
    "SETTLE_S": "montecarlo",
    "STARTS": "montecarlo",
    "sweep_montecarlo": "montecarlo",
    "DesignReport": "records",
    "DesignRow": "records",
    "over_target": "records",
    "design_sweep": "report",
    "smallest_meeting": "report",
    "ArraySpec": "setup",
    "DesignSetup": "setup",
    "Mount": "setup",
    "parse_array": "setup",
    "unit_quantiles": "units",
    "unit_yield": "units",
    "wilson_interval": "units",
    "CRITERIA": "verdict",
    "MIN_RUNS_CI": "verdict",
    "STATUSES": "verdict",
    "bootstrap_quantile_ci": "verdict",
    "cluster_quantile_ci": "verdict",
    "counted_epochs": "verdict",
    "gate": "verdict",
    "judge": "verdict",
    "recommend": "verdict",
    "share_quantile": "verdict",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
