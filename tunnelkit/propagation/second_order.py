"""The second-order specular paths (image method): the UE mirrored in one surface, then that
image mirrored in another (ceiling then road, wall then wall, ...), each bounce checked inside its
finite surface; what :func:`~tunnelkit.propagation.paths.trace_paths` adds with ``order=2``."""

from __future__ import annotations

import numpy as np

from ..arrays import ArrayGeometry
from .path import SECOND_ORDER, Path, make_path, trace_arguments
from .surfaces import Tunnel3D

__all__ = ["second_order_paths"]


def second_order_paths(
    tunnel: Tunnel3D,
    array: ArrayGeometry,
    ue,
    ue_velocity=(0.0, 0.0, 0.0),
    *,
    fc: float,
    kinds: tuple[str, ...] = ("wall", "ceiling", "road", "rrm"),
    front_only: bool = True,
) -> list[Path]:
    """The second-order specular paths from ``ue`` to ``array`` (image method), sorted by length.

    For every ordered pair of distinct surfaces (S1, S2) whose kinds are in ``kinds``: the UE's
    image in S1, ``V1``, mirrored in S2 gives the source ``V2``. The path exists when the UE and
    the array are on the inner sides of S1 and S2 respectively and ``V1`` on S2's inner side, the
    line from the reference antenna to ``V2`` crosses S2 inside its rectangle (point ``P2``), the
    line from ``P2`` to ``V1`` crosses S1 inside its rectangle (``P1``) with ``P2`` on S1's
    inner side and ``P1`` on S2's, and no leg (UE-P1, P1-P2, P2-array) is blocked. Its length is
    ``||V2 - p_m||`` at antenna ``m`` (= ``|UE P1| + |P1 P2| + |P2 p_m|`` at the reference
    antenna), its reflection coefficient the product of both bounces' (:meth:`Facet.reflection_coefficient`
    at each incidence), its source velocity the UE's mirrored twice.
    """
    fc, kinds, front_only, ue, vel = trace_arguments(
        tunnel, array, ue, ue_velocity, fc, kinds, front_only
    )
    return trace_second_order(tunnel, array, ue, vel, fc, kinds, front_only)


def trace_second_order(tunnel, array, ue, vel, fc, kinds, front_only) -> list[Path]:
    """:func:`second_order_paths` on checked arguments."""
    a0 = array.origin
    surf = [s for s in tunnel.surfaces if s.kind in kinds]
    out: list[Path] = []
    for s1 in surf:
        p1 = s1.plane
        du = float(p1.signed_distance(ue))
        if du <= 0:
            continue
        v1 = p1.mirror(ue)
        vel1 = vel - 2.0 * (vel @ p1.normal) * p1.normal
        for s2 in surf:
            if s2 is s1:
                continue
            p2 = s2.plane
            da, dv = float(p2.signed_distance(a0)), float(p2.signed_distance(v1))
            if da <= 0 or dv <= 0:
                continue
            v2 = p2.mirror(v1)
            q2 = a0 + da / (da + dv) * (v2 - a0)  # the reference antenna -> V2 crosses S2
            if not s2._contains(q2, 1e-9):
                continue
            e2 = float(p1.signed_distance(q2))
            if e2 <= 0:
                continue
            q1 = q2 + e2 / (e2 + du) * (v1 - q2)  # P2 -> V1 crosses S1
            if not s1._contains(q1, 1e-9) or float(p2.signed_distance(q1)) <= 0:
                continue
            if tunnel._blocked(ue, q1) or tunnel._blocked(q1, q2) or tunnel._blocked(q2, a0):
                continue
            if front_only and not array.in_front(q2):
                continue
            leg1, leg2 = float(np.linalg.norm(ue - q1)), float(np.linalg.norm(q1 - q2))
            g1 = s1.reflection_coefficient(fc, min(du / leg1, 1.0))
            g2 = s2.reflection_coefficient(fc, min(float(p2.signed_distance(q1)) / leg2, 1.0))
            vel2 = vel1 - 2.0 * (vel1 @ p2.normal) * p2.normal
            out.append(
                make_path(
                    SECOND_ORDER,
                    f"{s1.name} > {s2.name}",
                    SECOND_ORDER,
                    v2,
                    q2,
                    ue,
                    vel2,
                    array,
                    fc,
                    complex(g1 * g2),
                    leg=leg1 + leg2,
                )
            )
    out.sort(key=lambda p: p.length)
    return out
