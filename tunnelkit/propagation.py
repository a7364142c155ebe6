"""Image-method propagation in the JAVELIN tunnel: LoS plus one specular bounce per surface.

The tunnel of Italiano et al. (2026), section 4.1: straight, semicircular cross-section (100 m long,
10 m wide, 5 m high) built from ``n_facets`` planar facets plus the road, the base station at the
centre 4.8 m high, and four metallic radio-reflective road markings (RRMs): finite plates placed
per scenario. World frame: x along the tunnel, y across, z up, road at ``z = 0``.

For every surface the vehicle (UE) is mirrored into a virtual UE (VUE); the reflected path exists
when the straight line from the array's reference antenna to the VUE crosses the surface *inside
the finite facet* (the specular point) and neither leg is blocked by a box (a truck). Each
:class:`Path` carries the exact length to **every antenna** (a spherical wavefront centred on the
VUE, eq. 2 and 38) and, for comparison, the SR-NF lengths (the wavefront centred on the reflection
point, the model of the paper's reference 13).

    >>> import tunnelkit as tk
    >>> from tunnelkit import propagation
    >>> sc = tk.load_scenario("italiano2026-straight")     # its builders are in this module
    >>> tun, arrs = sc.tunnel(), propagation.scenario_arrays(sc)
    >>> traj = sc.trajectory()
    >>> paths = propagation.trace_paths(tun, arrs[1], traj.position[0], traj.velocity[0], fc=5.9e9)

Sign conventions (pinned by tests): ``range_rate`` is the time derivative of the path length;
``velocity = -range_rate`` (positive when the path shortens, i.e. the vehicle approaches) and
``doppler = fc * velocity / c``, so that eq. 1's time phase ``+2 pi k f_d T0`` and eq. 15's
``v = c f_d / fc`` hold with a physical carrier ``exp(j 2 pi fc (t - d(t)/c))``.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from ._validate import boolean, cosine, finite_array, integer, positive, real, vector
from .arrays import ArrayGeometry, make_array
from .budget import check_bytes
from .constants import C, wavelength
from .geometry import Plane
from .scenarios import (
    ScenarioError,
    Trajectory,
    register_arrays,
    register_trajectory,
    register_tunnel,
)

__all__ = [
    "Box",
    "Facet",
    "Path",
    "Tunnel3D",
    "concrete_permittivity",
    "fresnel_te",
    "lane_trajectory",
    "road_marking",
    "scenario_arrays",
    "select_array",
    "semicircular_tunnel",
    "trace_paths",
    "truck_box",
]

_EPS0 = 8.8541878128e-12
#: memory one facet takes while tracing: the facet (about 0.6 KiB measured), its plane and the
#: candidate path with two per-antenna length arrays (1.6 KiB at M = 100)
FACET_BYTES = 4096
_KINDS = ("los", "wall", "ceiling", "road", "rrm")


# --- materials ----------------------------------------------------------------------------------


def concrete_permittivity(fc: float) -> complex:
    """Complex relative permittivity of concrete at ``fc`` [Hz] (ITU-R P.2040-3, Table 3).

    ``eps' = 5.24``, ``sigma = 0.0462 f_GHz^0.7822`` S/m, ``eps = eps' - j sigma / (2 pi f eps0)``.
    """
    fc = positive("fc", fc)
    sigma = 0.0462 * (fc / 1e9) ** 0.7822
    return complex(5.24, -sigma / (2 * np.pi * fc * _EPS0))


def fresnel_te(eps_r: complex, cos_i) -> np.ndarray:
    """Fresnel reflection coefficient for perpendicular (TE) polarisation.

    ``Gamma = (cos i - sqrt(eps - sin^2 i)) / (cos i + sqrt(eps - sin^2 i))``; ``cos_i`` is the
    cosine of the incidence angle from the surface normal. A perfect conductor is ``Gamma = -1``.
    """
    ci = cosine("cos_i", cos_i)
    return _fresnel_te(_permittivity("eps_r", eps_r), ci)


def _permittivity(name: str, eps_r) -> complex:
    """A finite (complex) relative permittivity."""
    if isinstance(eps_r, bool | np.bool_) or not isinstance(eps_r, numbers.Number):
        raise TypeError(f"{name}: expected a (complex) number, got {type(eps_r).__name__}")
    e = complex(eps_r)
    if not (np.isfinite(e.real) and np.isfinite(e.imag)):
        raise ValueError(f"{name}: must be finite, got {e}")
    if e == 0:
        raise ValueError(f"{name}: must be non-zero")
    return e


def _fresnel_te(eps_r: complex, ci) -> np.ndarray:
    """:func:`fresnel_te` on checked inputs (``ci`` in [0, 1])."""
    root = np.sqrt(eps_r - (1.0 - ci**2))
    return (ci - root) / (ci + root)


# --- surfaces and blockers ----------------------------------------------------------------------


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
        if self.material not in ("concrete", "metal"):
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
        """True where point(s) ``p`` on the plane fall inside the finite rectangle."""
        rel = finite_array("p", p) - self.corner
        a = rel @ self.edge_u / (self.edge_u @ self.edge_u)
        b = rel @ self.edge_v / (self.edge_v @ self.edge_v)
        return (a >= -tol) & (a <= 1 + tol) & (b >= -tol) & (b <= 1 + tol)

    def corners(self) -> np.ndarray:
        """The four corners (4, 3) in drawing order."""
        c, u, v = self.corner, self.edge_u, self.edge_v
        return np.stack([c, c + u, c + u + v, c + v])

    def reflection_coefficient(self, fc: float, cos_i) -> np.ndarray:
        """``-1`` for metal, TE Fresnel coefficient of concrete at ``fc`` otherwise."""
        ci = cosine("cos_i", cos_i)
        fc = positive("fc", fc)
        if self.material == "metal":
            return -np.ones_like(ci) + 0j
        return _fresnel_te(concrete_permittivity(fc), ci)


@dataclass(frozen=True)
class Box:
    """An axis-aligned box ``lo <= p <= hi`` that blocks rays (a truck)."""

    lo: np.ndarray
    hi: np.ndarray
    name: str = "box"

    def __post_init__(self) -> None:
        lo = vector(f"{self.name}.lo", self.lo, 3)
        hi = vector(f"{self.name}.hi", self.hi, 3)
        if np.any(hi <= lo):
            raise ValueError(f"{self.name}: needs hi > lo on every axis, got lo={lo}, hi={hi}")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    def blocks(self, a, b) -> np.ndarray:
        """True where the segment ``a -> b`` (..., 3) crosses the box (slab test, vectorised)."""
        a = np.asarray(a, dtype=float)
        d = np.asarray(b, dtype=float) - a
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

    @property
    def surfaces(self) -> tuple[Facet, ...]:
        """Every reflecting surface: facets then plates."""
        return tuple(self.facets) + tuple(self.plates)

    def contains(self, p, margin: float = 0.0) -> np.ndarray:
        """True where ``p`` (..., 3) lies inside the tunnel by more than ``margin`` [m]."""
        p = finite_array("p", p)
        ok = (p[..., 0] > self.x_range[0] + margin) & (p[..., 0] < self.x_range[1] - margin)
        for f in self.facets:
            ok &= f.plane.signed_distance(p) > margin
        return ok

    def require_inside(self, name: str, p) -> np.ndarray:
        """``p`` as an array, raising ``ValueError`` naming ``name`` if a point is outside."""
        p = finite_array(name, p)
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
        """True where segment ``a -> b`` crosses any blocker."""
        out = np.zeros(np.broadcast_shapes(np.shape(a), np.shape(b))[:-1], dtype=bool)
        for box in self.blockers:
            out |= box.blocks(a, b)
        return out


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


# --- paths --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Path:
    """One propagation path from the UE to an array, at one epoch.

    Attributes
    ----------
    kind : "los" or "reflection"
    surface, surface_kind : name and kind ("wall", "ceiling", "road", "rrm") of the reflector
        ("" and "los" for the direct path)
    source : (3,) the VUE (the UE itself for LoS), world frame
    point : (3,) the reflection point (the UE for LoS), world frame
    length : exact path length to the reference antenna [m] (``||VUE - p_0||``)
    lengths : (M,) exact length to every antenna (spherical wavefront from the VUE)
    lengths_srnf : (M,) SR-NF lengths: ``||UE - point|| + ||point - p_m||``
    direction : (3,) unit vector of arrival, world frame, from the reference antenna towards
        ``point`` (and the VUE, which is collinear)
    direction_local : (3,) the same in the array's local frame
    azimuth, elevation : world-frame angles of ``direction`` (Italiano eq. 46-47, 49-50) [rad]
    kappa_srnf : ``||point - p_0||``, the SR-NF curvature radius (eq. 51; ``length`` for LoS)
    range_rate : d(length)/dt [m/s]; ``velocity = -range_rate``; ``doppler = fc velocity / c``
    reflection_coefficient : complex ``Gamma`` (1 for LoS)
    gain : complex amplitude ``Gamma lambda / (4 pi length) exp(-j 2 pi length / lambda)``
    ue : (3,) the vehicle position the path was traced from
    """

    kind: str
    surface: str
    surface_kind: str
    source: np.ndarray
    point: np.ndarray
    length: float
    lengths: np.ndarray = field(repr=False)
    lengths_srnf: np.ndarray = field(repr=False)
    direction: np.ndarray
    direction_local: np.ndarray
    azimuth: float
    elevation: float
    kappa_srnf: float
    range_rate: float
    velocity: float
    doppler: float
    reflection_coefficient: complex
    gain: complex
    ue: np.ndarray = field(default=None, repr=False)

    def delta(self, model: str = "exact") -> np.ndarray:
        """Path-length offsets ``delta_m = d_m - d_0`` (eq. 2) for ``model`` "exact" or "srnf"."""
        if model == "exact":
            return self.lengths - self.lengths[0]
        if model == "srnf":
            return self.lengths_srnf - self.lengths_srnf[0]
        raise ValueError(f"model: expected 'exact' or 'srnf', got {model!r}")

    def kappa(self, model: str = "exact") -> float:
        """Radius of the wavefront at the reference antenna: ``length`` (VUE) or ``kappa_srnf``."""
        if model == "exact":
            return self.length
        if model == "srnf":
            return self.kappa_srnf
        raise ValueError(f"model: expected 'exact' or 'srnf', got {model!r}")

    def wave_origin(self, model: str = "exact") -> np.ndarray:
        """Where the wavefront is centred: the VUE (exact) or the reflection point (SR-NF)."""
        return self.source if model == "exact" else self.point


def _angles(u: np.ndarray) -> tuple[float, float]:
    return float(np.arctan2(u[1], u[0])), float(np.arctan2(u[2], np.hypot(u[0], u[1])))


def _make_path(kind, surface, skind, source, point, ue, src_vel, array, fc, gamma) -> Path:
    lam = wavelength(fc)
    ant = array.world
    lengths = np.linalg.norm(source - ant, axis=-1)
    leg = float(np.linalg.norm(ue - point))
    lengths_srnf = leg + np.linalg.norm(point - ant, axis=-1) if kind != "los" else lengths
    d0 = float(lengths[0])
    to_point = point - array.origin
    dist = np.linalg.norm(to_point)
    u = to_point / dist
    rr = float((source - array.origin) @ src_vel / d0)
    vel = -rr
    az, el = _angles(u)
    g = complex(gamma) * lam / (4 * np.pi * d0) * np.exp(-2j * np.pi * d0 / lam)
    return Path(
        kind,
        surface,
        skind,
        source.copy(),
        point.copy(),
        d0,
        lengths,
        lengths_srnf,
        u,
        array.dir_to_local(u),
        az,
        el,
        float(dist),
        rr,
        vel,
        fc * vel / C,
        complex(gamma),
        g,
        ue.copy(),
    )


def trace_paths(
    tunnel: Tunnel3D,
    array: ArrayGeometry,
    ue,
    ue_velocity=(0.0, 0.0, 0.0),
    *,
    fc: float,
    kinds: tuple[str, ...] = ("los", "wall", "ceiling", "road", "rrm"),
    front_only: bool = True,
) -> list[Path]:
    """All single-bounce paths from ``ue`` to ``array`` (image method), LoS first.

    A reflection off surface S exists when UE and array are on S's inner side, the segment from
    the reference antenna to the VUE crosses S inside the finite rectangle, and neither leg is
    blocked. With ``front_only`` paths arriving from behind the array face (local z <= 0) are
    dropped (the elements' back lobe). ``kinds`` selects the path families. Reflected paths are
    sorted by length after the LoS path.
    """
    if not isinstance(tunnel, Tunnel3D):
        raise TypeError(f"tunnel: expected a propagation.Tunnel3D, got {type(tunnel).__name__}")
    if not isinstance(array, ArrayGeometry):
        raise TypeError(f"array: expected an arrays.ArrayGeometry, got {type(array).__name__}")
    fc = positive("fc", fc)
    if isinstance(kinds, str) or not isinstance(kinds, tuple | list | set | frozenset):
        raise TypeError(f"kinds: expected a tuple of path kinds from {_KINDS}, got {kinds!r}")
    unknown = [k for k in kinds if k not in _KINDS]
    if unknown or not kinds:
        raise ValueError(f"kinds: expected one or more of {_KINDS}, got {tuple(kinds)!r}")
    front_only = boolean("front_only", front_only)
    ue = tunnel.require_inside("ue", vector("ue", ue, 3))
    vel = vector("ue_velocity", ue_velocity, 3)
    a0 = array.origin
    out: list[Path] = []
    if "los" in kinds and not tunnel.blocked(ue, a0) and (not front_only or array.in_front(ue)):
        out.append(_make_path("los", "", "los", ue, ue, ue, vel, array, fc, 1.0))
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
        if not s.contains(point, tol=1e-9):
            continue
        if tunnel.blocked(ue, point) or tunnel.blocked(point, a0):
            continue
        if front_only and not array.in_front(point):
            continue
        cos_i = min(du / float(np.linalg.norm(ue - point)), 1.0)  # rounding may give 1 + 1e-16
        gamma = s.reflection_coefficient(fc, cos_i)
        vvue = vel - 2.0 * (vel @ pl.normal) * pl.normal
        refl.append(
            _make_path("reflection", s.name, s.kind, vue, point, ue, vvue, array, fc, gamma)
        )
    refl.sort(key=lambda p: p.length)
    return out + refl


def select_array(arrays, ue) -> ArrayGeometry:
    """The array whose boresight points most towards ``ue`` (the one the vehicle drives into)."""
    arrays = list(arrays)
    if not arrays:
        raise ValueError("arrays: need at least one array")
    ue = vector("ue", ue, 3)
    scores = [float(a.boresight @ (ue - a.origin)) for a in arrays]
    return arrays[int(np.argmax(scores))]


# --- scenario builders --------------------------------------------------------------------------


def _plate_from_table(i: int, tab: dict) -> Facet:
    where = f"tunnel.plates[{i}]"
    if not isinstance(tab, dict):
        raise ScenarioError(f"{where}: expected a table")
    try:
        return road_marking(
            x_range=tab["x_range"],
            y=float(tab["y"]),
            z=float(tab["z"]),
            width=float(tab["width"]),
            inclination_deg=float(tab["inclination_deg"]),
            name=str(tab.get("name", f"RRM {i}")),
        )
    except KeyError as exc:
        raise ScenarioError(f"{where}: missing key {exc.args[0]!r}") from None
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"{where}: {exc}") from None


@register_tunnel("semicircular3d")
def _semicircular(sec: dict, get) -> Tunnel3D:
    plates = tuple(_plate_from_table(i, t) for i, t in enumerate(sec.get("plates", [])))
    boxes = []
    for i, t in enumerate(sec.get("blockers", [])):
        try:
            boxes.append(
                Box(
                    np.asarray(t["lo"], float),
                    np.asarray(t["hi"], float),
                    name=str(t.get("name", f"blocker {i}")),
                )
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ScenarioError(f"tunnel.blockers[{i}]: {exc}") from None
    try:
        return semicircular_tunnel(
            length=get("length"),
            width=get("width"),
            height=get("height"),
            n_facets=get("n_facets", int, default=12),
            plates=plates,
            blockers=tuple(boxes),
        )
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"tunnel: {exc}") from None


def lane_trajectory(
    *,
    x_start: float,
    x_end: float,
    speed: float,
    period: float,
    y: float,
    height: float,
    slalom_amplitude: float = 0.0,
    slalom_wavelength: float = 20.0,
) -> Trajectory:
    """Constant speed along x from ``x_start`` to ``x_end`` at lane offset ``y`` and antenna height.

    With ``slalom_amplitude > 0`` the lateral position is ``y + A sin(2 pi (x - x_start) / Lambda)``
    (velocity includes the lateral component; the speed along x stays ``speed``).
    """
    speed, period = positive("speed", speed), positive("period", period)
    lam = positive("slalom_wavelength", slalom_wavelength)
    x_start, x_end = real("x_start", x_start), real("x_end", x_end)
    y, height = real("y", y), real("height", height)
    slalom_amplitude = real("slalom_amplitude", slalom_amplitude)
    span = x_end - x_start
    if span == 0:
        raise ValueError("x_end: must differ from x_start")
    steps = abs(span) / (speed * period)
    if not np.isfinite(steps):
        raise ValueError(f"period: {period:g} s at {speed:g} m/s gives no finite number of samples")
    n = int(np.floor(steps)) + 1
    check_bytes("period", 8 * 8 * n, f"{n} samples of t, position and velocity")
    t = np.arange(n) * period
    sgn = np.sign(span)
    x = x_start + sgn * speed * t
    ph = 2 * np.pi * (x - x_start) / lam
    yy = y + slalom_amplitude * np.sin(ph)
    vy = slalom_amplitude * np.cos(ph) * 2 * np.pi / lam * sgn * speed
    pos = np.stack([x, yy, np.full(n, float(height))], axis=-1)
    vel = np.stack([np.full(n, sgn * speed), vy, np.zeros(n)], axis=-1)
    return Trajectory(t=t, position=pos, velocity=vel)


@register_trajectory("lane3d")
def _lane(sec: dict, get, tunnel) -> Trajectory:
    try:
        traj = lane_trajectory(
            x_start=get("x_start"),
            x_end=get("x_end"),
            speed=get("speed"),
            period=get("period"),
            y=get("y"),
            height=get("height"),
            slalom_amplitude=get("slalom_amplitude", default=0.0),
            slalom_wavelength=get("slalom_wavelength", default=20.0),
        )
    except ValueError as exc:
        raise ScenarioError(f"trajectory: {exc}") from exc
    if isinstance(tunnel, Tunnel3D):
        inside = tunnel.contains(traj.position, margin=1e-6)
        if not np.all(inside):
            k = int(np.argmin(inside))
            raise ScenarioError(
                f"trajectory: leaves the tunnel at sample {k} (position {traj.position[k]})"
            )
    return traj


@register_arrays("italiano2026", "user")
def scenario_arrays(scenario) -> list[ArrayGeometry]:
    """The arrays of ``[[base_station.arrays]]`` (shape, azimuth/elevation in degrees, offset).

    Each array's reference antenna sits at ``base_station.position + offset``; the spacing is
    ``lambda/2`` at ``radio.fc``.
    """
    bs = scenario.base_station()
    fc = scenario.get("radio.fc")
    tabs = scenario.section("base_station").get("arrays")
    if not isinstance(tabs, list) or not tabs:
        raise ScenarioError(f"{scenario.path.name}: missing [[base_station.arrays]]")
    out = []
    for i, t in enumerate(tabs):
        try:
            rows, cols = (int(v) for v in t["shape"])
            out.append(
                make_array(
                    rows,
                    cols,
                    fc=fc,
                    azimuth=np.radians(float(t["azimuth_deg"])),
                    elevation=np.radians(float(t["elevation_deg"])),
                    origin=bs + np.asarray(t.get("offset", [0, 0, 0]), float),
                    spacing=t.get("spacing"),
                    name=str(t.get("name", f"array {i}")),
                )
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ScenarioError(f"base_station.arrays[{i}]: {exc}") from None
    return out
