"""How many antennas before a reflected path stops looking like one point on the wall? The
validity of the single-reflector near-field (SR-NF) model of Italiano et al. 2026, section 3.1.

The paper's bounds :func:`mmax_2d` (Theorem 3.1, eq. 25) and :func:`mmax_3d` (Theorem 3.4,
eq. 37); the exact mismatch (:func:`signed_mismatch`, :func:`phase_mismatch`,
:func:`phase_mismatch_ura`) and the largest admissible array (:func:`mmax_exact`,
:func:`mmax_exact_ura`); the corrected bound :func:`mmax_nonparaxial`; the Fraunhofer distance
(:func:`fraunhofer_distance`) and :func:`mmax_summary`. All functions take SI units.

How it works: docs/internals/channel-and-propagation.md.
"""

from __future__ import annotations

from .._lazy import lazy_exports

_EXPORTS = {
    "SECTION_4_1_TILT": "bounds",
    "aperture": "bounds",
    "fraunhofer_distance": "bounds",
    "mmax_2d": "bounds",
    "mmax_3d": "bounds",
    "mmax_fraunhofer": "bounds",
    "mmax_nonparaxial": "bounds",
    "paraxial_ratio": "bounds",
    "reference_specular_point": "bounds",
    "ula_positions": "bounds",
    "ura_positions": "bounds",
    "vue": "bounds",
    "ApertureProfile": "exact",
    "M_LIMIT": "exact",
    "M_LIMIT_URA": "exact",
    "aperture_profile": "exact",
    "mismatch_profile": "exact",
    "mmax_exact": "exact",
    "mmax_exact_grid": "exact",
    "mmax_exact_ura": "exact",
    "phase_mismatch": "exact",
    "phase_mismatch_ura": "exact",
    "signed_mismatch": "mismatch",
    "FC_PRESETS": "summary",
    "MmaxSummary": "summary",
    "design_report": "summary",
    "mmax_summary": "summary",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
