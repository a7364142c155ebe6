"""The ray-traced tensor split by what eq. 1's first-order model leaves out.

:func:`tensor_components` splits the noiseless tensor of one traced epoch
(:class:`~tunnelkit.rt.elements.ElementPaths`, :func:`~tunnelkit.rt.elements.element_tensor`)
into parts that sum back to it exactly::

    full = first_order_model + element_doppler + element_gain + wideband + specular2+ + diffuse

* ``diffuse``: every path with a diffuse interaction;
* ``specular2+``: the specular paths of two or more bounces;
* ``wideband``: the spatial-wideband term of the LoS and first-order specular paths (their tensor
  with each element's own delay across the band, minus the same with the reference element's
  delay of that path; the carrier phase per element kept);
* ``element_gain``: what a constant complex gain per path leaves out across the array (the
  1/distance amplitude per element, the reflection coefficient's change with the incidence
  angle, the polarisation projection): the first-order tensor without the wideband term minus
  the same with the reference element's gain (below);
* ``element_doppler``: each element's own Doppler shift of a first-order path (in the near field
  the direction of arrival, hence ``v . u / lambda``, changes across the aperture) against the
  reference element's;
* ``first_order_model``: the LoS and first-order specular paths with the reference element's
  gain, delay and Doppler and the traced carrier phase difference
  ``exp(-j 2 pi fc (tau_m - tau_0))`` per element: eq. 1's atom of each path, as far as the ray
  tracer's paths are whole.

A path is followed across the array by its order and the object of its first bounce; the
reference element is element 0 (the array's reference antenna). A first-order path the reference
element does not see keeps its own delay and gain. :func:`first_order_groups` lists the paths the
reference element sees, with the number of elements that see each: a path off a finite facet or
road marking whose specular point leaves the surface across the aperture is seen by part of the
array only (no diffraction is traced, so its field stops at the shadow boundary), which no
eq. 1 atom fits.
"""

from __future__ import annotations

import numpy as np

from .._physical import carrier
from .._validate import positive
from .elements import ElementPaths, element_tensor

__all__ = ["COMPONENTS", "first_order_groups", "tensor_components"]

#: the parts of :func:`tensor_components` besides ``first_order_model``
COMPONENTS = ("diffuse", "specular2+", "wideband", "element_gain", "element_doppler")


def _check(paths) -> ElementPaths:
    if not isinstance(paths, ElementPaths):
        raise TypeError(f"paths: expected an ElementPaths, got {type(paths).__name__}")
    return paths


def _with(ep: ElementPaths, **kw) -> ElementPaths:
    f = {k: getattr(ep, k) for k in ElementPaths.__dataclass_fields__}
    f.update(kw)
    return ElementPaths(**f)


def first_order_groups(paths: ElementPaths) -> list[dict]:
    """The LoS and first-order specular paths the reference element sees: per path its
    ``slot`` at the reference element, ``order``, ``first_object`` (Sionna's object id), the
    (M, P) mask ``select`` of its slots at every element, the (M,) mask
    ``elements`` of the elements that see it (matched by order and first object) and
    ``count`` = how many do."""
    ep = _check(paths)
    first = ep.mask("los") | ep.mask("specular1")
    out = []
    for j in np.flatnonzero(first[0]):
        same = first & (ep.order == ep.order[0, j]) & (ep.first_object == ep.first_object[0, j])
        out.append(
            {
                "slot": int(j),
                "order": int(ep.order[0, j]),
                "first_object": int(ep.first_object[0, j]),
                "select": same,
                "elements": same.any(axis=1),
                "count": int(same.any(axis=1).sum()),
            }
        )
    return out


def tensor_components(
    paths: ElementPaths,
    fc: float,
    tone_spacing: float,
    n_tones: int,
    symbol_period: float,
    n_symbols: int,
    *,
    amplitude: float = 1.0,
) -> dict[str, np.ndarray]:
    """The parts of the noiseless tensor (module docstring), each (M, Nf, Nt), times
    ``amplitude`` (``sqrt(P_t)`` for a received tensor): ``full``, ``first_order_model`` and
    :data:`COMPONENTS`; they sum to ``full`` up to rounding."""
    ep = _check(paths)
    fc = carrier("fc", fc)
    amp = positive("amplitude", amplitude)
    args = (tone_spacing, n_tones, symbol_period, n_symbols)

    def synth(e, sel):
        return amp * element_tensor(e, *args, select=sel)

    first = ep.mask("los") | ep.mask("specular1")
    tau0, g0, f0 = ep.tau.copy(), ep.gain.copy(), ep.doppler.copy()
    for g in first_order_groups(ep):
        tau0[g["select"]] = ep.tau[0, g["slot"]]
        g0[g["select"]] = ep.gain[0, g["slot"]]
        f0[g["select"]] = ep.doppler[0, g["slot"]]
    model = _with(ep, tau=tau0, gain=g0 * np.exp(-2j * np.pi * fc * (ep.tau - tau0)))
    h1 = synth(ep, first)
    h1_nb = synth(_with(ep, tau=tau0), first)
    h1_gain = synth(model, first)
    out = {
        "full": synth(ep, None),
        "first_order_model": synth(_with(model, doppler=f0), first),
        "diffuse": synth(ep, ep.mask("diffuse")),
        "specular2+": synth(ep, ep.mask("specular2+")),
        "wideband": h1 - h1_nb,
    }
    out["element_gain"] = h1_nb - h1_gain
    out["element_doppler"] = h1_gain - out["first_order_model"]
    return out
