"""Scenario builders of the JAVELIN family and your own tunnels: RRM plates and blockers from
``[tunnel]`` tables, the ``semicircular3d`` tunnel, the ``lane3d`` trajectory and the arrays of
``[[base_station.arrays]]`` (registered in :mod:`tunnelkit.scenarios.registry`)."""

from __future__ import annotations

import numpy as np

from .._physical import speeds
from .._validate import integer, nonnegative, positive, real
from ..arrays import ArrayGeometry, make_array
from ..budget import check_bytes
from ..scenarios import (
    Scenario,
    ScenarioError,
    Trajectory,
    register_arrays,
    register_trajectory,
    register_tunnel,
)
from .surfaces import Box, Facet, Tunnel3D, road_marking, semicircular_tunnel

__all__ = ["lane_trajectory", "plate_from_table", "scenario_arrays"]


def plate_from_table(i: int, tab: dict) -> Facet:
    """The RRM plate of the table ``tunnel.plates[i]`` (keys ``x_range``, ``y``, ``z``, ``width``,
    ``inclination_deg``, optional ``name``; see :func:`road_marking`), a :class:`ScenarioError`
    naming ``tunnel.plates[i]`` and the key if a key is missing or a value is invalid."""
    i = integer("i", i, minimum=0)
    where = f"tunnel.plates[{i}]"
    if not isinstance(tab, dict):
        raise ScenarioError(f"{where}: expected a table (tab), got {type(tab).__name__}")
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
    plates = tuple(plate_from_table(i, t) for i, t in enumerate(sec.get("plates", [])))
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
    speed, period = float(speeds("speed", positive("speed", speed))), positive("period", period)
    lam = positive("slalom_wavelength", slalom_wavelength)
    x_start, x_end = real("x_start", x_start), real("x_end", x_end)
    y, height = real("y", y), nonnegative("height", height)  # the antenna above the road
    slalom_amplitude = nonnegative("slalom_amplitude", slalom_amplitude)
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
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a scenarios.Scenario, got {type(scenario).__name__}")
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
        first = next((j for j, a in enumerate(out[:-1]) if a.name == out[-1].name), None)
        if first is not None:
            raise ScenarioError(
                f"{scenario.path.name}: 'base_station.arrays[{i}].name' {out[-1].name!r} is also "
                f"the name of base_station.arrays[{first}]; array names must be distinct (the "
                "calibration and the ray-traced channel are keyed by name)"
            )
    return out
