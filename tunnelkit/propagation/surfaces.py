"""The tunnel's geometry: finite planar facets (walls, ceiling, road, RRM plates), blocking boxes
(trucks) and the straight tunnel they make, the JAVELIN semicircular tunnel of Italiano et al.
(2026) among them. World frame: x along the tunnel, y across, z up, road at ``z = 0``."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from .._validate import (
    choice,
    finite_array,
    instance,
    integer,
    positive,
    real,
    record,
    sequence,
    text,
    vector,
)
from ..budget import check_bytes
from ..geometry import Plane
from .materials import MATERIALS, reflection_coefficient

__all__ = [
    "FACET_BYTES",
    "Box",
    "Facet",
    "Tunnel3D",
    "close_tunnel",
    "road_marking",
    "semicircular_tunnel",
    "truck_box",
]

#: memory one facet takes while tracing: the facet (about 0.6 KiB measured), its plane and the
#: candidate path with two per-antenna length arrays (1.6 KiB at M = 100)
FACET_BYTES = 4096
#: what a facet is (``Facet.kind``)
FACET_KINDS = ("wall", "ceiling", "road", "rrm")


@dataclass(frozen=True)
class Facet:
    """A finite planar rectangle ``corner + a * edge_u + b * edge_v``, ``a, b`` in [0, 1].

    ``normal`` is the unit normal pointing into the tunnel (the side reflections come from);
    ``kind`` is "wall", "ceiling", "road" or "rrm"; ``material`` is "concrete" or "metal"
    (perfect conductor, ``Gamma = -1``).
    """

    corner: np.ndarray
    edge_u: np.ndarray
    edge_v: np.ndarray
    normal: np.ndarray
    name: str = ""
    kind: str = "wall"
    material: str = "concrete"

    def __post_init__(self) -> None:
        text("name", self.name, empty=True)
        choice("kind", self.kind, FACET_KINDS)
        label = self.name or "facet"
        c = vector(f"{label}.corner", self.corner, 3)
        u = vector(f"{label}.edge_u", self.edge_u, 3)
        v = vector(f"{label}.edge_v", self.edge_v, 3)
        n = vector(f"{label}.normal", self.normal, 3)
        area = float(np.linalg.norm(np.cross(u, v)))
        if area <= 1e-12:
            raise ValueError(f"{label}: the plate/facet has zero area (edges {u}, {v})")
        if abs(u @ v) > 1e-9 * np.linalg.norm(u) * np.linalg.norm(v):
            raise ValueError(f"{label}: edge_u and edge_v must be orthogonal")
        nn = np.cross(u, v) / area
        if np.linalg.norm(n) == 0:
            raise ValueError(f"{label}.normal: must be non-zero")
        n = n / np.linalg.norm(n)
        if abs(abs(n @ nn) - 1.0) > 1e-9:
            raise ValueError(f"{label}.normal: must be perpendicular to both edges")
        if self.material not in MATERIALS:
            raise ValueError(
                f"{label}.material: expected 'concrete' or 'metal', got {self.material!r}"
            )
        for k, val in (("corner", c), ("edge_u", u), ("edge_v", v), ("normal", n)):
            object.__setattr__(self, k, val)

    @property
    def area(self) -> float:
        """Area [m^2]."""
        return float(np.linalg.norm(np.cross(self.edge_u, self.edge_v)))

    @property
    def center(self) -> np.ndarray:
        """Centre of the rectangle."""
        return self.corner + 0.5 * (self.edge_u + self.edge_v)

    @cached_property
    def plane(self) -> Plane:
        """The infinite plane, normal pointing into the tunnel (built once per facet)."""
        return Plane(self.normal, -float(self.normal @ self.corner), name=self.name)

    def contains(self, p, tol: float = 1e-9) -> np.ndarray:
        """True where point(s) ``p`` (..., 3) on the plane fall inside the finite rectangle
        (by ``tol`` in units of the edges; a negative ``tol`` keeps points strictly inside)."""
        return self._contains(_points("p", p), real("tol", tol))

    def _contains(self, p: np.ndarray, tol: float) -> np.ndarray:
        """:meth:`contains` on checked arguments (the tracer's unchecked twin)."""
        rel = p - self.corner
        a = rel @ self.edge_u / (self.edge_u @ self.edge_u)
        b = rel @ self.edge_v / (self.edge_v @ self.edge_v)
        return (a >= -tol) & (a <= 1 + tol) & (b >= -tol) & (b <= 1 + tol)

    def corners(self) -> np.ndarray:
        """The four corners (4, 3) in drawing order."""
        c, u, v = self.corner, self.edge_u, self.edge_v
        return np.stack([c, c + u, c + u + v, c + v])

    def reflection_coefficient(self, fc: float, cos_i) -> np.ndarray:
        """``-1`` for metal, TE Fresnel coefficient of concrete at ``fc`` otherwise."""
        return reflection_coefficient(self.material, fc, cos_i)


@dataclass(frozen=True)
class Box:
    """An axis-aligned box ``lo <= p <= hi`` that blocks rays (a truck)."""

    lo: np.ndarray
    hi: np.ndarray
    name: str = "box"

    def __post_init__(self) -> None:
        text("name", self.name, empty=True)
        lo = vector(f"{self.name}.lo", self.lo, 3)
        hi = vector(f"{self.name}.hi", self.hi, 3)
        if np.any(hi <= lo):
            raise ValueError(f"{self.name}: needs hi > lo on every axis, got lo={lo}, hi={hi}")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    def blocks(self, a, b) -> np.ndarray:
        """True where the segment ``a -> b`` (..., 3) crosses the box (slab test, vectorised)."""
        return self._blocks(_points("a", a), _points("b", b))

    def _blocks(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """:meth:`blocks` on checked arguments (the tracer's unchecked twin)."""
        d = b - a
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / d
            t1 = (self.lo - a) * inv
            t2 = (self.hi - a) * inv
        # a segment parallel to a slab never leaves it if it starts inside, never enters otherwise
        inside = (a >= self.lo) & (a <= self.hi)
        tmin = np.where(d == 0, np.where(inside, -np.inf, np.inf), np.minimum(t1, t2))
        tmax = np.where(d == 0, np.where(inside, np.inf, -np.inf), np.maximum(t1, t2))
        t_enter = np.max(tmin, axis=-1)
        t_exit = np.min(tmax, axis=-1)
        return (t_enter <= t_exit) & (t_exit >= 0.0) & (t_enter <= 1.0)


def truck_box(
    x_center: float,
    y_center: float,
    *,
    length: float = 12.0,
    width: float = 2.5,
    height: float = 4.0,
    name: str = "truck",
) -> Box:
    """A truck-sized box standing on the road, centred at ``(x_center, y_center)``."""
    length, width, height = (
        positive(k, v) for k, v in (("length", length), ("width", width), ("height", height))
    )
    c = np.array([real("x_center", x_center), real("y_center", y_center), 0.0])
    half = np.array([length / 2, width / 2, 0.0])
    return Box(c - half, c + half + np.array([0, 0, height]), name=name)


@dataclass(frozen=True)
class Tunnel3D:
    """A straight tunnel made of planar facets (walls, ceiling, road), RRM plates and blockers.

    ``x_range`` (2,) is the tunnel's extent along x. The cross-section (walls + road) must be
    convex with inward normals; :meth:`contains` tests a point against every facet plane.
    """

    facets: tuple[Facet, ...]
    x_range: tuple[float, float]
    plates: tuple[Facet, ...] = ()
    blockers: tuple[Box, ...] = ()
    width: float = 0.0
    height: float = 0.0

    def __post_init__(self) -> None:
        record(self, shapes={"x_range": (2,)}, nonnegative=("width", "height"),
               may_be_empty=("plates", "blockers"))  # fmt: skip
        for name, cls in (("facets", Facet), ("plates", Facet), ("blockers", Box)):
            for i, f in enumerate(getattr(self, name)):
                instance(f"{name}[{i}]", f, cls)
        lo, hi = (real("x_range", x) for x in self.x_range)
        if not lo < hi:
            raise ValueError(f"x_range: must be increasing, got ({lo:g}, {hi:g})")

    @property
    def surfaces(self) -> tuple[Facet, ...]:
        """Every reflecting surface: facets then plates."""
        return tuple(self.facets) + tuple(self.plates)

    def contains(self, p, margin: float = 0.0) -> np.ndarray:
        """True where ``p`` (..., 3) lies inside the tunnel by more than ``margin`` [m]."""
        p, margin = _points("p", p), real("margin", margin)
        ok = (p[..., 0] > self.x_range[0] + margin) & (p[..., 0] < self.x_range[1] - margin)
        for f in self.facets:
            ok &= f.plane.signed_distance(p) > margin
        return ok

    def require_inside(self, name: str, p) -> np.ndarray:
        """``p`` as an array, raising ``ValueError`` naming ``name`` if a point is outside."""
        p = finite_array(text("name", name), p)
        if p.ndim == 0 or p.shape[-1] != 3:
            raise ValueError(f"{name}: expected 3-D point(s), got shape {p.shape}")
        inside = np.atleast_1d(self.contains(p, margin=1e-6))
        if not np.all(inside):
            bad = np.atleast_2d(p)[int(np.argmin(inside))]
            raise ValueError(f"{name}: point {bad} lies outside the tunnel")
        return p

    def with_blockers(self, *boxes: Box) -> Tunnel3D:
        """A copy with ``boxes`` as the blockers (e.g. a truck for NLoS conditions)."""
        for i, b in enumerate(boxes):
            if not isinstance(b, Box):
                raise TypeError(f"boxes[{i}]: expected a propagation.Box, got {type(b).__name__}")
        return replace(self, blockers=tuple(boxes))

    def without_plates(self) -> Tunnel3D:
        """A copy without the RRMs (the paper's "NoRRMs" configuration)."""
        return replace(self, plates=())

    def blocked(self, a, b) -> np.ndarray:
        """True where segment ``a -> b`` (..., 3) crosses any blocker."""
        return self._blocked(_points("a", a), _points("b", b))

    def _blocked(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """:meth:`blocked` on checked arguments (the tracer's unchecked twin)."""
        out = np.zeros(np.broadcast_shapes(np.shape(a), np.shape(b))[:-1], dtype=bool)
        for box in self.blockers:
            out |= box._blocks(a, b)
        return out


def _points(name: str, p) -> np.ndarray:
    """Finite point(s) (..., 3)."""
    p = finite_array(name, p)
    if p.ndim == 0 or p.shape[-1] != 3:
        raise ValueError(f"{name}: expected 3-D point(s) (..., 3), got shape {p.shape}")
    return p


def semicircular_tunnel(
    *,
    length: float = 100.0,
    width: float = 10.0,
    height: float = 5.0,
    n_facets: int = 12,
    x_start: float | None = None,
    plates: tuple[Facet, ...] = (),
    blockers: tuple[Box, ...] = (),
    wall_material: str = "concrete",
    road_material: str = "concrete",
) -> Tunnel3D:
    """The paper's tunnel: a half-ellipse (semicircle when ``width = 2 height``) of facets + road.

    Facet ``i`` joins the cross-section vertices at angles ``i pi / n`` and ``(i + 1) pi / n``
    (``(width/2 cos t, height sin t)``), extruded along x over ``[x_start, x_start + length]``
    (centred on x = 0 by default). Facets whose normal is mostly vertical are "ceiling".
    """
    length, width, height = (
        positive("length", length),
        positive("width", width),
        positive("height", height),
    )
    n = integer("n_facets", n_facets, minimum=2)
    choice("wall_material", wall_material, MATERIALS)
    choice("road_material", road_material, MATERIALS)
    plates, blockers = (
        sequence("plates", plates, empty=True),
        sequence("blockers", blockers, empty=True),
    )
    check_bytes("n_facets", n * FACET_BYTES, f"{n} facets of about {FACET_BYTES} B while tracing")
    x0 = -length / 2 if x_start is None else real("x_start", x_start)
    ax = np.array([length, 0.0, 0.0])
    t = np.linspace(0.0, np.pi, n + 1)
    verts = np.stack([np.zeros_like(t), width / 2 * np.cos(t), height * np.sin(t)], axis=-1)
    facets = []
    for i in range(n):
        a, b = verts[i], verts[i + 1]
        e = b - a
        nrm = np.cross(ax, e)
        nrm = nrm / np.linalg.norm(nrm)
        if nrm @ (np.array([0.0, 0.0, height / 2]) - a) < 0:
            nrm = -nrm
        kind = "ceiling" if abs(nrm[2]) > np.cos(np.radians(45)) else "wall"
        facets.append(
            Facet(
                a + np.array([x0, 0, 0]),
                ax,
                e,
                nrm,
                name=f"facet {i}",
                kind=kind,
                material=wall_material,
            )
        )
    return close_tunnel(
        facets, x0, length, -width / 2, width, height, road_material, plates, blockers
    )


def close_tunnel(
    facets, x0, length, y_right, width, height, road_material, plates=(), blockers=()
) -> Tunnel3D:
    """Add the road (``width`` across from ``y_right``, along x from ``x0``) to the wall/ceiling
    ``facets`` and check that every plate lies inside the tunnel and every blocker is a Box."""
    facets = sequence("facets", facets)
    x0, y_right, length = real("x0", x0), real("y_right", y_right), positive("length", length)
    width, height = positive("width", width), positive("height", height)
    choice("road_material", road_material, MATERIALS)
    plates, blockers = (
        sequence("plates", plates, empty=True),
        sequence("blockers", blockers, empty=True),
    )
    road = Facet(
        np.array([x0, y_right, 0.0]),
        np.array([length, 0.0, 0.0]),
        np.array([0.0, width, 0.0]),
        np.array([0.0, 0.0, 1.0]),
        name="road",
        kind="road",
        material=road_material,
    )
    tun = Tunnel3D(tuple([*facets, road]), (x0, x0 + length), (), tuple(blockers), width, height)
    for i, p in enumerate(plates):
        if not isinstance(p, Facet):
            raise TypeError(f"plates[{i}]: expected a propagation.Facet, got {type(p).__name__}")
        if not np.all(tun.contains(p.corners(), margin=-1e-6)):
            raise ValueError(f"{p.name or 'plate'}: the plate sticks out of the tunnel")
    for i, b in enumerate(blockers):
        if not isinstance(b, Box):
            raise TypeError(f"blockers[{i}]: expected a propagation.Box, got {type(b).__name__}")
    return replace(tun, plates=tuple(plates))


def road_marking(
    *, x_range, y: float, z: float, width: float, inclination_deg: float, name: str = "RRM"
) -> Facet:
    """A metallic RRM plate running along x over ``x_range``, centred across at ``(y, z)``.

    ``inclination_deg`` is the angle between the plate and the road (90 = vertical on a side
    wall, 55 = the paper's sidewalk-wall junction markings); the plate faces the tunnel axis
    (its normal points towards ``y = 0``) and upwards. ``width`` [m] is its extent in the
    cross-section. Zero length or width raises.
    """
    xr = finite_array("x_range", x_range, shape=(2,))
    width = positive("width", width)
    y, z = real("y", y), real("z", z)
    inclination_deg = real("inclination_deg", inclination_deg)
    if xr[1] <= xr[0]:
        raise ValueError(f"{name}: x_range must be increasing with non-zero length, got {xr}")
    if y == 0:
        raise ValueError(f"{name}: y must be non-zero (the plate sits on one side of the tunnel)")
    th = np.radians(float(inclination_deg))
    if not 0 < th <= np.pi / 2:
        raise ValueError(f"{name}: inclination_deg must lie in (0, 90], got {inclination_deg}")
    side = np.sign(y)
    n = np.array([0.0, -side * np.sin(th), np.cos(th)])
    w = np.array([0.0, side * np.cos(th), np.sin(th)])  # in-plane, across the tunnel, upwards
    center = np.array([0.5 * (xr[0] + xr[1]), float(y), float(z)])
    corner = center - 0.5 * width * w - np.array([0.5 * (xr[1] - xr[0]), 0, 0])
    eu = np.array([xr[1] - xr[0], 0.0, 0.0])
    ev = width * w
    if side > 0:  # keep (edge_u x edge_v) along the inward normal
        return Facet(corner, eu, ev, n, name=name, kind="rrm", material="metal")
    return Facet(corner + ev, eu, -ev, n, name=name, kind="rrm", material="metal")
