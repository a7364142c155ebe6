"""Joint maximum-likelihood path extraction on the full eq. 1 model (ours, beyond Italiano et al.
2026): variable projection with Levenberg-Marquardt, a basin test on the noise floor, a residual
test (the GLRT of one path more) and SAGE / RIMAX-like re-seedings.

Main names: :func:`ml_paths` (the extraction), :func:`fit_ml` and :class:`MLFit` (one fit and its
verdict), :class:`Problem` and :class:`WidebandProblem` (the models), the residual test
(:func:`residual_peak`, :func:`calibrated_threshold`) and the resolution tests
(:func:`separations`, :func:`pair_test`, :func:`snr_threshold`, :func:`below_threshold`);
every name loads on first use (the wideband model only where it is asked for).

How it works: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

from ..._lazy import lazy_exports

_EXPORTS = {
    "MAX_ITER": "fitting",
    "MLConvergenceWarning": "fitting",
    "MLDetectionWarning": "fitting",
    "MLFit": "fitting",
    "SEARCHES": "fitting",
    "fit_problem": "fitting",
    "check_start": "given_start",
    "fit_ml": "given_start",
    "Problem": "model",
    "noise_floor": "model",
    "project_feasible": "model",
    "ml_order": "order",
    "estimates_from_fit": "paths",
    "ml_paths": "paths",
    "physical": "paths",
    "complete_paths": "rank_one",
    "search_path": "rank_one",
    "FALSE_ALARM": "residual",
    "calibrated_threshold": "residual",
    "peak_null": "residual",
    "peak_threshold": "residual",
    "residual_peak": "residual",
    "OUTLIER_RATE": "resolution",
    "PAIR_FALSE_ALARM": "resolution",
    "PAIR_LLR": "resolution",
    "PAIR_TEST_Z": "resolution",
    "RESOLVE_Z": "resolution",
    "below_threshold": "resolution",
    "outlier_probability": "resolution",
    "separations": "resolution",
    "snr_threshold": "resolution",
    "closest_pair": "resolved",
    "pair_separation": "resolved",
    "pair_test": "resolved",
    "resolvable": "resolved",
    "path_from_peak": "search",
    "start_from_estimates": "search",
    "WidebandProblem": "wideband",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
