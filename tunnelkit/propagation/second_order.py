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


def bounce_points_unchecked(
    tunnel, s1, s2, ue: np.ndarray, receivers: np.ndarray, every_point: bool = False
) -> tuple:
    """Where the second-order path off ``s1`` then ``s2`` from ``ue`` (3,) reaches each of the
    ``receivers`` (N, 3) (unchecked: the tracer's and the visibility study's inner step):
    ``(ok, q1, q2)``, ``ok`` (N,) the image method's checks of :func:`second_order_paths`
    (receiver, ``V1`` and UE on the surfaces' inner sides, both bounces inside their rectangles
    and in front of each other, no leg blocked), ``q1``/``q2`` (N, 3) the bounce points (where a
    check fails, those of the distances clipped at zero: the reference element's geometry of a
    path other elements see, with ``every_point``). With the UE or its image ``V1`` not on the
    inner sides (no receiver sees the path) ``q1`` and ``q2`` are the UE itself. Without
    ``every_point`` the checks stop as soon as no receiver is left (the tracer calls it for one
    receiver per pair of surfaces), and ``q1``/``q2`` of a receiver that fails mean nothing."""
    p1, p2 = s1.plane, s2.plane
    n1, o1, n2, o2 = p1.normal, p1.offset, p2.normal, p2.offset  # Plane's formulas, unchecked
    du = float(ue @ n1 + o1)
    v1 = ue - 2.0 * du * n1
    dv = float(v1 @ n2 + o2)
    if du <= 0 or dv <= 0:
        at_ue = np.tile(ue, (len(receivers), 1))
        return np.zeros(len(receivers), bool), at_ue, at_ue
    da = receivers @ n2 + o2
    ok = da > 0
    if not (every_point or ok.any()):
        return ok, receivers, receivers
    a = np.where(ok, da, 0.0)
    q2 = receivers + (a / (a + dv))[:, None] * (v1 - 2.0 * dv * n2 - receivers)  # -> V2 on S2
    e2 = q2 @ n1 + o1
    b = np.where(e2 > 0, e2, 0.0)
    q1 = q2 + (b / (b + du))[:, None] * (v1 - q2)  # P2 -> V1 crosses S1
    ok &= e2 > 0
    for test in (
        lambda: s2._contains(q2, 1e-9),
        lambda: s1._contains(q1, 1e-9),
        lambda: q1 @ n2 + o2 > 0,
        lambda: ~tunnel._blocked(ue, q1),
        lambda: ~tunnel._blocked(q1, q2),
        lambda: ~tunnel._blocked(q2, receivers),
    ):
        if not ok.any():
            break
        ok &= test()
    return ok, q1, q2


def second_order_path_unchecked(s1, s2, ue, vel, q1, q2, array, fc: float) -> Path:
    """The second-order :class:`Path` off ``s1`` then ``s2`` from ``ue`` moving at ``vel`` with
    bounce points ``q1`` and ``q2`` (3,) (:func:`bounce_points_unchecked` at the reference element), to
    ``array`` at the carrier ``fc`` (unchecked): its source the UE mirrored twice, its
    reflection coefficient the product of both bounces' at their incidences, its velocity the
    UE's mirrored twice."""
    p1, p2 = s1.plane, s2.plane
    du = float(p1.signed_distance(ue))
    leg1, leg2 = float(np.linalg.norm(ue - q1)), float(np.linalg.norm(q1 - q2))
    g1 = s1.reflection_coefficient(fc, min(du / max(leg1, 1e-9), 1.0))
    g2 = s2.reflection_coefficient(
        fc, min(max(float(p2.signed_distance(q1)), 0.0) / max(leg2, 1e-9), 1.0)
    )
    vel1 = vel - 2.0 * (vel @ p1.normal) * p1.normal
    vel2 = vel1 - 2.0 * (vel1 @ p2.normal) * p2.normal
    v2 = p2.mirror(p1.mirror(ue))
    return make_path(SECOND_ORDER, f"{s1.name} > {s2.name}", SECOND_ORDER, v2, q2, ue, vel2,
                     array, fc, complex(g1 * g2), leg=leg1 + leg2)  # fmt: skip


def trace_second_order(tunnel, array, ue, vel, fc, kinds, front_only) -> list[Path]:
    """:func:`second_order_paths` on checked arguments."""
    a0 = array.origin[None]
    surf = [s for s in tunnel.surfaces if s.kind in kinds]
    out: list[Path] = []
    for s1 in surf:
        for s2 in surf:
            if s2 is s1:
                continue
            ok, q1, q2 = bounce_points_unchecked(tunnel, s1, s2, ue, a0)
            if not ok[0] or (front_only and not array.in_front(q2[0])):
                continue
            out.append(second_order_path_unchecked(s1, s2, ue, vel, q1[0], q2[0], array, fc))
    out.sort(key=lambda p: p.length)
    return out
