"""The direct fit: the ray-traced channel's tensor fitted with every atom tied to one UE position.

Eq. 1 gives each path its own angles, delay and curvature; on the ray-traced channel those are
biased by what the tracer models and eq. 1 does not (``docs/results/traced-attribution.md``).
This package fits the tensor with the geometry instead:

- :mod:`.aperture` — eq. 1 with each path's amplitude varying across the array
  (:class:`~.aperture.ApertureProblem`; order 0 is eq. 1 itself);
- :mod:`.visibility` — each path on the elements that see it (the per-element image method,
  :class:`~.visibility.MaskedProblem`, :func:`~.visibility.predicted_model`);
- :mod:`.fit` — every atom of that model tied to one UE position, one clock bias and one speed
  (:func:`~.fit.direct_fix`), with diffuse atoms admitted by a test against the noise.

Under the tracker (the design's ``--traced-tracker direct``): :mod:`tunnelkit.design.traceddirect`.
Measured in ``docs/results/traced-models.md``. Every name loads on first use.
"""

from __future__ import annotations

from ..._lazy import lazy_exports

_EXPORTS = {
    "MAX_ORDER": "aperture",
    "ApertureProblem": "aperture",
    "taper_basis": "aperture",
    "MaskedProblem": "visibility",
    "element_visibility": "visibility",
    "predicted_model": "visibility",
    "visible_paths": "visibility",
    "visible_second_order": "visibility",
    "DirectFix": "fit",
    "DirectProblem": "fit",
    "diffuse_share": "fit",
    "diffuse_start": "fit",
    "diffuse_threshold": "fit",
    "direct_fix": "fit",
    "image_maps": "fit",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
