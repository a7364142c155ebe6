"""Scenario presets: each paper's setup as a TOML file under ``data/scenarios/`` loaded by name.

A scenario file has a few top-level keys (``name``, ``paper``, ``description``) and sections
(``[tunnel]``, ``[base_station]``, ``[trajectory]``, ``[noise]``, ``[radio]`` ...). Sections with a
``kind`` key are built into objects by a registered builder (``tunnel.kind = "walls2d"`` gives a
:class:`tunnelkit.geometry.Tunnel2D`); later chapters register their own kinds with
:func:`register_tunnel` / :func:`register_trajectory`. Errors name the file and the key.

    >>> import tunnelkit as tk
    >>> sc = tk.load_scenario("jiang2023-straight")
    >>> traj = sc.trajectory()          # times, positions, velocities
"""

from __future__ import annotations

import importlib
import itertools
import os
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .geometry import Tunnel2D

__all__ = [
    "Scenario",
    "ScenarioError",
    "Trajectory",
    "data_dir",
    "list_scenarios",
    "load_scenario",
    "register_trajectory",
    "register_tunnel",
]


class ScenarioError(ValueError):
    """A scenario that does not exist or whose file is malformed (the message names the key)."""


def data_dir() -> Path:
    """The repository's ``data/`` folder (override with ``TUNNELKIT_DATA``)."""
    env = os.environ.get("TUNNELKIT_DATA")
    return Path(env) if env else Path(__file__).resolve().parent.parent / "data"


@dataclass(frozen=True)
class Trajectory:
    """Sampled ground truth: ``t`` (T,), ``position`` (T, dim), ``velocity`` (T, dim)."""

    t: np.ndarray
    position: np.ndarray
    velocity: np.ndarray

    def __len__(self) -> int:
        return self.t.shape[0]

    @property
    def period(self) -> float:
        """Sampling period [s] (the observation period T1 of Jiang eq. 41)."""
        return float(self.t[1] - self.t[0]) if len(self) > 1 else 0.0


_TUNNELS: dict[str, Callable[[dict, Callable], Any]] = {}
_TRAJECTORIES: dict[str, Callable[[dict, Callable, Any], Trajectory]] = {}


def register_tunnel(kind: str):
    """Decorator: ``builder(section, get)`` building a tunnel of ``[tunnel] kind = ...``."""

    def deco(fn):
        _TUNNELS[kind] = fn
        return fn

    return deco


def register_trajectory(kind: str):
    """Decorator: ``builder(section, get, tunnel) -> Trajectory`` for ``[trajectory] kind = ...``."""

    def deco(fn):
        _TRAJECTORIES[kind] = fn
        return fn

    return deco


def _getter(where: str, section: dict, prefix: str):
    """``get(key, type, shape=None, default=...)`` reading ``section`` with errors naming the key."""
    missing = object()

    def get(key: str, kind: type = float, *, shape: tuple | None = None, default: Any = missing):
        full = f"{prefix}.{key}" if prefix else key
        if key not in section:
            if default is not missing:
                return default
            raise ScenarioError(f"{where}: missing key '{full}'")
        val = section[key]
        if kind is str:
            if not isinstance(val, str):
                raise ScenarioError(f"{where}: '{full}' must be a string, got {val!r}")
            return val
        if kind is int:
            if isinstance(val, bool) or not isinstance(val, int):
                raise ScenarioError(f"{where}: '{full}' must be an integer, got {val!r}")
            return val
        try:
            arr = np.asarray(val, dtype=float)
        except (TypeError, ValueError):
            raise ScenarioError(f"{where}: '{full}' must be numeric, got {val!r}") from None
        if shape is not None and (
            arr.ndim != len(shape)
            or any(s is not None and s != a for s, a in zip(shape, arr.shape))
        ):
            raise ScenarioError(f"{where}: '{full}' must have shape {shape}, got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ScenarioError(f"{where}: '{full}' must be finite")
        return float(arr) if arr.ndim == 0 else arr

    return get


@dataclass(frozen=True)
class Scenario:
    """A loaded preset. ``sections`` holds the raw TOML tables; helpers build objects from them."""

    name: str
    paper: str
    description: str
    path: Path
    sections: dict[str, Any] = field(repr=False)

    def section(self, key: str) -> dict[str, Any]:
        """A raw TOML table (``ScenarioError`` naming it if absent)."""
        sec = self.sections.get(key)
        if not isinstance(sec, dict):
            raise ScenarioError(f"{self.path.name}: missing section [{key}]")
        return sec

    def get(self, key: str, kind: type = float, **kw):
        """Read ``"section.key"`` with type/shape checks, e.g. ``sc.get("radio.fc")``."""
        sec_name, _, k = key.rpartition(".")
        sec = self.section(sec_name) if sec_name else self.sections
        return _getter(self.path.name, sec, sec_name)(k, kind, **kw)

    def tunnel(self):
        """The tunnel built from ``[tunnel]`` by its registered ``kind``."""
        sec = self.section("tunnel")
        get = _getter(self.path.name, sec, "tunnel")
        kind = get("kind", str)
        if kind not in _TUNNELS:
            raise ScenarioError(
                f"{self.path.name}: unknown tunnel.kind {kind!r}; known: {sorted(_TUNNELS)}"
            )
        return _TUNNELS[kind](sec, get)

    def base_station(self) -> np.ndarray:
        """Base-station (reference antenna) position from ``[base_station] position``."""
        sec = self.section("base_station")
        return _getter(self.path.name, sec, "base_station")("position", shape=(None,))

    def trajectory(self, tunnel=None) -> Trajectory:
        """Ground-truth trajectory built from ``[trajectory]`` by its registered ``kind``."""
        sec = self.section("trajectory")
        get = _getter(self.path.name, sec, "trajectory")
        kind = get("kind", str)
        if kind not in _TRAJECTORIES:
            raise ScenarioError(
                f"{self.path.name}: unknown trajectory.kind {kind!r}; known: {sorted(_TRAJECTORIES)}"
            )
        return _TRAJECTORIES[kind](sec, get, self.tunnel() if tunnel is None else tunnel)

    def noise_levels(self) -> list[tuple[float, float]]:
        """``[(sigma_theta [rad], sigma_d [m]), ...]`` from ``[noise] levels`` given in (deg, m)."""
        lv = self.get("noise.levels", shape=(None, 2))
        return [(float(np.radians(a)), float(b)) for a, b in lv]


def list_scenarios() -> list[str]:
    """Names of the presets in ``data/scenarios/``."""
    return sorted(p.stem for p in (data_dir() / "scenarios").glob("*.toml"))


def load_scenario(name: str) -> Scenario:
    """Load a preset by name, e.g. ``"jiang2023-straight"`` (``ScenarioError`` if unknown/malformed)."""
    if not isinstance(name, str) or not name:
        raise TypeError(f"name: expected a scenario name string, got {name!r}")
    path = Path(name) if name.endswith(".toml") else data_dir() / "scenarios" / f"{name}.toml"
    if not path.is_file():
        raise ScenarioError(
            f"name: unknown scenario {name!r}; available: {', '.join(list_scenarios())}"
        )
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path.name}: not valid TOML ({exc})") from None
    get = _getter(path.name, raw, "")
    # modules that register this preset's tunnel/trajectory kinds (e.g. "tunnelkit.propagation")
    for mod in raw.get("requires", []):
        if not isinstance(mod, str) or not mod.startswith("tunnelkit."):
            raise ScenarioError(
                f"{path.name}: 'requires' entries must name tunnelkit modules, got {mod!r}"
            )
        importlib.import_module(mod)
    sc = Scenario(
        name=get("name", str),
        paper=get("paper", str),
        description=get("description", str, default=""),
        path=path,
        sections=raw,
    )
    # build once so a malformed file fails at load time, naming the key
    if "tunnel" in raw:
        sc.tunnel()
    if "trajectory" in raw:
        sc.trajectory()
    return sc


# --- builders for Jiang et al. 2023 -------------------------------------------------------------


@register_tunnel("walls2d")
def _walls2d(sec: dict, get) -> Tunnel2D:
    walls = get("walls", shape=(2, 3))
    try:
        return Tunnel2D.from_lines(walls[0], walls[1])
    except ValueError as exc:
        raise ScenarioError(f"tunnel.walls: {exc}") from None


@register_trajectory("piecewise_acceleration")
def _piecewise(sec: dict, get, tunnel) -> Trajectory:
    """Constant acceleration per segment, given in the tunnel frame (along, across) [m/s^2].

    ``start`` [m] and ``velocity`` [m/s] are in global (x, y); ``segments = [[duration, a_along,
    a_across], ...]``; samples every ``period`` seconds for ``steps`` samples.
    """
    start = get("start", shape=(2,))
    vel = get("velocity", shape=(2,))
    period = get("period")
    steps = get("steps", int)
    if period <= 0:
        raise ScenarioError("trajectory.period: must be > 0")
    if steps < 2:
        raise ScenarioError("trajectory.steps: must be >= 2")
    segs = get("segments", shape=(None, 3), default=np.zeros((0, 3)))
    if np.any(segs[:, 0] <= 0) if len(segs) else False:
        raise ScenarioError("trajectory.segments: durations must be > 0")
    t = np.arange(steps) * period
    # acceleration as a function of time (zero after the last segment)
    edges = np.concatenate([[0.0], np.cumsum(segs[:, 0])]) if len(segs) else np.array([0.0])
    acc_tf = np.zeros((steps, 2))
    for (t0, t1), (_, a_al, a_ac) in zip(itertools.pairwise(edges), segs):
        acc_tf[(t >= t0) & (t < t1)] = (a_al, a_ac)
    if isinstance(tunnel, Tunnel2D):
        basis = np.stack([tunnel.axis, tunnel.across])  # rows: along, across
    else:
        basis = np.eye(2)
    acc = acc_tf @ basis
    # exact integration of piecewise-constant acceleration on the sample grid
    vel_t = np.vstack([vel, vel + np.cumsum(acc[:-1] * period, axis=0)])
    pos = np.vstack(
        [start, start + np.cumsum(vel_t[:-1] * period + 0.5 * acc[:-1] * period**2, axis=0)]
    )
    if isinstance(tunnel, Tunnel2D) and not np.all(tunnel.contains(pos)):
        k = int(np.argmin(tunnel.contains(pos)))
        raise ScenarioError(
            f"trajectory: leaves the tunnel at sample {k} (t = {t[k]:.2f} s, position {pos[k]})"
        )
    return Trajectory(t=t, position=pos, velocity=vel_t)
