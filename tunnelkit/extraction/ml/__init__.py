"""Joint maximum-likelihood path extraction on the full eq. 1 model (ours, beyond Italiano et al.
2026): variable projection with Levenberg-Marquardt, a basin test on the noise floor, a residual
test (the GLRT of one path more) and SAGE / RIMAX-like re-seedings.

Main names: :func:`ml_paths` (the extraction), :func:`fit_ml` and :class:`MLFit` (one fit and its
verdict), :class:`Problem` and :class:`WidebandProblem` (the models), the residual test
(:func:`residual_peak`, :func:`calibrated_threshold`) and the resolution tests
(:func:`separations`, :func:`pair_test`, :func:`snr_threshold`, :func:`below_threshold`).

How it works: docs/internals/extraction-ml.md.
"""

from ..numerics import spatial_phase
from .fitting import (
    MAX_ITER,
    SEARCHES,
    MLConvergenceWarning,
    MLDetectionWarning,
    MLFit,
    fit_ml,
    fit_problem,
    pair_separation,
)
from .model import Problem, noise_floor, project_feasible
from .paths import estimates_from_fit, ml_order, ml_paths, physical
from .residual import FALSE_ALARM, calibrated_threshold, peak_null, peak_threshold, residual_peak
from .resolution import (
    OUTLIER_RATE,
    PAIR_FALSE_ALARM,
    PAIR_LLR,
    PAIR_TEST_Z,
    RESOLVE_Z,
    below_threshold,
    closest_pair,
    outlier_probability,
    pair_test,
    resolvable,
    separations,
    snr_threshold,
)
from .search import (
    check_start,
    complete_paths,
    path_from_peak,
    search_path,
    start_from_estimates,
)
from .wideband import WidebandProblem

__all__ = [
    "FALSE_ALARM",
    "MAX_ITER",
    "OUTLIER_RATE",
    "PAIR_FALSE_ALARM",
    "PAIR_LLR",
    "PAIR_TEST_Z",
    "RESOLVE_Z",
    "SEARCHES",
    "MLConvergenceWarning",
    "MLDetectionWarning",
    "MLFit",
    "Problem",
    "WidebandProblem",
    "below_threshold",
    "calibrated_threshold",
    "check_start",
    "closest_pair",
    "complete_paths",
    "estimates_from_fit",
    "fit_ml",
    "fit_problem",
    "ml_order",
    "ml_paths",
    "noise_floor",
    "outlier_probability",
    "pair_separation",
    "pair_test",
    "path_from_peak",
    "peak_null",
    "peak_threshold",
    "physical",
    "project_feasible",
    "residual_peak",
    "resolvable",
    "search_path",
    "separations",
    "snr_threshold",
    "spatial_phase",
    "start_from_estimates",
]
