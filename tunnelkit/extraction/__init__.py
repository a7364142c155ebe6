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
    "kruskal_rank": "decomposition",
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
    "refine_joint": "paper",
    "refine_roots": "paper",
    "solve_far_field": "paper",
    "solve_near_field": "paper",
    "unwrap_spatial": "paper",
    "vandermonde_roots": "paper",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
