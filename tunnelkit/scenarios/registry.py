"""The builders that turn a scenario's tables into objects, registered by kind or family.

Four registries, one call protocol each:

* :data:`TUNNELS`, by ``[tunnel] kind``: ``builder(section, get) -> tunnel``;
* :data:`TRAJECTORIES`, by ``[trajectory] kind``: ``builder(section, get, tunnel) -> Trajectory``;
* :data:`ARRAYS`, by family: ``builder(scenario) -> list[ArrayGeometry]`` (``[[base_station.arrays]]``);
* :data:`CHECKS`, by family: ``check(scenario) -> None``, raising :class:`ScenarioError` when the
  base station, the arrays or the route do not fit the tunnel (run once on load).

``section`` is the validated table and ``get`` reads one of its keys with type and shape checks
(:func:`getter`). A module registers its builders when it is imported (:func:`register_tunnel`,
:func:`register_trajectory`, :func:`register_arrays`, :func:`register_check`);
:data:`PROVIDERS` names the module of every built-in kind. This module imports none of them: the
package (:mod:`tunnelkit`) installs the loader (:func:`set_loader`) that the first lookup of a
built-in kind calls with its module's name, so loading a scenario imports only the builders it
needs. Without a loader, looking up a kind nobody registered is a :class:`ScenarioError` naming
the kind and the module to import.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._physical import speeds
from .._validate import callable_, record, text
from ..odometry import WHITE, Odometry
from ..schema import ScenarioError

__all__ = [
    "ARRAYS",
    "CHECKS",
    "PROVIDERS",
    "TRAJECTORIES",
    "TUNNELS",
    "Registry",
    "Trajectory",
    "getter",
    "register_arrays",
    "register_check",
    "register_trajectory",
    "register_tunnel",
    "require",
    "set_loader",
]


@dataclass(frozen=True)
class Trajectory:
    """The vehicle's drive: its sampled ground truth ``t`` (T,), ``position`` (T, dim),
    ``velocity`` (T, dim), and ``odometry``, the model of the speed and heading messages the
    vehicle sends of it (:class:`tunnelkit.odometry.Odometry`; the scenario's ``[odometry]``, the
    paper's white model by default)."""

    t: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    odometry: Odometry = WHITE

    def __post_init__(self) -> None:
        record(self, shapes={"t": ("T",), "position": ("T", "D"), "velocity": ("T", "D")})
        speeds("velocity", self.velocity)

    def __len__(self) -> int:
        return self.t.shape[0]

    @property
    def period(self) -> float:
        """Sampling period [s] (the observation period T1 of Jiang eq. 41)."""
        return float(self.t[1] - self.t[0]) if len(self) > 1 else 0.0


def getter(where: str, section: dict, prefix: str):
    """``get(key, type, shape=None, default=...)`` reading ``section`` with errors naming the key.

    ``where`` (the file name) starts every message and ``prefix`` (the section's dotted name)
    leads the key. ``type`` is ``float`` (the default: a finite number or array, checked against
    ``shape`` with ``None`` for any length), ``int`` or ``str``; a missing key returns ``default``
    when one is given.
    """
    if not isinstance(where, str) or not isinstance(prefix, str):
        raise TypeError(f"where, prefix: expected strings, got {where!r}, {prefix!r}")
    if not isinstance(section, dict):
        raise TypeError(f"section: expected a dict (a TOML table), got {type(section).__name__}")
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


#: the module whose import registers each built-in builder: registry name -> key -> module
PROVIDERS: dict[str, dict[str, str]] = {
    "tunnel.kind": {
        "walls2d": "tunnelkit.scenarios.jiang",
        "semicircular3d": "tunnelkit.propagation",
        "rectangular": "tunnelkit.tunnels",
        "horseshoe": "tunnelkit.tunnels",
        "semicircular": "tunnelkit.tunnels",
    },
    "trajectory.kind": {
        "piecewise_acceleration": "tunnelkit.scenarios.jiang",
        "lane3d": "tunnelkit.propagation",
        "lane": "tunnelkit.tunnels",
        "slalom": "tunnelkit.tunnels",
    },
    "arrays": {
        "italiano2026": "tunnelkit.propagation",
        "user": "tunnelkit.propagation",
    },
    "placement check": {
        "jiang2023": "tunnelkit.scenarios.checks",
        "italiano2026": "tunnelkit.scenarios.checks",
        "user": "tunnelkit.scenarios.checks",
        "halili2022": "tunnelkit.doppler_drive",
    },
}

_loader: list[Callable[[str], Any]] = []


def set_loader(loader: Callable[[str], Any] | None) -> None:
    """Install ``loader(module_name)``, called to import the module of a built-in kind the first
    time it is looked up (``None`` removes it). The package installs
    :func:`importlib.import_module`."""
    if loader is not None:
        callable_("loader", loader)
    _loader[:] = [] if loader is None else [loader]


def require(module: str, where: str = "") -> None:
    """Make sure ``module`` is imported (a scenario file's ``requires`` entry), through the
    installed loader; without one, a :class:`ScenarioError` unless it is imported already."""
    if not isinstance(module, str) or not module:
        raise TypeError(f"module: expected a module name, got {module!r}")
    text("where", where, empty=True)
    if module in sys.modules:
        return
    if not _loader:
        raise ScenarioError(f"{where}: requires {module!r}, which is not imported; import it first")
    _loader[0](module)


class Registry:
    """Builders of one kind of object, by key, all called the same way (``protocol``)."""

    def __init__(self, name: str, protocol: str) -> None:
        self.name = text("name", name)
        self.protocol = text("protocol", protocol)
        self._builders: dict[str, Callable] = {}

    def __repr__(self) -> str:
        return f"Registry({self.name!r}, {self.protocol!r})"

    def register(self, *keys: str):
        """Decorator registering ``builder`` under every one of ``keys``."""
        if not keys or not all(isinstance(k, str) and k for k in keys):
            raise TypeError(f"keys: expected one or more non-empty strings, got {keys!r}")

        def deco(fn):
            callable_("builder", fn)
            for k in keys:
                self._builders[k] = fn
            return fn

        return deco

    def known(self) -> list[str]:
        """Every key with a builder: the registered ones and the built-in ones (:data:`PROVIDERS`)."""
        return sorted(set(self._builders) | set(PROVIDERS.get(self.name, {})))

    def lookup(self, key: str, where: str = "") -> Callable:
        """The builder of ``key``; a built-in one is imported through the loader on first use."""
        text("key", key)
        text("where", where, empty=True)
        if key not in self._builders:
            module = PROVIDERS.get(self.name, {}).get(key)
            if module is None:
                raise ScenarioError(f"{where}: unknown {self.name} {key!r}; known: {self.known()}")
            if _loader and module not in sys.modules:
                _loader[0](module)
            if key not in self._builders:
                raise ScenarioError(
                    f"{where}: {self.name} {key!r} has no registered builder; import {module} "
                    "(it registers it)"
                )
        return self._builders[key]

    def build(self, key: str, where: str, *args):
        """Run the builder of ``key`` on ``args``; its :class:`ScenarioError` s name ``where`` first."""
        builder = self.lookup(key, where)
        try:
            return builder(*args)
        except ScenarioError as exc:
            msg = str(exc)
            if msg.startswith(f"{where}: "):
                raise
            raise ScenarioError(f"{where}: {msg}") from None


TUNNELS = Registry("tunnel.kind", "builder(section, get) -> tunnel")
TRAJECTORIES = Registry("trajectory.kind", "builder(section, get, tunnel) -> Trajectory")
ARRAYS = Registry("arrays", "builder(scenario) -> list[ArrayGeometry]")
CHECKS = Registry("placement check", "check(scenario) -> None")


def register_tunnel(kind: str):
    """Decorator: ``builder(section, get)`` building a tunnel of ``[tunnel] kind = ...``."""
    text("kind", kind)
    return TUNNELS.register(kind)


def register_trajectory(kind: str):
    """Decorator: ``builder(section, get, tunnel) -> Trajectory`` for ``[trajectory] kind = ...``."""
    text("kind", kind)
    return TRAJECTORIES.register(kind)


def register_arrays(*families: str):
    """Decorator: ``builder(scenario) -> list[ArrayGeometry]`` for the families named."""
    return ARRAYS.register(*families)


def register_check(*families: str):
    """Decorator: ``check(scenario)`` run on load for the families named (raises ScenarioError)."""
    return CHECKS.register(*families)
