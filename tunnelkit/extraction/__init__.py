"""Channel-parameter extraction from the SRS tensor (Italiano et al. 2026, eq. 11-24, Algorithm 1).

One module per stage, :func:`extract_paths` (:mod:`.extract`) in front:

- :mod:`.decomposition` — the CP decomposition of ``H`` (eq. 3, 11, 12) with tensorly, rank checks;
- :mod:`.paper` — the paper's route from CPD factors to path parameters (eq. 13-24, Algorithm 1);
- :mod:`.coherent` — paths the CPD merged, separated by the array (beyond the paper);
- :mod:`.ml` — the joint maximum-likelihood fit of eq. 1 at the Cramér-Rao bound, started from
  the two above (the default route of :func:`extract_paths`);
- :mod:`.bounds` — Cramér-Rao bounds of the eq. 1 model;
- :mod:`.estimates` — :class:`PathEstimates`, the container every route returns;
- below them all, :mod:`.numerics` (the solvers, contractions and scans the stages share) and
  :mod:`.radio` (the ``array`` and ``srs`` arguments, checked).

Every entry point that reads the tensor takes the radio as ``(..., array, srs, ...)``: ``array``
a :class:`tunnelkit.arrays.ArrayGeometry` (or (M, 3) local element positions), ``srs`` a
:class:`tunnelkit.channel.SRSConfig` (carrier, tone spacing, symbol period)::

    est = extract_paths(H, n_paths, array, srs)                   # the ML route
    est = extract_paths(H, n_paths, array, srs, refine="joint")   # the paper's

``H`` follows eq. 1 exactly as printed (spatial phase ``+2 pi fc/c delta``, frequency phase
``-2 pi s Df tau``, time phase ``+2 pi k f_d T0``).
"""

from __future__ import annotations

from .bounds import crlb_paths, estimate_crlb, ml_truth, path_crlb
from .decomposition import (
    CPDConvergenceWarning,
    CPDResult,
    check_rank,
    check_tensor,
    cp_rel_error,
    cpd,
    kruskal_rank,
    max_identifiable_rank,
    normalize_factors,
)
from .estimates import PathEstimates, path_estimates
from .extract import ROUTES, extract_paths
from .numerics import MIN_SIGNIFICANCE
from .paper import (
    algorithm1,
    angles_from_solution,
    paper_route,
    refine_joint,
    refine_roots,
    solve_far_field,
    solve_near_field,
    unwrap_spatial,
    vandermonde_roots,
)

__all__ = [
    "MIN_SIGNIFICANCE",
    "ROUTES",
    "CPDConvergenceWarning",
    "CPDResult",
    "PathEstimates",
    "algorithm1",
    "angles_from_solution",
    "check_rank",
    "check_tensor",
    "cp_rel_error",
    "cpd",
    "crlb_paths",
    "estimate_crlb",
    "extract_paths",
    "kruskal_rank",
    "max_identifiable_rank",
    "ml_truth",
    "normalize_factors",
    "paper_route",
    "path_crlb",
    "path_estimates",
    "refine_joint",
    "refine_roots",
    "solve_far_field",
    "solve_near_field",
    "unwrap_spatial",
    "vandermonde_roots",
]
