"""Lines, planes, mirror images and the angles of a direction.

One class, :class:`Plane`, serves both dimensions: in 2-D it is the line ``A x + B y + C = 0``
(Jiang's tunnel walls), in 3-D the plane ``n . p + c = 0`` (the JAVELIN facets). Everything is
vectorised over leading axes of the points, so a whole trajectory or a grid of positions is
mirrored in one call.

A virtual UE (VUE, Italiano et al. 2026) is the UE mirrored in a reflecting surface; Jiang et al.
2023's virtual stations (the base station mirrored in a wall, eq. 3-4) and their 2-D tunnel are in
:mod:`tunnelkit.tunnel2d`. By reciprocity the two pictures give the same reflected path length.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._validate import finite_array, instance, real, text, vector

__all__ = [
    "Plane",
    "line",
    "mirror",
    "reflector_point",
    "specular_point",
    "spherical",
    "spherical_jacobian",
]


def spherical(q) -> np.ndarray:
    """Azimuth, elevation and range of the offsets ``q`` (..., 3) (Italiano eq. 46-47): the
    ``(phi, psi, r)`` a base station measures towards a point ``q`` away from it."""
    q = finite_array("q", q)
    rho = np.hypot(q[..., 0], q[..., 1])
    return np.stack(
        [np.arctan2(q[..., 1], q[..., 0]), np.arctan2(q[..., 2], rho), np.linalg.norm(q, axis=-1)],
        axis=-1,
    )


def spherical_jacobian(q) -> np.ndarray:
    """d(phi, psi, r) / dq of :func:`spherical`, shape (..., 3, 3) (rows: azimuth, elevation,
    range). Undefined on the vertical axis (``q_x = q_y = 0``), where it raises."""
    q = finite_array("q", q)
    rho2 = q[..., 0] ** 2 + q[..., 1] ** 2
    if np.any(rho2 < 1e-18):
        raise ValueError("q: a point on the vertical axis has no azimuth")
    rho = np.sqrt(rho2)
    r2 = rho2 + q[..., 2] ** 2
    J = np.zeros((*q.shape[:-1], 3, 3))
    J[..., 0, 0] = -q[..., 1] / rho2
    J[..., 0, 1] = q[..., 0] / rho2
    J[..., 1, 0] = -q[..., 2] * q[..., 0] / (rho * r2)
    J[..., 1, 1] = -q[..., 2] * q[..., 1] / (rho * r2)
    J[..., 1, 2] = rho / r2
    J[..., 2, :] = q / np.sqrt(r2)[..., None]
    return J


@dataclass(frozen=True)
class Plane:
    """The hyperplane ``normal . p + offset = 0`` in 2-D (a line) or 3-D (a plane).

    ``normal`` need not be unit length on input; it is stored normalised together with ``offset``
    so that :meth:`signed_distance` is a true distance.
    """

    normal: np.ndarray
    offset: float
    name: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        n = finite_array("normal", self.normal, ndim=1)
        if n.shape[0] not in (2, 3):
            raise ValueError(f"normal: expected 2 or 3 components, got {n.shape[0]}")
        big = float(np.max(np.abs(n)))  # scaled first: no overflow of the norm
        if big == 0.0:
            raise ValueError("normal: degenerate plane, all coefficients are zero (A = B = 0)")
        norm = float(np.linalg.norm(n / big))
        off = real("offset", self.offset)
        text("name", self.name, empty=True)
        object.__setattr__(self, "normal", n / big / norm)
        object.__setattr__(self, "offset", off / big / norm)

    @property
    def dim(self) -> int:
        """2 for a line, 3 for a plane."""
        return self.normal.shape[0]

    def _points(self, name: str, p) -> np.ndarray:
        arr = finite_array(name, p)
        if arr.ndim == 0 or arr.shape[-1] != self.dim:
            raise ValueError(
                f"{name}: expected points with {self.dim} coordinates in the last axis, got shape {arr.shape}"
            )
        return arr

    def signed_distance(self, p) -> np.ndarray:
        """Signed distance of point(s) ``p`` (..., dim) from the plane."""
        p = self._points("p", p)
        return p @ self.normal + self.offset

    def mirror(self, p) -> np.ndarray:
        """Mirror image of point(s) ``p`` (Jiang eq. 3-4 in 2-D; the VUE in 3-D)."""
        p = self._points("p", p)
        return p - 2.0 * (p @ self.normal + self.offset)[..., None] * self.normal

    def project(self, p) -> np.ndarray:
        """Orthogonal projection of point(s) ``p`` onto the plane."""
        p = self._points("p", p)
        return p - (p @ self.normal + self.offset)[..., None] * self.normal

    def coefficients(self) -> np.ndarray:
        """``[A, B, C]`` (2-D) or ``[a, b, c, d]`` (3-D) with a unit normal."""
        return np.append(self.normal, self.offset)


def line(A: float, B: float, C: float, name: str = "") -> Plane:
    """The 2-D line ``A x + B y + C = 0``; raises if ``A = B = 0``."""
    coeffs = np.array([real(k, v) for k, v in (("A", A), ("B", B), ("C", C))])
    if coeffs[0] == 0 and coeffs[1] == 0:
        raise ValueError("A, B: degenerate line, A = B = 0 describes no line")
    return Plane(coeffs[:2], coeffs[2], name=name)


def mirror(point, plane: Plane) -> np.ndarray:
    """Mirror ``point`` in ``plane`` (functional form of :meth:`Plane.mirror`)."""
    instance("plane", plane, Plane)
    point = plane._points("point", point)
    return plane.mirror(point)


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
