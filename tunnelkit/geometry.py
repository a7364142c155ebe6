"""Lines, planes, mirror images and the angles of a direction.

One class, :class:`Plane`, serves both dimensions: in 2-D it is the line ``A x + B y + C = 0``
(Jiang's tunnel walls), in 3-D the plane ``n . p + c = 0`` (the JAVELIN facets). Everything is
vectorised over leading axes of the points, so a whole trajectory or a grid of positions is
mirrored in one call.

A virtual UE (VUE, Italiano et al. 2026) is the UE mirrored in a reflecting surface; Jiang et al.
2023's virtual stations (the base station mirrored in a wall, eq. 3-4) and their 2-D tunnel are in
:mod:`tunnelkit.tunnel2d`. By reciprocity the two pictures give the same reflected path length.
Where a path meets the plane (the specular point, eq. 45's reflection point):
:mod:`tunnelkit.reflection`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._validate import finite_array, real, text

__all__ = [
    "Plane",
    "line",
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


def line(A: float, B: float, C: float, name: str = "") -> Plane:
    """The 2-D line ``A x + B y + C = 0``; raises if ``A = B = 0``."""
    coeffs = np.array([real(k, v) for k, v in (("A", A), ("B", B), ("C", C))])
    if coeffs[0] == 0 and coeffs[1] == 0:
        raise ValueError("A, B: degenerate line, A = B = 0 describes no line")
    return Plane(coeffs[:2], coeffs[2], name=name)
