"""Eq. 1 with each path on the elements that see it: the ray-traced channel's per-element
visibility, as a model.

The tracer traces every element on its own, and a first-order reflection reaches an element only
where the element's specular point falls on the facet (no diffraction is traced, so the field
stops at the edge). The attribution study found this the largest single cost of eq. 1's fit
(``docs/results/traced-attribution.md``): a ceiling path cut by the ridge above the array, a
road marking seen by part of the array, and a second ceiling facet that the reference element
does not see but the other elements do, which the image method (listing the paths at the
reference element) leaves out. Here eq. 1 is given that geometry:

* :func:`element_visibility`: which elements see a reflection off one facet (the image method per
  element: the segment from the element to the VUE crosses the facet inside its rectangle and
  neither leg is blocked);
* :func:`visible_paths`: the masks (M, L) of the listed paths, and the paths of the facets the
  reference element misses but some element sees, with theirs;
* :class:`MaskedProblem`: eq. 1 with a fixed 0/1 profile per path over the elements
  (:class:`~.aperture.ApertureProblem` with its profile fixed instead of fitted: no parameter
  more per path).

The masks need the UE's position: the truth for the pseudo-true bias, a predicted one
(:func:`predicted_model`, a tracker's prediction) for the noisy fits; a prediction's error moves
a mask only where an element's specular point is within it of an edge.
Measured by :func:`tunnelkit.studies.nuisance.traced_bias` (models ``visibility`` and
``visibility-second-order-N``).
"""

from __future__ import annotations

import numpy as np

from ..._physical import carrier
from ..._validate import boolean, finite_array, instance, integer, probability, sequence
from ...arrays import ArrayGeometry
from ...propagation import PATH_KINDS, SECOND_ORDER, Facet, Path, Tunnel3D, trace_paths
from ...propagation.path import make_path
from ...propagation.second_order import bounce_points_unchecked, second_order_path_unchecked
from .aperture import ApertureProblem

__all__ = [
    "MaskedProblem",
    "element_visibility",
    "predicted_model",
    "visible_paths",
    "visible_second_order",
]


def element_visibility(tunnel, surface, ue, elements) -> np.ndarray:
    """(M,) bool: the elements (world positions (M, 3)) that receive ``ue``'s first-order
    reflection off ``surface`` (a facet of ``tunnel``), by the image method at each element."""
    instance("tunnel", tunnel, Tunnel3D)
    instance("surface", surface, Facet)
    ue = finite_array("ue", ue, shape=(3,))
    el = finite_array("elements", elements, shape=(None, 3))
    return _visibility(tunnel, surface, ue, el)


def _visibility(tunnel, surface, ue: np.ndarray, el: np.ndarray) -> np.ndarray:
    """:func:`element_visibility` on checked arguments."""
    pl = surface.plane
    du, da = float(pl.signed_distance(ue)), pl.signed_distance(el)
    if du <= 0:
        return np.zeros(len(el), bool)
    vue = pl.mirror(ue)
    front = da > 0
    q = el + (np.where(front, da, 0.0) / (np.where(front, da, 0.0) + du))[:, None] * (vue - el)
    return front & surface.contains(q) & ~tunnel.blocked(ue, q) & ~tunnel.blocked(q, el)


def visible_paths(
    tunnel, array, paths, ue, ue_velocity, fc: float, min_share: float = 0.25, kinds=PATH_KINDS
) -> tuple[list, np.ndarray]:
    """The masks of ``paths`` (first-order, traced at ``array``'s reference element) and the
    first-order paths at least ``min_share`` of the elements see that the list lacks: ``(extra,
    masks)``, ``extra`` the missing facets' :class:`~tunnelkit.propagation.Path` (as at the
    reference element, from the VUE), ``masks`` (M, len(paths) + len(extra)) float 0/1 in that
    order. The line of sight's mask is the elements it reaches unblocked. A facet fewer elements
    see is left out: too few elements place no atom (one element carries no direction); so is a
    facet whose kind is not in ``kinds`` or whose plane the reference element is behind."""
    instance("tunnel", tunnel, Tunnel3D)
    instance("array", array, ArrayGeometry)
    ue = finite_array("ue", ue, shape=(3,))
    vel = finite_array("ue_velocity", ue_velocity, shape=(3,))
    fc = carrier("fc", fc)
    min_share = probability("min_share", min_share)
    kinds = sequence("kinds", kinds)
    if not set(kinds) <= set(PATH_KINDS):
        raise ValueError(f"kinds: expected path kinds of {PATH_KINDS}, got {kinds!r}")
    paths = sequence("paths", paths)
    if not all(isinstance(p, Path) for p in paths):
        raise TypeError("paths: expected the traced first-order Paths of one epoch")
    faces = {s.name: s for s in tunnel.surfaces}
    if any(p.kind not in ("los", "reflection") for p in paths):
        raise ValueError("paths: expected first-order paths (the line of sight, one reflection)")
    if any(p.kind != "los" and p.surface not in faces for p in paths):
        raise ValueError("paths: a reflection off a surface the tunnel does not have")
    el = array.world
    masks = [
        ~tunnel.blocked(ue, el)
        if p.kind == "los"
        else _visibility(tunnel, faces[p.surface], ue, el)
        for p in paths
    ]
    listed, extra = {p.surface for p in paths}, []
    for s in tunnel.surfaces:
        if s.name in listed or s.kind not in kinds:
            continue
        seen, pl = _visibility(tunnel, s, ue, el), s.plane
        du, da = float(pl.signed_distance(ue)), float(pl.signed_distance(array.origin))
        if seen.mean() < min_share or da <= 0:
            continue
        vue = pl.mirror(ue)
        point = array.origin + da / (da + du) * (vue - array.origin)
        gamma = s.reflection_coefficient(fc, min(du / float(np.linalg.norm(ue - point)), 1.0))
        v_vue = vel - 2.0 * (vel @ pl.normal) * pl.normal
        extra.append(
            make_path("reflection", s.name, s.kind, vue, point, ue, v_vue, array, fc, gamma)
        )
        masks.append(seen)
    return extra, np.column_stack(masks).astype(float)


def visible_second_order(
    tunnel, array, ue, ue_velocity, fc: float, n: int, min_share: float = 0.25, kinds=PATH_KINDS
) -> tuple[list, np.ndarray]:
    """The ``n`` strongest second-order specular paths at least ``min_share`` of ``array``'s
    elements receive, each with the elements that do: ``(paths, masks)``, ``masks`` (M, n) float
    0/1. Unlike ``trace_paths(order=2)``, which checks each bounce at the reference element only,
    a path is kept when enough elements see it, whether the reference element does or not (its
    :class:`~tunnelkit.propagation.Path` then as at the reference element, from its source, the
    UE mirrored twice); strongest by the magnitude of that path's gain, as ``trace_paths``'s are
    ranked by :func:`predicted_model`."""
    instance("tunnel", tunnel, Tunnel3D)
    instance("array", array, ArrayGeometry)
    ue = finite_array("ue", ue, shape=(3,))
    vel = finite_array("ue_velocity", ue_velocity, shape=(3,))
    fc = carrier("fc", fc)
    n = integer("n", n, minimum=0, maximum=64)
    min_share = probability("min_share", min_share)
    kinds = sequence("kinds", kinds)
    if not set(kinds) <= set(PATH_KINDS):
        raise ValueError(f"kinds: expected path kinds of {PATH_KINDS}, got {kinds!r}")
    el, a0 = array.world, array.origin[None]
    surf = [s for s in tunnel.surfaces if s.kind in kinds]
    found = []
    for s1 in surf:
        for s2 in surf:
            if s2 is s1:
                continue
            ok, _, q2 = bounce_points_unchecked(tunnel, s1, s2, ue, el)
            seen = ok & array.in_front(q2)
            if seen.mean() < min_share:
                continue
            _, q1, q2 = bounce_points_unchecked(tunnel, s1, s2, ue, a0, every_point=True)
            path = second_order_path_unchecked(s1, s2, ue, vel, q1[0], q2[0], array, fc)
            found.append((abs(path.gain), path, seen))
    found.sort(key=lambda f: -f[0])
    found = found[:n]
    masks = (
        np.column_stack([f[2] for f in found]).astype(float) if found else np.zeros((len(el), 0))
    )
    return [f[1] for f in found], masks


def predicted_model(
    route, array, ue, ue_velocity, second_order: int = 0, *, element_second_order: bool = False
) -> tuple:
    """The visibility model at a UE position ``ue`` (a tracker's prediction): the first-order paths
    traced there to ``array`` (the route's path kinds), the facets part of the array sees
    (:func:`visible_paths`) and the ``second_order`` strongest second-order paths (those the
    reference element sees, on every element, as ``RouteOptions(second_order=N)`` picks them; with
    ``element_second_order`` each on the elements that see it, :func:`visible_second_order`):
    ``(paths, masks, n_first)``, the paths in that order, ``masks`` (M, len(paths)), ``n_first``
    the first-order paths listed."""
    if not hasattr(route, "tunnel") or not hasattr(route, "kinds"):
        raise TypeError(f"route: expected a SignalRoute, got {type(route).__name__}")
    n2 = integer("second_order", second_order, minimum=0, maximum=64)
    by_element = boolean("element_second_order", element_second_order)
    fc = route.config.fc
    every = trace_paths(route.tunnel, array, ue, ue_velocity, fc=fc, kinds=route.kinds,
                        order=2 if n2 and not by_element else 1)  # fmt: skip
    first = [p for p in every if p.kind != SECOND_ORDER]
    extra, masks = visible_paths(route.tunnel, array, first, ue, ue_velocity, fc, kinds=route.kinds)
    if by_element:
        second, m2 = visible_second_order(route.tunnel, array, ue, ue_velocity, fc, n2,
                                          kinds=route.kinds)  # fmt: skip
    else:
        second = sorted((p for p in every if p.kind == SECOND_ORDER), key=lambda p: -abs(p.gain))
        second = second[:n2]
        m2 = np.ones((array.M, len(second)))
    return first + extra + second, np.column_stack([masks, m2]), len(first)


class MaskedProblem(ApertureProblem):
    """The tensor ``H`` (M, Nf, Nt), the array (local positions (M, 3)), the carrier ``fc`` and
    ``mask`` (M, L): eq. 1 with path ``l``'s atom multiplied by ``mask[:, l]`` (its visibility
    over the elements, :func:`visible_paths`); every path's parameters and gain as in eq. 1. With
    a mask of ones it is eq. 1's :class:`~tunnelkit.extraction.ml.model.Problem` (tested)."""

    def __init__(self, H, element_positions, fc: float, mask):
        super().__init__(H, element_positions, fc, order=0)
        self.mask = finite_array("mask", mask, shape=(self.M, None))
        if self.mask.shape[1] < 1 or np.any((self.mask < 0) | (self.mask > 1)):
            raise ValueError("mask: expected one column of weights in [0, 1] per path")

    def _check(self, theta, mu_f, mu_t, beta=None) -> tuple:
        out = super()._check(theta, mu_f, mu_t, beta)
        if out[0].shape[0] != self.mask.shape[1]:
            raise ValueError(
                f"theta: expected one path per mask column ({self.mask.shape[1]}), got "
                f"{out[0].shape[0]}"
            )
        return out

    def _profile(self, beta: np.ndarray) -> np.ndarray:
        return self.mask
