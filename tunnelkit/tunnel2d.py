"""Jiang et al. 2023's tunnel seen from above: two parallel wall lines (:class:`Tunnel2D`) and
the virtual stations, the base station mirrored in each wall (eq. 3-4, :func:`virtual_stations`).
By reciprocity a virtual station gives the same reflected path length as the UE's mirror image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import finite_array, instance, real, sequence, text, vector
from .geometry import Plane, line

__all__ = ["Tunnel2D", "virtual_stations"]


def virtual_stations(base_station, walls) -> np.ndarray:
    """Virtual stations: the base station mirrored in each wall (Jiang eq. 3-4). Shape (N, dim).

    The base station must lie off every wall and between every pair of parallel walls (the
    tunnel's inside): ``ValueError`` naming ``base_station`` otherwise."""
    walls = sequence("walls", walls, empty=True)
    if not walls:
        raise ValueError("walls: need at least one wall")
    for i, w in enumerate(walls):
        instance(f"walls[{i}]", w, Plane)
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
            instance(f"walls[{i}]", w, Plane)
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
