"""Paths by the image method: LoS plus one specular reflection per surface, with the exact length
to every antenna and the SR-NF lengths for comparison (the model and the sign conventions:
docs/internals/channel-and-propagation.md), and, on request (``order=2``), the second-order specular
paths of :mod:`tunnelkit.propagation.second_order`. The :class:`~tunnelkit.propagation.path.Path`
record: :mod:`tunnelkit.propagation.path`."""

from __future__ import annotations

import numpy as np

from .._validate import integer, sequence, vector
from ..arrays import ArrayGeometry
from .path import Path, make_path, trace_arguments
from .surfaces import Tunnel3D

__all__ = ["select_array", "trace_paths"]


def trace_paths(
    tunnel: Tunnel3D,
    array: ArrayGeometry,
    ue,
    ue_velocity=(0.0, 0.0, 0.0),
    *,
    fc: float,
    kinds: tuple[str, ...] = ("los", "wall", "ceiling", "road", "rrm"),
    front_only: bool = True,
    order: int = 1,
) -> list[Path]:
    """All single-bounce paths from ``ue`` to ``array`` (image method), LoS first; with
    ``order=2`` the second-order specular paths after them
    (:func:`~tunnelkit.propagation.second_order.second_order_paths`, both
    surfaces' kinds in ``kinds``), sorted by length.

    A reflection off surface S exists when UE and array are on S's inner side, the segment from
    the reference antenna to the VUE crosses S inside the finite rectangle, and neither leg is
    blocked. With ``front_only`` paths arriving from behind the array face (local z <= 0) are
    dropped (the elements' back lobe). ``kinds`` selects the path families. Reflected paths are
    sorted by length after the LoS path.
    """
    order = integer("order", order, minimum=1, maximum=2)
    fc, kinds, front_only, ue, vel = trace_arguments(
        tunnel, array, ue, ue_velocity, fc, kinds, front_only
    )
    a0 = array.origin
    out: list[Path] = []
    if "los" in kinds and not tunnel._blocked(ue, a0) and (not front_only or array.in_front(ue)):
        out.append(make_path("los", "", "los", ue, ue, ue, vel, array, fc, 1.0))
    refl = []
    for s in tunnel.surfaces:
        if s.kind not in kinds:
            continue
        pl = s.plane
        du, da = float(pl.signed_distance(ue)), float(pl.signed_distance(a0))
        if du <= 0 or da <= 0:
            continue
        vue = pl.mirror(ue)
        point = a0 + da / (da + du) * (vue - a0)  # where reference-antenna -> VUE crosses S
        if not s._contains(point, 1e-9):
            continue
        if tunnel._blocked(ue, point) or tunnel._blocked(point, a0):
            continue
        if front_only and not array.in_front(point):
            continue
        cos_i = min(du / float(np.linalg.norm(ue - point)), 1.0)  # rounding may give 1 + 1e-16
        gamma = s.reflection_coefficient(fc, cos_i)
        vvue = vel - 2.0 * (vel @ pl.normal) * pl.normal
        refl.append(make_path("reflection", s.name, s.kind, vue, point, ue, vvue, array, fc, gamma))
    refl.sort(key=lambda p: p.length)
    if order == 2:
        from .second_order import trace_second_order

        refl += trace_second_order(tunnel, array, ue, vel, fc, kinds, front_only)
    return out + refl


def select_array(arrays, ue) -> ArrayGeometry:
    """The array whose boresight points most towards ``ue`` (the one the vehicle drives into)."""
    arrays = sequence("arrays", arrays)
    ue = vector("ue", ue, 3)
    for i, a in enumerate(arrays):
        if not isinstance(a, ArrayGeometry):
            raise TypeError(
                f"arrays[{i}]: expected an arrays.ArrayGeometry, got {type(a).__name__}"
            )
    scores = [float(a.boresight @ (ue - a.origin)) for a in arrays]
    return arrays[int(np.argmax(scores))]
