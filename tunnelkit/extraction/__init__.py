"""Channel-parameter extraction from the SRS tensor (Italiano et al. 2026, eq. 11-24, Algorithm 1).

:func:`extract_paths` runs a route: the paper's (:mod:`.paper`, from the CPD of
:mod:`.decomposition`), the coherent split (:mod:`.coherent`) or, by default, the joint
maximum-likelihood fit (:mod:`.ml`); every route returns a :class:`PathEstimates`, and
:mod:`.bounds` holds the Cramér-Rao bounds. :mod:`.direct` fits the ray-traced channel with every
atom tied to one UE position (the design's direct tracker). Entry points take the radio as
``(..., array, srs, ...)``. ``H`` follows eq. 1 exactly as printed (spatial phase
``+2 pi fc/c delta``, frequency phase ``-2 pi s Df tau``, time phase ``+2 pi k f_d T0``).

How it works: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

from .._lazy import lazy_exports

_EXPORTS = {
    "crlb_paths": "bounds",
    "estimate_crlb": "bounds",
    "ml_truth": "bounds",
    "path_crlb": "bounds",
    "CPDConvergenceWarning": "decomposition",
    "CPDResult": "decomposition",
    "check_rank": "decomposition",
    "check_tensor": "decomposition",
    "cp_rel_error": "decomposition",
    "cpd": "decomposition",
    "kruskal_rank": "krank",
    "max_identifiable_rank": "decomposition",
    "normalize_factors": "decomposition",
    "PathEstimates": "estimates",
    "path_estimates": "estimates",
    "ROUTES": "extract",
    "extract_paths": "extract",
    "MIN_SIGNIFICANCE": "numerics",
    "algorithm1": "paper",
    "angles_from_solution": "paper",
    "paper_route": "paper",
    "refine_joint": "joint",
    "refine_roots": "paper",
    "solve_far_field": "paper",
    "solve_near_field": "paper",
    "unwrap_spatial": "paper",
    "vandermonde_roots": "paper",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
