"""The drive simulator: the chain run along whole drives, above the trackers and below the design.

``drives`` (the one drive simulator and the adapter from extracted paths to tracker
measurements) · ``scoring`` (JAVELIN / TeNFiLoc on a drive, error metrics, settled errors) ·
``collect`` (seeded drives on the Monte-Carlo runner) · ``analysis`` (ablation, extraction errors
per kind of path, VUE prediction errors). Notebooks 04 and 04b, ``tunnelkit reproduce
javelin-table1|2`` and the array design (``tunnelkit design``) use them.
"""

from __future__ import annotations

from .analysis import (
    ablation,
    error_correlations,
    extraction_errors,
    path_errors,
    vue_prediction_errors,
)
from .collect import collect_drives, collect_routes, per_drive, simulate_condition
from .drives import (
    CONDITIONS,
    EXTRACTIONS,
    HELD_OUT_SEED,
    SIGMA_HEADING,
    SIGMA_SPEED,
    TUNING_SEEDS,
    Condition,
    DriveData,
    ml_epoch,
    path_measurements,
    route_name,
    scenario_route,
    separate_epoch,
    simulate_drive,
    simulate_routes,
)
from .scoring import (
    SETTLE_S,
    Evaluation,
    error_metrics,
    evaluate,
    settled,
    settled_errors,
    tenfiloc_track,
)

__all__ = [
    "CONDITIONS",
    "EXTRACTIONS",
    "HELD_OUT_SEED",
    "SETTLE_S",
    "SIGMA_HEADING",
    "SIGMA_SPEED",
    "TUNING_SEEDS",
    "Condition",
    "DriveData",
    "Evaluation",
    "ablation",
    "collect_drives",
    "collect_routes",
    "error_correlations",
    "error_metrics",
    "evaluate",
    "extraction_errors",
    "ml_epoch",
    "path_errors",
    "path_measurements",
    "per_drive",
    "route_name",
    "scenario_route",
    "separate_epoch",
    "settled",
    "settled_errors",
    "simulate_condition",
    "simulate_drive",
    "simulate_routes",
    "tenfiloc_track",
    "vue_prediction_errors",
]
