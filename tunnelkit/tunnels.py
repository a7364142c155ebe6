"""Tunnel cross-sections for your own tunnel: rectangular, horseshoe and semicircular.

Every shape is a convex cross-section polygon in the (y, z) plane, extruded along x into planar
:class:`~tunnelkit.propagation.Facet` s with inward normals, plus the road at ``z = 0``. The result
is a :class:`~tunnelkit.propagation.Tunnel3D`, so the image-method propagation, the channel
synthesis and the SR-NF code work on it unchanged.

* ``rectangular``: two vertical walls (``y = +-width/2``) and a flat ceiling at ``height``;
* ``horseshoe``: vertical walls up to ``wall_height``, then an arched roof: a half-ellipse of
  ``n_facets`` facets with semi-axes ``width/2`` and ``height - wall_height`` (a semicircular roof
  when ``wall_height = height - width/2``, the default);
* ``semicircular``: the JAVELIN tunnel (:func:`tunnelkit.propagation.semicircular_tunnel`).

Facet kinds: ``"wall"`` for facets whose normal is mostly horizontal, ``"ceiling"`` otherwise,
``"road"`` for the road. :data:`SHAPES` maps a shape name to its builder; ``[tunnel] kind`` of a
``user`` scenario picks one. This module also registers the ``lane`` and ``slalom`` trajectories.

    >>> from tunnelkit import tunnels
    >>> tun = tunnels.make_tunnel("rectangular", width=8.0, height=6.0, length=200.0)
    >>> round(tunnels.cross_section_area(tun), 6)
    48.0
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ._validate import finite_array, integer, positive, real, text
from .propagation import (
    Box,
    Facet,
    Tunnel3D,
    close_tunnel,
    lane_trajectory,
    plate_from_table,
    semicircular_tunnel,
)
from .scenarios import ScenarioError, Trajectory, register_trajectory, register_tunnel

__all__ = [
    "SHAPES",
    "cross_section",
    "cross_section_area",
    "cross_section_perimeter",
    "extruded_tunnel",
    "horseshoe_tunnel",
    "make_tunnel",
    "rectangular_tunnel",
]


def extruded_tunnel(
    profile,
    names,
    *,
    length: float,
    x_start: float | None = None,
    plates: tuple[Facet, ...] = (),
    blockers: tuple[Box, ...] = (),
    wall_material: str = "concrete",
    road_material: str = "concrete",
) -> Tunnel3D:
    """A straight tunnel from a convex cross-section ``profile`` (K, 2) of (y, z) vertices.

    The profile runs from the right road corner ``(width/2, 0)`` over the walls and roof to the
    left road corner ``(-width/2, 0)``; edge ``i`` (vertices ``i`` to ``i + 1``) becomes the facet
    ``names[i]``, extruded over ``[x_start, x_start + length]`` (centred on x = 0 by default). The
    road closes the section. Normals point into the tunnel; plates must lie inside.
    """
    text("wall_material", wall_material), text("road_material", road_material)
    prof = finite_array("profile", profile)
    if prof.ndim != 2 or prof.shape[1] != 2 or prof.shape[0] < 3:
        raise ValueError(f"profile: expected (K >= 3, 2) vertices, got shape {prof.shape}")
    if isinstance(names, str) or not isinstance(names, list | tuple):
        raise TypeError(f"names: expected a list of facet names, got {type(names).__name__}")
    names = list(names)
    if len(names) != prof.shape[0] - 1:
        raise ValueError(f"names: expected {prof.shape[0] - 1} facet names, got {len(names)}")
    if abs(prof[0, 1]) > 1e-12 or abs(prof[-1, 1]) > 1e-12 or prof[0, 0] <= prof[-1, 0]:
        raise ValueError("profile: must run from (width/2, 0) to (-width/2, 0) over the roof")
    _check_convex_profile(prof)
    length = positive("length", length)
    width = float(prof[0, 0] - prof[-1, 0])
    height = float(prof[:, 1].max())
    x0 = -length / 2 if x_start is None else real("x_start", x_start)
    ax = np.array([length, 0.0, 0.0])
    centre = np.array([0.0, 0.5 * (prof[0, 0] + prof[-1, 0]), 0.5 * height])
    verts = np.column_stack([np.full(len(prof), x0), prof])
    facets = []
    for i, name in enumerate(names):
        a, e = verts[i], verts[i + 1] - verts[i]
        nrm = np.cross(ax, e)
        nrm = nrm / np.linalg.norm(nrm)
        if nrm @ (centre - a) < 0:
            nrm = -nrm
        kind = "ceiling" if abs(nrm[2]) > np.cos(np.radians(45)) else "wall"
        facets.append(Facet(a, ax, e, nrm, name=name, kind=kind, material=wall_material))
    return close_tunnel(
        facets, x0, length, prof[-1, 0], width, height, road_material, plates, blockers
    )


def _check_convex_profile(prof: np.ndarray) -> None:
    """The cross-section closed by the road must be a convex polygon traversed once,
    counter-clockwise in (y, z) (right road corner, up over the roof, down to the left corner):
    every turn to the left (collinear edges allowed) and the turns adding up to one revolution.
    A concave or self-intersecting profile (a wall folding inwards, a crossed edge) is refused:
    the tracer's inside test and the facets' inward normals assume a convex section."""
    closed = np.vstack([prof, prof[:1]])
    e = np.diff(closed, axis=0)  # the K - 1 profile edges and the road
    lengths = np.linalg.norm(e, axis=1)
    if np.any(lengths <= 1e-9 * max(float(lengths.max()), 1.0)):
        raise ValueError(f"profile: edge {int(np.argmin(lengths))} has zero length")
    nxt = np.roll(e, -1, axis=0)
    cross = e[:, 0] * nxt[:, 1] - e[:, 1] * nxt[:, 0]
    turn = np.arctan2(cross, np.einsum("ij,ij->i", e, nxt))
    tol = 1e-9 * lengths.max() ** 2
    if np.any(cross < -tol) or abs(turn.sum() - 2 * np.pi) > 1e-6:
        bad = int(np.argmin(cross)) + 1
        raise ValueError(
            "profile: the cross-section (closed by the road) must be convex and not cross itself; "
            f"it turns the wrong way or winds more than once (near vertex {bad % len(prof)})"
        )


def rectangular_tunnel(*, width: float, height: float, length: float, **kw) -> Tunnel3D:
    """Vertical walls at ``y = +-width/2`` and a flat ceiling at ``z = height``."""
    w, h = positive("width", width), positive("height", height)
    prof = [(w / 2, 0.0), (w / 2, h), (-w / 2, h), (-w / 2, 0.0)]
    return extruded_tunnel(prof, ["wall left", "ceiling", "wall right"], length=length, **kw)


def horseshoe_tunnel(
    *,
    width: float,
    height: float,
    length: float,
    wall_height: float | None = None,
    n_facets: int = 12,
    **kw,
) -> Tunnel3D:
    """Vertical walls up to ``wall_height``, then a half-elliptic roof of ``n_facets`` facets.

    The roof joins ``(+-width/2, wall_height)`` to the crown ``(0, height)``; its vertices are
    ``(width/2 cos t, wall_height + (height - wall_height) sin t)`` at ``t = i pi / n_facets``.
    ``wall_height`` defaults to ``height - width/2`` (a semicircular roof), which needs
    ``height > width/2``.
    """
    w, h = positive("width", width), positive("height", height)
    n = integer("n_facets", n_facets, minimum=2)
    if n > 360:
        raise ValueError(f"n_facets: at most 360 roof facets, got {n}")
    if wall_height is None:
        if h <= w / 2:
            raise ValueError(
                f"wall_height: the default height - width/2 = {h - w / 2:g} m is not > 0; "
                "give wall_height (0 < wall_height < height) for a flatter arch"
            )
        hw = h - w / 2
    else:
        hw = positive("wall_height", wall_height)
        if hw >= h:
            raise ValueError(f"wall_height: must be < height = {h:g} m, got {hw:g}")
    t = np.linspace(0.0, np.pi, n + 1)
    arch = np.column_stack([w / 2 * np.cos(t), hw + (h - hw) * np.sin(t)])
    arch[[0, -1], 0] = (w / 2, -w / 2)  # exact corners
    prof = np.vstack([[w / 2, 0.0], arch, [-w / 2, 0.0]])
    names = ["wall left"] + [f"roof {i}" for i in range(n)] + ["wall right"]
    return extruded_tunnel(prof, names, length=length, **kw)


def _semicircular(*, width: float, height: float, length: float, n_facets: int = 12, **kw):
    return semicircular_tunnel(width=width, height=height, length=length, n_facets=n_facets, **kw)


#: shape name -> builder(width=, height=, length=, x_start=, plates=, blockers=, materials, ...)
SHAPES: dict[str, Callable[..., Tunnel3D]] = {
    "rectangular": rectangular_tunnel,
    "horseshoe": horseshoe_tunnel,
    "semicircular": _semicircular,
}


def make_tunnel(shape: str, **kw) -> Tunnel3D:
    """Build the tunnel ``shape`` (one of :data:`SHAPES`) with the builder's keyword arguments."""
    if shape not in SHAPES:
        raise ValueError(f"shape: expected one of {sorted(SHAPES)}, got {shape!r}")
    return SHAPES[shape](**kw)


# --- cross-section measures (tests, design tables) ----------------------------------------------


def cross_section(tunnel: Tunnel3D) -> np.ndarray:
    """The cross-section edges (F, 2, 2): ``[[y0, z0], [y1, z1]]`` of every facet (walls, roof, road)."""
    if not isinstance(tunnel, Tunnel3D):
        raise TypeError(f"tunnel: expected a propagation.Tunnel3D, got {type(tunnel).__name__}")
    out = []
    for f in tunnel.facets:
        if abs(f.edge_v[0]) > 1e-12 or abs(f.edge_u[1]) + abs(f.edge_u[2]) > 1e-12:
            raise ValueError(f"tunnel: facet {f.name!r} is not extruded along x")
        out.append([f.corner[1:], f.corner[1:] + f.edge_v[1:]])
    return np.asarray(out)


def cross_section_area(tunnel: Tunnel3D) -> float:
    """Area [m^2] of the (convex) faceted cross-section."""
    e = cross_section(tunnel)
    c = e.reshape(-1, 2).mean(axis=0)
    a, b = e[:, 0] - c, e[:, 1] - c
    return float(0.5 * np.sum(np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])))


def cross_section_perimeter(tunnel: Tunnel3D) -> float:
    """Perimeter [m] of the faceted cross-section, road included."""
    e = cross_section(tunnel)
    return float(np.sum(np.linalg.norm(e[:, 1] - e[:, 0], axis=-1)))


# --- scenario builders (user family) ------------------------------------------------------------


def _boxes(sec: dict) -> tuple[Box, ...]:
    out = []
    for i, t in enumerate(sec.get("blockers", [])):
        try:
            out.append(Box(t["lo"], t["hi"], name=str(t.get("name", f"blocker {i}"))))
        except (TypeError, ValueError) as exc:
            raise ScenarioError(f"tunnel.blockers[{i}]: {exc}") from None
    return tuple(out)


def _user_tunnel(shape: str):
    def build(sec: dict, get) -> Tunnel3D:
        kw = dict(
            width=get("width"),
            height=get("height"),
            length=get("length"),
            x_start=get("x_start", default=None),
            plates=tuple(plate_from_table(i, t) for i, t in enumerate(sec.get("plates", []))),
            blockers=_boxes(sec),
            wall_material=get("wall_material", str, default="concrete"),
            road_material=get("road_material", str, default="concrete"),
        )
        if shape != "rectangular":
            kw["n_facets"] = get("n_facets", int, default=12)
        if shape == "horseshoe":
            kw["wall_height"] = get("wall_height", default=None)
        try:
            return make_tunnel(shape, **kw)
        except (TypeError, ValueError) as exc:
            raise ScenarioError(f"tunnel: {exc}") from None

    return build


for _shape in SHAPES:
    register_tunnel(_shape)(_user_tunnel(_shape))


def _inside(traj: Trajectory, tunnel) -> Trajectory:
    if isinstance(tunnel, Tunnel3D):
        inside = tunnel.contains(traj.position, margin=1e-6)
        if not np.all(inside):
            k = int(np.argmin(inside))
            raise ScenarioError(
                f"trajectory: leaves the tunnel at sample {k} (t = {traj.t[k]:.2f} s, "
                f"position {traj.position[k].round(3).tolist()})"
            )
    return traj


def _lane_kw(get) -> dict:
    return dict(
        x_start=get("x_start"),
        x_end=get("x_end"),
        speed=get("speed"),
        period=get("period"),
        y=get("y"),
        height=get("height"),
    )


@register_trajectory("lane")
def _lane(sec: dict, get, tunnel) -> Trajectory:
    """Straight along x at lane centre ``y`` and antenna ``height``."""
    try:
        traj = lane_trajectory(**_lane_kw(get))
    except ValueError as exc:
        raise ScenarioError(f"trajectory: {exc}") from None
    return _inside(traj, tunnel)


@register_trajectory("slalom")
def _slalom(sec: dict, get, tunnel) -> Trajectory:
    """``y + amplitude sin(2 pi (x - x_start) / wavelength)`` at constant speed along x."""
    try:
        traj = lane_trajectory(
            **_lane_kw(get),
            slalom_amplitude=get("amplitude"),
            slalom_wavelength=get("wavelength"),
        )
    except ValueError as exc:
        raise ScenarioError(f"trajectory: {exc}") from None
    return _inside(traj, tunnel)
