"""How many antennas before a reflected path stops looking like one point on the wall?

Italiano et al. 2026, section 3.1: the single-reflector near-field (SR-NF) channel model replaces
the wall-reflected path seen by antenna ``m`` (whose true wavefront is centred on the virtual UE,
VUE) by a spherical wave from one point on the wall, the specular point ``p_s0`` of the reference
antenna. The model is valid while the phase mismatch across the array stays below ``eps_phi``.

Geometry (Fig. 2 of the paper): the base station's reference antenna at the origin, the tunnel
axis along x, the reflecting wall the plane ``y = W`` (``W > 0``), the UE at ``(R, y_u, z_u)``
with ``y_u < W``, its VUE at ``(R, 2W - y_u, z_u)``. The ULA lies along y with spacing
``lambda / 2``: ``y_m = m lambda / 2``, ``m = 0 .. M-1``.

What is here:

* the paper's bounds: :func:`mmax_2d` (Theorem 3.1, eq. 25) and :func:`mmax_3d` (Theorem 3.4,
  eq. 37) (:mod:`~tunnelkit.fresnel.bounds`, with the geometry and the corrected and classical
  bounds below);
* the exact mismatch, no expansion: :func:`signed_mismatch`, :func:`mismatch_profile`,
  :func:`phase_mismatch` (ULA), :func:`phase_mismatch_ura` (the URA of section 4.1) and the
  largest admissible array :func:`mmax_exact`, :func:`mmax_exact_grid`, :func:`mmax_exact_ura`
  (:mod:`~tunnelkit.fresnel.exact`, with the proof term by term, :func:`aperture_profile`;
  :func:`signed_mismatch` alone in :mod:`~tunnelkit.fresnel.mismatch`, all a design needs);
* the corrected second-order bound :func:`mmax_nonparaxial`: eq. 41 with the SR model's own
  wavefront curvature kept (eq. 41 as printed drops it) and without the paraxial assumption
  ``|2W - y_u| << R`` behind eq. 28 and eq. 31;
* the classical Fraunhofer distance ``2 D^2 / lambda`` (:func:`fraunhofer_distance`,
  :func:`mmax_fraunhofer`) and a summary/report for design tables and the ``tunnelkit mmax``
  command (:mod:`~tunnelkit.fresnel.summary`).

All functions take SI units (metres, hertz, radians).
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
