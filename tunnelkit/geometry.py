"""Lines, planes, mirror images and the two tunnels of the papers.

One class, :class:`Plane`, serves both dimensions: in 2-D it is the line ``A x + B y + C = 0``
(Jiang's tunnel walls), in 3-D the plane ``n . p + c = 0`` (the JAVELIN facets). Everything is
vectorised over leading axes of the points, so a whole trajectory or a grid of positions is
mirrored in one call.

Virtual stations (Jiang et al. 2023, eq. 3-4) are the base station mirrored in a wall; a virtual
UE (VUE, Italiano et al. 2026) is the UE mirrored in a reflecting surface. By reciprocity the two
pictures give the same reflected path length.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._validate import finite_array, real, sequence, text, vector

__all__ = [
    "Plane",
    "Tunnel2D",
    "line",
    "mirror",
    "reflector_point",
    "specular_point",
    "spherical",
    "spherical_jacobian",
    "virtual_stations",
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
    _check_plane("plane", plane)
    point = plane._points("point", point)
    return plane.mirror(point)


def virtual_stations(base_station, walls) -> np.ndarray:
    """Virtual stations: the base station mirrored in each wall (Jiang eq. 3-4). Shape (N, dim).

    The base station must lie off every wall and between every pair of parallel walls (the
    tunnel's inside): ``ValueError`` naming ``base_station`` otherwise."""
    walls = sequence("walls", walls, empty=True)
    if not walls:
        raise ValueError("walls: need at least one wall")
    for i, w in enumerate(walls):
        _check_plane(f"walls[{i}]", w)
    bs = vector("base_station", base_station, walls[0].dim)
    side = [float(w.signed_distance(bs)) for w in walls]
    for i, wi in enumerate(walls):
        if side[i] == 0.0:
            raise ValueError(f"base_station: {bs} lies on walls[{i}] (no mirror image)")
        for j, wj in enumerate(walls):
            on_j = -wj.offset * wj.normal  # a point of wall j
            parallel = wi.dim == wj.dim and abs(abs(float(wi.normal @ wj.normal)) - 1) < 1e-12
            if j != i and parallel and side[i] * float(wi.signed_distance(on_j)) < 0:
                raise ValueError(
                    f"base_station: {bs} lies outside the tunnel (beyond walls[{i}], away "
                    f"from walls[{j}])"
                )
    return np.stack([w.mirror(bs) for w in walls])


def specular_point(source, target, plane: Plane) -> np.ndarray:
    """The point on ``plane`` where a ray from ``source`` reflects towards ``target``.

    It is where the segment from ``target`` to the mirror image of ``source`` crosses the plane.
    Both points must lie strictly on the same side of the plane. Vectorised over ``target``.
    """
    _check_plane("plane", plane)
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


def _check_plane(name: str, plane) -> None:
    if not isinstance(plane, Plane):
        raise TypeError(f"{name}: expected a tunnelkit.geometry.Plane, got {type(plane).__name__}")


@dataclass(frozen=True)
class Tunnel2D:
    """A straight 2-D tunnel between two parallel wall lines (Jiang's top view).

    ``walls[0]`` and ``walls[1]`` must be parallel and distinct. The tunnel frame has unit vectors
    ``axis`` (along the tunnel) and ``across`` (from ``walls[1]`` towards ``walls[0]``).
    """

    walls: tuple[Plane, Plane]

    def __post_init__(self) -> None:
        sequence("walls", self.walls, empty=True)
        if len(self.walls) != 2:
            raise ValueError(f"walls: a 2-D tunnel needs exactly two walls, got {len(self.walls)}")
        for i, w in enumerate(self.walls):
            _check_plane(f"walls[{i}]", w)
            if w.dim != 2:
                raise ValueError(f"walls[{i}]: expected a 2-D line, got a {w.dim}-D plane")
        n0, n1 = self.walls[0].normal, self.walls[1].normal
        cross = n0[0] * n1[1] - n0[1] * n1[0]
        if abs(cross) > 1e-9:
            raise ValueError("walls: the two wall lines must be parallel")
        if self.width <= 0:
            raise ValueError("walls: the two wall lines coincide, the tunnel has zero width")

    @classmethod
    def from_lines(cls, line0, line1) -> Tunnel2D:
        """Build from two ``(A, B, C)`` triples, e.g. Jiang's ``(3, -3, 40)`` and ``(3, -3, -23.6396)``."""
        l0 = finite_array("line0", line0, shape=(3,))
        l1 = finite_array("line1", line1, shape=(3,))
        return cls((line(*l0, name="wall 1"), line(*l1, name="wall 2")))

    @property
    def _sign(self) -> float:
        """+1 or -1 so that ``_sign * walls[0].signed_distance(p)`` is positive inside."""
        w0, w1 = self.walls
        return float(np.sign(w0.signed_distance(-w1.offset * w1.normal)))

    def _depth(self, p) -> np.ndarray:
        """Distance of ``p`` from wall 1 towards wall 2 (negative beyond wall 1)."""
        return self._sign * self.walls[0].signed_distance(p)

    @property
    def width(self) -> float:
        """Distance between the walls [m]."""
        w0, w1 = self.walls
        return float(abs(w0.signed_distance(-w1.offset * w1.normal)))

    @property
    def across(self) -> np.ndarray:
        """Unit vector across the tunnel, from wall 2 towards wall 1."""
        return -self._sign * self.walls[0].normal

    @property
    def axis(self) -> np.ndarray:
        """Unit vector along the tunnel (``across`` rotated by 90 deg, x-component >= 0)."""
        c = self.across
        a = np.array([c[1], -c[0]])
        return a if (a[0] > 0 or (a[0] == 0 and a[1] > 0)) else -a

    def wall_distances(self, p) -> np.ndarray:
        """Signed distance of point(s) ``p`` from wall 1 and wall 2, shape (..., 2), positive inside."""
        depth = self._depth(self.walls[0]._points("p", p))
        return np.stack([depth, self.width - depth], axis=-1)

    def contains(self, p, margin: float = 0.0) -> np.ndarray:
        """True where ``p`` lies strictly between the walls (by more than ``margin``)."""
        depth = self._depth(self.walls[0]._points("p", p))
        margin = real("margin", margin)
        return (depth > margin) & (depth < self.width - margin)

    def require_inside(self, name: str, p) -> np.ndarray:
        """Return ``p`` as an array, raising if any point lies outside the tunnel (the error names
        ``name``, the caller's parameter)."""
        name = text("name", name)
        p = self.walls[0]._points(name, p)
        inside = np.atleast_1d(self.contains(p))
        if not np.all(inside):
            first = int(np.argmin(inside))
            raise ValueError(
                f"{name}: point {np.atleast_2d(p)[first]} lies outside the tunnel walls"
            )
        return p

    def virtual_stations(self, base_station) -> np.ndarray:
        """The base station mirrored in wall 1 and wall 2 (Jiang eq. 3-4), shape (2, 2); the base
        station must lie between the walls (``ValueError`` naming ``base_station`` otherwise)."""
        bs = vector("base_station", base_station, 2)
        return virtual_stations(self.require_inside("base_station", bs), self.walls)

    def to_tunnel_frame(self, p) -> np.ndarray:
        """(along, across) coordinates; ``across`` measured from wall 2."""
        p = self.walls[0]._points("p", p)
        w1 = self.walls[1]
        origin = -w1.offset * w1.normal
        rel = p - origin
        return np.stack([rel @ self.axis, rel @ self.across], axis=-1)

    def from_tunnel_frame(self, q) -> np.ndarray:
        """Inverse of :meth:`to_tunnel_frame`."""
        q = finite_array("q", q)
        w1 = self.walls[1]
        origin = -w1.offset * w1.normal
        return origin + q[..., :1] * self.axis + q[..., 1:2] * self.across
