"""Size an antenna array for a tunnel: bounds, predicted error, the tracker's Monte-Carlo over
manufactured units and a recommendation by unit yield.

Main names: :class:`DesignSetup` and :func:`parse_array` (the inputs), :func:`route_bounds`
(SR-NF validity, PEB, per-path CRLBs), :func:`predicted_error`, :func:`sweep_montecarlo`,
:func:`judge` and :func:`recommend`, and :func:`design_sweep` with its :class:`DesignReport`.

How it works, and which module does each job: docs/internals/design.md.

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
    "route_bounds": "bounds",
    "route_geometry": "bounds",
    "path_bounds": "pathbounds",
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
    "over_target": "render",
    "design_sweep": "report",
    "smallest_meeting": "explore",
    "ArraySpec": "setup",
    "DesignSetup": "setup",
    "Mount": "setup",
    "parse_array": "setup",
    "unit_quantiles": "units",
    "unit_rmse": "units",
    "unit_yield": "units",
    "wilson_interval": "units",
    "CRITERIA": "verdict",
    "DRIVES_PER_UNIT": "verdict",
    "MAX_UNITS": "verdict",
    "MIN_RUNS_CI": "verdict",
    "REQUIRED_YIELD": "verdict",
    "STATUSES": "verdict",
    "bootstrap_quantile_ci": "intervals",
    "cluster_quantile_ci": "intervals",
    "paired_rmse_ratio": "intervals",
    "rmse_ci": "intervals",
    "counted_epochs": "verdict",
    "gate": "verdict",
    "judge": "verdict",
    "recommend": "verdict",
    "share_quantile": "verdict",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
