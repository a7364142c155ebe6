"""The loaded scenario: its validated tables and the objects its registered builders make."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from .._validate import record, text
from ..odometry import Odometry
from ..schema import ScenarioError
from .registry import ARRAYS, TRAJECTORIES, TUNNELS, Trajectory, getter

__all__ = ["Scenario"]


@dataclass(frozen=True)
class Scenario:
    """A loaded, validated scenario.

    ``family`` is ``"jiang2023"``, ``"italiano2026"``, ``"halili2022"`` or ``"user"`` (your own
    tunnel, no ``paper`` key; ``paper`` is then ``""``). ``sections`` holds the validated tables with
    defaults filled in (for ``user`` files also the derived keys the builders read:
    ``base_station.arrays[i].elevation_deg = -tilt_deg``, ``.spacing`` in metres and
    ``radio.n_rb``); ``raw`` is the file exactly as parsed.
    """

    name: str
    paper: str
    description: str
    path: Path
    sections: dict[str, Any] = field(repr=False)
    family: str = ""
    raw: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        record(self, may_be_empty=("paper", "description"))

    def section(self, key: str) -> dict[str, Any]:
        """A raw TOML table (``ScenarioError`` naming it if absent)."""
        sec = self.sections.get(text("key", key))
        if not isinstance(sec, dict):
            raise ScenarioError(f"{self.path.name}: missing section [{key}]")
        return sec

    def get(self, key: str, kind: type = float, **kw):
        """Read ``"section.key"`` with type/shape checks, e.g. ``sc.get("radio.fc")``."""
        if not isinstance(key, str) or not key:
            raise TypeError(f"key: expected a dotted key such as 'radio.fc', got {key!r}")
        if kind not in (float, int, str):
            raise TypeError(f"kind: expected float, int or str, got {kind!r}")
        sec_name, _, k = key.rpartition(".")
        sec = self.section(sec_name) if sec_name else self.sections
        return getter(self.path.name, sec, sec_name)(k, kind, **kw)

    def tunnel(self):
        """The tunnel built from ``[tunnel]`` by the builder registered for its ``kind``."""
        sec = self.section("tunnel")
        get = getter(self.path.name, sec, "tunnel")
        return TUNNELS.build(get("kind", str), self.path.name, sec, get)

    def base_station(self) -> np.ndarray:
        """Base-station (reference antenna) position from ``[base_station] position``."""
        sec = self.section("base_station")
        return getter(self.path.name, sec, "base_station")("position", shape=(None,))

    def arrays(self) -> list:
        """The arrays of ``[[base_station.arrays]]`` (:func:`tunnelkit.propagation.scenario_arrays`)."""
        return ARRAYS.lookup(self.family, self.path.name)(self)

    def trajectory(self, tunnel=None) -> Trajectory:
        """The drive built from ``[trajectory]`` by the builder of its ``kind``, with the
        scenario's :meth:`odometry`."""
        if tunnel is not None and not callable(getattr(tunnel, "contains", None)):
            raise TypeError(
                f"tunnel: expected a tunnel (tunnel2d.Tunnel2D or propagation.Tunnel3D), got "
                f"{type(tunnel).__name__}"
            )
        sec = self.section("trajectory")
        get = getter(self.path.name, sec, "trajectory")
        kind = get("kind", str)
        TRAJECTORIES.lookup(
            kind, self.path.name
        )  # an unknown kind fails before the tunnel is built
        tun = self.tunnel() if tunnel is None else tunnel
        traj = TRAJECTORIES.build(kind, self.path.name, sec, get, tun)
        return replace(traj, odometry=self.odometry()) if "odometry" in self.sections else traj

    def odometry(self) -> Odometry:
        """The model of the vehicle's speed and heading messages from ``[odometry]``
        (:func:`tunnelkit.scenarios.odometry.odometry_from_scenario`; without it the paper's white
        model)."""
        from .odometry import odometry_from_scenario  # read for a scenario with the section only

        return odometry_from_scenario(self)

    def noise_levels(self) -> list[tuple[float, float]]:
        """``[(sigma_theta [rad], sigma_d [m]), ...]`` from ``[noise] levels`` given in (deg, m)."""
        lv = self.get("noise.levels", shape=(None, 2))
        return [(float(np.radians(a)), float(b)) for a, b in lv]
