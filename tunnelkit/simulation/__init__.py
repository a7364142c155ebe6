"""The drive simulator: the chain run along whole drives, above the trackers and below the design.

``drives`` (the one drive simulator and the adapter from extracted paths to tracker
measurements) · ``variants`` (a preset's drive over another length) · ``reextract`` (an epoch
redone by the coherent or the ML route) · ``scoring`` (JAVELIN / TeNFiLoc on a drive, error
metrics, settled errors) · ``baselines`` (TeNFiLoc's fixes, the drive without its radio) ·
``collect`` (seeded drives on the Monte-Carlo runner) · ``analysis`` (ablation, extraction errors
per kind of path, VUE prediction errors). Notebooks 04 and 04b, ``tunnelkit reproduce
javelin-table1|2`` and the array design (``tunnelkit design``) use them.
"""

from __future__ import annotations

from .._lazy import lazy_exports

_EXPORTS = {
    "ablation": "analysis",
    "ablation_path": "analysis",
    "error_correlations": "analysis",
    "error_samples": "analysis",
    "extraction_errors": "analysis",
    "path_errors": "analysis",
    "vue_prediction_errors": "analysis",
    "ml_epoch": "reextract",
    "separate_epoch": "reextract",
    "tenfiloc_track": "baselines",
    "without_radio": "baselines",
    "collect_drives": "collect",
    "collect_routes": "collect",
    "per_drive": "collect",
    "simulate_condition": "collect",
    "CONDITIONS": "drives",
    "Condition": "drives",
    "DriveData": "drives",
    "EXTRACTIONS": "drives",
    "HELD_OUT_SEED": "drives",
    "SIGMA_HEADING": "drives",
    "SIGMA_SPEED": "drives",
    "TUNING_SEEDS": "drives",
    "path_measurements": "drives",
    "route_name": "drives",
    "scenario_route": "drives",
    "simulate_drive": "drives",
    "simulate_routes": "drives",
    "Evaluation": "scoring",
    "SETTLE_S": "scoring",
    "error_metrics": "scoring",
    "evaluate": "scoring",
    "settled": "scoring",
    "settled_errors": "scoring",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
