"""A long tunnel served by a row of identical sites, on the design's bound route.

A road tunnel of a few kilometres is served by a row of sites, not one: :class:`SiteRow` repeats
a :class:`~tunnelkit.design.setup.DesignSetup`'s site (its mounts, every candidate array on
them) every ``spacing`` metres along the tunnel axis (x), from the setup's own mount position,
as many times as the tunnel holds. :meth:`SiteRow.along` builds one from a scenario's setup: the
tunnel's cross-section lengthened to the drive, a constant-speed drive along the setup's lane
(80 km/h by default), the first site half a spacing inside the tunnel.

Per epoch the **serving site** is the nearest one along the axis, if it lies within
``max_range`` metres (default: always the nearest); an epoch with no site in range carries no
measurement (the tracker dead-reckons on the V2X messages).

Every site is the same site moved along a straight tunnel whose cross-section does not change,
so what an array measures depends only on where the UE is *relative to its serving site*.
:func:`site_route` therefore builds the path error model
(:func:`~tunnelkit.design.achievable.path_error_model`) once, for the first site, over the
distinct relative positions of the drive (positions within :data:`OFFSET_RESOLUTION_M` share
one), and each epoch draws from its row (:func:`site_drive`); when the spacing is a whole number
of the drive's steps (100 m at 80 km/h and 0.1 s: 45 steps) the rows are one spacing's worth,
however long the drive. The measurements carry their serving site's reference antenna
(``PathMeasurements.site``), from which the tracker evaluates that epoch's measurement model;
its virtual UEs (the UE mirrored in the surfaces) do not depend on the site.

The RRM plates and blockers of a scenario are local features, not a property of the row: a row
of more than one site refuses a setup that has them (:meth:`SiteRow.along` drops them). The
V2X messages are drawn from the drive's odometry model (the setup's scenario's ``[odometry]``,
the paper's white model where it has none) or the one given, in
:func:`~tunnelkit.design.fastroute.indexed_drive`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._validate import (
    finite_array,
    instance,
    integer,
    nonnegative,
    positive,
    real,
    record,
    rng_or_error,
)
from ..odometry import Odometry
from ..reckoning import posterior_bound
from .bounds import route_geometry
from .drivebound import position_information
from .errordraws import draw_calibration
from .fastroute import SIGMA_V, bound_route, indexed_drive
from .geometry import RouteGeometry
from .setup import DesignSetup, Mount, parse_array
from .trackerfix import REPORTS, START_SIGMA_M, BoundRoute

__all__ = [
    "LONG_DRIVE_SPEED",
    "OFFSET_RESOLUTION_M",
    "SiteRoute",
    "SiteRow",
    "row_pcrlb",
    "site_drive",
    "site_route",
]

#: the drive speed of :meth:`SiteRow.along` [m/s]: 80 km/h
LONG_DRIVE_SPEED = 80.0 / 3.6

#: relative positions (and velocities, in m/s) closer than this share one row of the model [m]
OFFSET_RESOLUTION_M = 1e-6

#: how far inside the tunnel's ends the drive of :meth:`SiteRow.along` starts and stops [m]
END_MARGIN_M = 25.0


def _x_extent(f) -> tuple[float, float]:
    xs = f.corners()[:, 0]
    return float(xs.min()), float(xs.max())


@dataclass(frozen=True)
class SiteRow:
    """``setup``'s site repeated every ``spacing`` [m] along the tunnel axis (module docstring).

    ``setup``: its tunnel (straight, every facet spanning its length), its mounts (the first
    site), its trajectory (the drive). ``count``: the number of sites (default: as many as the
    tunnel holds from the first); ``max_range`` [m]: the farthest a serving site may be along
    the axis (default ``None``: always the nearest). Refused, naming the parameter: a spacing
    <= 0, longer than the tunnel, or not longer than the site's own mounts' extent along x
    (overlapping sites); a count that puts a site outside the tunnel; RRM plates or blockers
    with more than one site (``setup``); a facet shorter than the tunnel (``setup``)."""

    setup: DesignSetup
    spacing: float
    count: int | None = None
    max_range: float | None = None

    def __post_init__(self) -> None:
        instance("setup", self.setup, DesignSetup)
        s = positive("spacing", self.spacing)
        tun = self.setup.tunnel
        lo, hi = (float(x) for x in tun.x_range)
        if s > hi - lo:
            raise ValueError(f"spacing: {s:g} m is longer than the tunnel ({hi - lo:g} m)")
        xs = np.array([m.centre[0] for m in self.setup.mounts])
        if s <= np.ptp(xs):
            raise ValueError(
                f"spacing: {s:g} m is not longer than the site's own mounts span along the "
                f"tunnel ({np.ptp(xs):.3f} m): the sites would overlap"
            )
        fit = int(np.floor((hi - xs.max()) / s * (1 + 1e-12))) + 1
        while fit > 1 and not _inside(self.setup, (fit - 1) * s):
            fit -= 1
        if self.count is not None:
            n = integer("count", self.count, minimum=1)
            if n > fit:
                raise ValueError(
                    f"count: {n} sites every {s:g} m from x = {xs.mean():.1f} m reach x = "
                    f"{xs.mean() + (n - 1) * s:.1f} m, outside the tunnel (x <= {hi:g} m)"
                )
        object.__setattr__(self, "spacing", s)
        object.__setattr__(self, "count", fit if self.count is None else int(self.count))
        if self.max_range is not None:
            object.__setattr__(self, "max_range", positive("max_range", self.max_range))
        if self.count > 1:
            if tun.plates or tun.blockers:
                raise ValueError(
                    "setup: its tunnel has RRM plates or blockers, local features a row of "
                    "identical sites does not repeat; drop them (Tunnel3D.without_plates, "
                    "with_blockers()) or use SiteRow.along"
                )
            for f in tun.facets:
                a, b = _x_extent(f)
                if a > lo + 1e-9 or b < hi - 1e-9:
                    raise ValueError(
                        f"setup: facet {f.name!r} spans x = {a:g}..{b:g} m, not the tunnel's "
                        f"{lo:g}..{hi:g} m: the cross-section must not change along a row"
                    )

    @classmethod
    def along(
        cls,
        setup: DesignSetup,
        spacing: float,
        length: float,
        *,
        speed: float = LONG_DRIVE_SPEED,
        first: float | None = None,
        max_range: float | None = None,
    ) -> SiteRow:
        """A row over a ``length`` [m] drive: ``setup``'s cross-section (plates and blockers
        dropped) lengthened to ``length + 2 END_MARGIN_M``, centred on x = 0; a drive along
        ``setup``'s lane (its first epoch's y and height, its epoch period) at ``speed`` [m/s]
        from ``END_MARGIN_M`` inside the +x end towards -x; the first site's centre at x =
        ``first`` (default: half a spacing inside the -x end), then one every ``spacing``."""
        from ..propagation import lane_trajectory

        instance("setup", setup, DesignSetup)
        from .._physical import MAX_RANGE_M, speeds

        length = positive("length", length)
        if length > MAX_RANGE_M:
            raise ValueError(f"length: at most {MAX_RANGE_M:g} m, got {length:g}")
        speed = float(speeds("speed", speed))
        if speed <= 0:
            raise ValueError(f"speed: must be > 0, got {speed:g}")
        half = 0.5 * length + END_MARGIN_M
        tun = _lengthened(setup.tunnel.without_plates().with_blockers(), half)
        y, h = (float(c) for c in setup.trajectory.position[0, 1:])
        traj = lane_trajectory(
            x_start=half - END_MARGIN_M,
            x_end=-half + END_MARGIN_M,
            speed=speed,
            period=setup.trajectory.period,
            y=y,
            height=h,
        )
        traj = replace(traj, odometry=setup.trajectory.odometry)  # the same car
        centre = float(np.mean([m.centre[0] for m in setup.mounts]))
        x0 = -half + min(0.5 * positive("spacing", spacing), half) if first is None else first
        x0 = real("first", x0)
        if not -half < x0 < half:
            raise ValueError(f"first: x = {x0:g} m lies outside the tunnel ({-half:g}..{half:g} m)")
        mounts = []
        for m in setup.mounts:
            c = m.centre.copy()
            c[0] += x0 - centre
            if not np.all(tun.contains(c, margin=0.0)):
                raise ValueError(f"first: x = {x0:g} m puts mount {m.name!r} outside the tunnel")
            mounts.append(Mount(m.name, c, m.azimuth, m.elevation))
        row_setup = replace(setup, tunnel=tun, mounts=tuple(mounts), trajectory=traj)
        return cls(row_setup, spacing, max_range=max_range)

    @property
    def centres(self) -> np.ndarray:
        """Each site's centre along the axis (count,) [m] (the mean x of its mounts)."""
        x0 = float(np.mean([m.centre[0] for m in self.setup.mounts]))
        return x0 + self.spacing * np.arange(self.count)

    def serving(self, position) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For UE positions (T, 3): the nearest site's index (T,), its distance along the axis
        (T,) [m] and whether it serves (within ``max_range``) (T,)."""
        p = finite_array("position", position, shape=(None, 3))
        dist = np.abs(p[:, :1] - self.centres[None, :])
        idx = np.argmin(dist, axis=1)
        d = dist[np.arange(len(p)), idx]
        served = np.ones(len(p), bool) if self.max_range is None else d <= self.max_range
        return idx, d, served


def _lengthened(tun, half: float):
    """``tun`` (a tunnel whose facets all span its length) over x in ``(-half, half)``."""
    lo, hi = (float(x) for x in tun.x_range)
    facets = []
    for f in tun.facets:
        a, b = _x_extent(f)
        if a > lo + 1e-9 or b < hi - 1e-9:
            raise ValueError(f"setup: facet {f.name!r} does not span the tunnel's length")
        u, v = (np.array(e, float) for e in (f.edge_u, f.edge_v))
        along_u = abs(u[0]) > abs(v[0])
        e = u if along_u else v
        scale = 2 * half / abs(e[0])
        corner = f.corner.copy()
        corner[0] = -half if e[0] > 0 else half
        kw = {"edge_u": u * scale} if along_u else {"edge_v": v * scale}
        facets.append(replace(f, corner=corner, **kw))
    return replace(tun, facets=tuple(facets), x_range=(-half, half))


def _inside(setup: DesignSetup, shift: float) -> bool:
    c = np.array([m.centre for m in setup.mounts]) + np.array([shift, 0.0, 0.0])
    return bool(np.all(setup.tunnel.contains(c, margin=0.0)))


@dataclass(frozen=True)
class SiteRoute:
    """What every drive of one array along a :class:`SiteRow` shares (:func:`site_route`):
    ``route`` the bound route of the first site over the drive's distinct relative positions,
    ``rows`` (T,) the row each epoch draws from, ``site`` (T,) its serving site, ``origin``
    (T, 3) that site's reference antenna (of the array facing the UE), ``served`` (T,) whether
    a site is in range, ``offset`` (T,) the UE's x relative to its serving site's centre [m],
    ``geometry`` the route geometry of the first site's frame the model was built on
    (:func:`~tunnelkit.design.bounds.route_geometry`, one epoch per row; ``None``: not kept)."""

    route: BoundRoute
    rows: np.ndarray
    site: np.ndarray
    origin: np.ndarray
    served: np.ndarray
    offset: np.ndarray
    geometry: RouteGeometry | None = None

    def __post_init__(self) -> None:
        record(self, shapes={"rows": ("T",), "site": ("T",), "origin": ("T", 3),
                             "served": ("T",), "offset": ("T",)})  # fmt: skip

    @property
    def label(self) -> str:
        return self.route.label


def site_route(row: SiteRow, spec, impairments=None, *, report: str = "auto") -> SiteRoute:
    """The per-array part of :func:`site_drive`, computed once: the path error model of
    ``spec`` on the first site over the drive's distinct positions relative to the serving
    site (module docstring), its bound route (``report`` as :func:`~.fastroute.bound_route`)
    and each epoch's row, site and reference antenna. ``impairments``: as
    :func:`~tunnelkit.design.achievable.path_error_model` (default none)."""
    from .achievable import path_error_model

    instance("row", row, SiteRow)
    spec = parse_array(spec)
    if report not in REPORTS:
        raise ValueError(f"report: expected one of {REPORTS}, got {report!r}")
    xs = np.concatenate([a.world[:, 0] for a in row.setup.arrays(spec)])
    if row.spacing <= np.ptp(xs):
        raise ValueError(
            f"spacing: {row.spacing:g} m is not longer than the site's {spec.label} arrays "
            f"span along the tunnel ({np.ptp(xs):.3f} m): the sites would overlap"
        )
    traj = row.setup.trajectory
    site, _, served = row.serving(traj.position)
    shift = row.spacing * site  # the serving site's shift from the first
    rel = traj.position - shift[:, None] * np.array([1.0, 0.0, 0.0])
    key = np.round(np.concatenate([rel, traj.velocity], axis=1) / OFFSET_RESOLUTION_M)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # representatives in the drive's order
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    rows = rank[np.asarray(inverse).reshape(-1)]
    rep = first[order]
    # the first site's frame: the row's tunnel with a spacing more on each end, so that a UE
    # half a spacing before the first site (a UE between two sites, seen from the one behind it)
    # lies inside the tunnel rather than on its end; a path's reflection points lie between the
    # UE and the array, so no path of a position inside the row's tunnel changes
    half = 0.5 * float(np.ptp(row.setup.tunnel.x_range)) + row.spacing
    local = replace(
        row.setup,
        tunnel=_lengthened(row.setup.tunnel, half),
        trajectory=replace(traj, t=traj.t[rep], position=rel[rep], velocity=traj.velocity[rep]),
    )
    geometry = route_geometry(local, spec)
    model = path_error_model(local, spec, impairments, geometry=geometry)
    prepared = bound_route(model, local, spec, report=report)
    origin = prepared.origin[rows] + shift[:, None] * np.array([1.0, 0.0, 0.0])
    offset = traj.position[:, 0] - row.centres[site]
    return SiteRoute(prepared, rows, site, origin, served, offset, geometry)


def row_pcrlb(
    row: SiteRow, route: SiteRoute, odometry: Odometry, sigma_start: float = START_SIGMA_M
) -> np.ndarray:
    """Posterior CRLB (T,) [m] of the 2-D position along ``row``'s drive measured through
    ``route`` (:func:`site_route`) on the V2X messages of ``odometry``, from a start known to
    ``sigma_start`` [m] per axis: :func:`tunnelkit.reckoning.posterior_bound` with the scale
    factor and the heading biases as states and, per epoch, the serving site's information
    about the horizontal position in what the model draws
    (:func:`~tunnelkit.design.drivebound.position_information` of its ``cov``, the clock bias
    eliminated; none where no site is in range). The sites' calibration draws are known to the
    bound (the bound of every unit, as :func:`~tunnelkit.design.drivebound.unit_pcrlb` with
    ``calibration=False``) and the messages arrive on schedule: lower than with losses."""
    instance("row", row, SiteRow)
    instance("route", route, SiteRoute)
    instance("odometry", odometry, Odometry)
    if route.geometry is None:
        raise ValueError("route: built without its geometry (site_route keeps it)")
    info = position_information(route.route.model, route.geometry, drawn=True)[route.rows]
    info[~route.served] = 0.0
    traj = row.setup.trajectory
    v = np.linalg.norm(traj.velocity[:, :2], axis=1)
    th = np.arctan2(traj.velocity[:, 1], traj.velocity[:, 0])
    return posterior_bound(traj.t, v, th, odometry, info, sigma_start=sigma_start)


def site_drive(
    row: SiteRow,
    route: SiteRoute,
    rng: np.random.Generator,
    *,
    n_epochs: int | None = None,
    sigma_v: float = SIGMA_V,
    calibration: tuple | None = None,
    odometry=None,
):
    """One drive along ``row`` measured through ``route`` (:func:`site_route`): a
    :class:`tunnelkit.simulation.DriveData` of the bound route (as
    :func:`~tunnelkit.design.fastroute.bound_drive`: reported covariances, the clock bias per
    epoch, the V2X messages), each epoch's paths drawn from its row and carrying its serving
    site (``PathMeasurements.site``); ``None`` where no site is in range. Every site's array is
    a unit of its own: ``calibration`` a list of one
    :func:`~tunnelkit.design.errordraws.draw_calibration` per site (``None``:
    drawn from ``rng``, site by site, before the drive's other draws). ``odometry``: the V2X
    messages' model (:class:`tunnelkit.odometry.Odometry`; ``None``: the row's trajectory's, its
    scenario's ``[odometry]``)."""
    instance("row", row, SiteRow)
    if odometry is not None:
        instance("odometry", odometry, Odometry)
    instance("route", route, SiteRoute)
    rng = rng_or_error("rng", rng)
    sigma_v = nonnegative("sigma_v", sigma_v)
    T = len(row.setup.trajectory)
    if route.rows.size != T:
        raise ValueError(f"route: built for {route.rows.size} epochs, the row drives {T}")
    if n_epochs is not None:
        T = min(integer("n_epochs", n_epochs, minimum=1), T)
    model = route.route.model
    if calibration is None:
        calibration = [draw_calibration(model, rng) for _ in range(row.count)]
    elif not isinstance(calibration, list | tuple) or len(calibration) != row.count:
        raise TypeError(
            f"calibration: expected a list of {row.count} (phase_rad, gain_db) draws, one per "
            "site (design.errordraws.draw_calibration)"
        )
    return indexed_drive(
        route.route,
        row.setup,
        rng,
        T,
        sigma_v,
        calibration,
        rows=route.rows,
        origin=route.origin,
        served=route.served,
        units=route.site,
        odometry=odometry,
    )
