"""The geometry pre-filter of a ray-traced epoch and the provenance of a traced scene.

On the ray-traced channel every ML fit fails its own residual test (the test judges eq. 1, not
the paths the tracker needs), so the traced treatment keeps an epoch's measurements whatever that
verdict and drops the paths that do not agree with one UE through the tunnel's planes
(:func:`geometry_keep`: :func:`tunnelkit.path_consistency.epoch_consistency` with the
model-error floors :data:`FLOORS` alone); :func:`traced_measurements` is that adapter, the one
:func:`tunnelkit.design.traced.traced_drive` and :mod:`tunnelkit.studies.traced` feed the
tracker. :func:`scene_provenance` / :func:`check_provenance`: what a record measured on the
traced channel depends on (the ray tracer's settings, the trace cache's key), and the check that
refuses a record of another scene.
"""

from __future__ import annotations

import json

import numpy as np

from .._validate import boolean, finite_array, instance
from ..consistency import plane_kinds
from ..path_consistency import epoch_consistency
from ..signal_route import Epoch, SignalRoute
from ..tracking.measurements import PathMeasurements
from .drives import scenario_route

__all__ = [
    "FLOORS",
    "NUISANCE",
    "SIGMA_SCENARIO",
    "check_floors",
    "check_provenance",
    "geometry_keep",
    "geometry_labels",
    "scene_provenance",
    "traced_measurements",
]

#: model-error floors of the geometry pre-filter: (angle [rad], range [m]), chosen on the straight
#: drive, seed 0 (``benchmarks/bench_rt_track.py``); the bound's own sigmas are left out (the
#: traced fits lie thousands of CRLB standard deviations off)
FLOORS = (float(np.radians(0.5)), 0.3)


#: the drive the traced sigmas are measured on (the scene :func:`scene_provenance` reads)
SIGMA_SCENARIO = "italiano2026-straight"


#: the ray-traced route the traced sigmas are measured on (the ML fit judged against noise +
#: diffuse power)
NUISANCE = {"diffuse_floor": True}


def check_floors(floors) -> tuple[float, float]:
    f = finite_array("floors", floors)
    if f.shape != (2,) or np.any(f <= 0):
        raise ValueError(f"floors: expected (angle [rad], range [m]), both > 0, got {floors!r}")
    return float(f[0]), float(f[1])


def geometry_labels(ep: Epoch, route: SignalRoute, floors=FLOORS) -> tuple[np.ndarray, np.ndarray]:
    """The geometry-consistency test of ``ep.measurements`` (residuals in units of the
    model-error ``floors`` = (angle [rad], range [m]) alone, per-path chi-square(3) at 1 %):
    the rows it keeps, and the kind of surface it assigns to each kept row (``"los"`` or
    :func:`~tunnelkit.consistency.plane_kinds` of its plane). An epoch of fewer than two
    paths keeps them all, unassigned (``""``: nothing to test)."""
    instance("ep", ep, Epoch)
    instance("route", route, SignalRoute)
    fa, fr = check_floors(floors)
    m = ep.measurements
    if len(m) < 2:
        return np.arange(len(m)), np.full(len(m), "", dtype="<U7")
    res = epoch_consistency(ep, route, bound=False, floor_angle=fa, floor_range=fr)
    keep = np.flatnonzero(res["keep"])
    names = np.array(("los", *plane_kinds(route.tunnel)))
    return keep, names[res["plane"][keep] + 1]


def geometry_keep(ep: Epoch, route: SignalRoute, floors=FLOORS) -> np.ndarray:
    """Rows of ``ep.measurements`` the geometry-consistency test keeps
    (:func:`geometry_labels`)."""
    return geometry_labels(ep, route, floors)[0]


def traced_measurements(
    ep: Epoch, route: SignalRoute, floors=FLOORS, *, prefilter: bool = True
) -> tuple[PathMeasurements | None, str | None]:
    """The traced design's adapter: ``ep``'s measurements whatever its fit's own verdict
    (``fit_ok``), reduced to the rows :func:`geometry_keep` keeps; ``prefilter=False``: all rows.
    ``(None, reason)`` when no row is left."""
    instance("ep", ep, Epoch)
    instance("route", route, SignalRoute)
    prefilter = boolean("prefilter", prefilter)
    m = ep.measurements
    pm = PathMeasurements.from_arrays(
        m.phi, m.psi, m.kappa, m.d, m.v, warn=False, min_d=route.min_d
    )
    if not prefilter:
        return pm, None
    rows = np.flatnonzero(np.isin(pm.source, geometry_keep(ep, route, floors)))
    if not rows.size:
        return None, "the geometry test kept no path"
    return pm.subset(rows), None


def scene_provenance(route=None) -> dict:
    """What the traced sigmas depend on besides the procedure: ``rt_settings`` (the ray tracer's
    :class:`~tunnelkit.rt.settings.RTSettings`) and ``rt_key`` (the ray-tracing cache's key of the
    drive: scene export hash, settings, arrays, trajectory, radio, cache format, sionna-rt
    version; :meth:`~tunnelkit.rt.cache.RayTracedChannel.key`) of ``route`` (default: the route
    the sigmas are measured on, :data:`SIGMA_SCENARIO` on the ray-traced channel)."""
    if route is None:
        route = scenario_route(SIGMA_SCENARIO, "exact", "sionna", NUISANCE)
    instance("route", route, SignalRoute)
    if route.raytraced is None:
        raise ValueError("route: expected a route on the ray-traced channel (channel='sionna')")
    return {
        "rt_settings": route.raytraced.settings.record(),
        "rt_key": route.raytraced.key(),
    }


def check_provenance(record: dict, current: dict | None = None) -> list[str]:
    """Compare a stored record's ``rt_settings`` / ``rt_key`` with ``current``
    (:func:`scene_provenance` by default). Returns the entries it cannot check (absent from the
    record); raises ``ValueError`` naming every entry that differs (the record belongs to another
    scene or ray tracer and must not be reused)."""
    if not isinstance(record, dict):
        raise TypeError(f"record: expected the dict of measure_traced_errors, got {record!r}")
    cur = scene_provenance() if current is None else current
    if not isinstance(cur, dict) or not {"rt_settings", "rt_key"} <= set(cur):
        raise TypeError("current: expected the dict of scene_provenance")
    unchecked, differ = [], []
    for part in ("rt_settings", "rt_key"):
        old = record.get(part)
        if not isinstance(old, dict):
            unchecked.append(part)
            continue
        for name in sorted(set(old) | set(cur[part])):
            a, b = old.get(name), cur[part].get(name)
            if json.dumps(a, default=str) != json.dumps(b, default=str):
                differ.append(f"{part}.{name}: stored {a!r}, now {b!r}")
    if differ:
        raise ValueError(
            "record: measured on another scene or ray tracer than the current one ("
            + "; ".join(differ)
            + "); re-measure with benchmarks/bench_rt_sigmas.py --write"
        )
    return unchecked
