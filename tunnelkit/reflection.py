"""Where a path reflects off a plane: the specular point of a source and a target
(:func:`specular_point`) and the reflection point of a UE and its virtual UE
(:func:`reflector_point`, Italiano et al. 2026, eq. 45), on :class:`tunnelkit.geometry.Plane`."""

from __future__ import annotations

import numpy as np

from ._validate import finite_array, instance, vector
from .geometry import Plane

__all__ = ["reflector_point", "specular_point"]


def specular_point(source, target, plane: Plane) -> np.ndarray:
    """The point on ``plane`` where a ray from ``source`` reflects towards ``target``.

    It is where the segment from ``target`` to the mirror image of ``source`` crosses the plane.
    Both points must lie strictly on the same side of the plane. Vectorised over ``target``.
    """
    instance("plane", plane, Plane)
    src = vector("source", source, plane.dim)
    tgt = plane._points("target", target)
    ds = float(plane.signed_distance(src))
    dt = plane.signed_distance(tgt)
    if ds == 0.0:
        raise ValueError("source: lies on the reflecting plane, no specular reflection exists")
    if np.any(dt * ds <= 0):
        raise ValueError("target: must lie strictly on the same side of the plane as source")
    img = plane.mirror(src)
    t = (ds / (ds + dt))[..., None]  # fraction along img -> target where the plane is crossed
    return img + t * (tgt - img)


def reflector_point(p_u, p_v, p_bs=None) -> np.ndarray:
    """Reflection point of the path whose virtual UE is ``p_v`` (Italiano eq. 45).

    The reflecting plane is the perpendicular bisector of UE and VUE; the reflection point is
    where the straight line from the base station (origin by default) to the VUE crosses it:
    ``p_r = p_bs + t (p_v - p_bs)`` with ``n . p_r = n . (p_u + p_v) / 2``. With the base station
    at the origin this is eq. 45 exactly. Vectorised over leading axes.
    """
    pu = finite_array("p_u", p_u)
    pv = finite_array("p_v", p_v)
    if pu.shape[-1:] != pv.shape[-1:] or pu.shape[-1] not in (2, 3):
        raise ValueError(
            f"p_u, p_v: expected matching 2-D or 3-D points, got {pu.shape} and {pv.shape}"
        )
    bs = np.zeros(pu.shape[-1]) if p_bs is None else vector("p_bs", p_bs, pu.shape[-1])
    n = pv - pu
    nn = np.linalg.norm(n, axis=-1, keepdims=True)
    if np.any(nn == 0):
        raise ValueError("p_v: coincides with p_u, the reflecting plane is undefined")
    n = n / nn
    mid = 0.5 * (pu + pv)
    denom = np.sum(n * (pv - bs), axis=-1, keepdims=True)
    if np.any(np.abs(denom) < 1e-12):
        raise ValueError("p_v: the base station-to-VUE line is parallel to the reflecting plane")
    t = np.sum(n * (mid - bs), axis=-1, keepdims=True) / denom
    return bs + t * (pv - bs)
