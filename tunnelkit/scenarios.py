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

import copy
import importlib
import itertools
import os
import re
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .geometry import Tunnel2D
from .schema import ScenarioError, render_template, validate

__all__ = [
    "ALLOWED_REQUIRES",
    "Scenario",
    "ScenarioError",
    "Trajectory",
    "check_all",
    "data_dir",
    "list_scenarios",
    "load_scenario",
    "register_trajectory",
    "register_tunnel",
    "scenario_from_dict",
    "scenario_path",
    "template",
    "with_values",
]


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
        return _prefixed(self.path.name, _TUNNELS[kind], sec, get)

    def base_station(self) -> np.ndarray:
        """Base-station (reference antenna) position from ``[base_station] position``."""
        sec = self.section("base_station")
        return _getter(self.path.name, sec, "base_station")("position", shape=(None,))

    def arrays(self) -> list:
        """The arrays of ``[[base_station.arrays]]`` (:func:`tunnelkit.propagation.scenario_arrays`)."""
        from .propagation import scenario_arrays

        return scenario_arrays(self)

    def trajectory(self, tunnel=None) -> Trajectory:
        """Ground-truth trajectory built from ``[trajectory]`` by its registered ``kind``."""
        sec = self.section("trajectory")
        get = _getter(self.path.name, sec, "trajectory")
        kind = get("kind", str)
        if kind not in _TRAJECTORIES:
            raise ScenarioError(
                f"{self.path.name}: unknown trajectory.kind {kind!r}; known: {sorted(_TRAJECTORIES)}"
            )
        tun = self.tunnel() if tunnel is None else tunnel
        return _prefixed(self.path.name, _TRAJECTORIES[kind], sec, get, tun)

    def noise_levels(self) -> list[tuple[float, float]]:
        """``[(sigma_theta [rad], sigma_d [m]), ...]`` from ``[noise] levels`` given in (deg, m)."""
        lv = self.get("noise.levels", shape=(None, 2))
        return [(float(np.radians(a)), float(b)) for a, b in lv]


def _prefixed(where: str, builder, *args):
    """Run a registered builder; its ``ScenarioError`` s name the file first."""
    try:
        return builder(*args)
    except ScenarioError as exc:
        msg = str(exc)
        if msg.startswith(f"{where}: "):
            raise
        raise ScenarioError(f"{where}: {msg}") from None


def list_scenarios() -> list[str]:
    """Names of the presets in ``data/scenarios/``."""
    return sorted(p.stem for p in (data_dir() / "scenarios").glob("*.toml"))


#: modules a file's ``requires`` may name (they register tunnel/trajectory kinds on import)
ALLOWED_REQUIRES = ("tunnelkit.propagation", "tunnelkit.tunnels")
#: modules imported for every file of a family (their builders)
_FAMILY_MODULES = {
    "italiano2026": ("tunnelkit.propagation",),
    "user": ("tunnelkit.propagation", "tunnelkit.tunnels"),
}
_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")


def scenario_path(name: str | os.PathLike) -> Path:
    """The file a scenario name or path refers to (``ScenarioError`` if it is not allowed).

    A plain name (letters, digits, ``.``, ``_``, ``-``; no directory part) resolves inside
    ``data/scenarios/`` only; anything else (a :class:`~pathlib.Path`, or a string with a
    directory part or ending in ``.toml``) must be an existing ``.toml`` file.
    """
    if isinstance(name, os.PathLike) or (
        isinstance(name, str) and (name.endswith(".toml") or "/" in name or os.sep in name)
    ):
        path = Path(name)
        if path.suffix != ".toml":
            raise ScenarioError(
                f"name: {str(name)!r} is neither a preset name nor a path to a .toml file"
            )
        if not path.is_file():
            raise ScenarioError(f"name: no such scenario file {str(path)!r}")
        return path
    if not isinstance(name, str) or not name:
        raise TypeError(f"name: expected a scenario name string or a path, got {name!r}")
    root = (data_dir() / "scenarios").resolve()
    path = (root / f"{name}.toml").resolve()
    if not _NAME_RE.fullmatch(name) or not path.is_relative_to(root) or not path.is_file():
        raise ScenarioError(
            f"name: unknown scenario {name!r}; available: {', '.join(list_scenarios())}"
        )
    return path


def load_scenario(name: str | os.PathLike) -> Scenario:
    """Load and validate a scenario: a preset name (``"jiang2023-straight"``) or a ``.toml`` path.

    Names resolve inside ``data/scenarios/`` only (see :func:`scenario_path`); a path such as
    ``"my-tunnel.toml"`` or ``Path("tunnels/mine.toml")`` loads your own file. The file is checked
    against its family's schema (:mod:`tunnelkit.schema`): required keys, types, ranges, unknown
    keys (with the nearest valid name), the base station, its arrays and the trajectory inside
    the tunnel. Any problem is a :class:`ScenarioError` naming the file and the key.
    """
    path = scenario_path(name)
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path.name}: not valid TOML ({exc})") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path.name}: cannot read ({exc})") from None
    return scenario_from_dict(raw, path)


def scenario_from_dict(raw: dict, path: str | os.PathLike = "<dict>") -> Scenario:
    """Validate and build a scenario from a parsed table (what :func:`load_scenario` does after
    reading the file); ``path`` only labels the messages. No file is read or written.
    """
    if not isinstance(raw, dict):
        raise TypeError(f"raw: expected a dict of TOML tables, got {type(raw).__name__}")
    raw = copy.deepcopy(raw)
    path = Path(path)
    where = path.name
    family, sections = validate(raw, where)
    for mod in sections.get("requires", []):
        if mod not in ALLOWED_REQUIRES:
            raise ScenarioError(
                f"{where}: 'requires' entries must be one of {list(ALLOWED_REQUIRES)}, got {mod!r}"
            )
    for mod in (*_FAMILY_MODULES.get(family, ()), *sections.get("requires", [])):
        importlib.import_module(mod)
    if family == "user":
        _derive_user(sections, raw, where)
    sc = Scenario(
        name=sections["name"],
        paper=sections.get("paper", ""),
        description=sections.get("description", ""),
        path=path,
        sections=sections,
        family=family,
        raw=raw,
    )
    _check_placement(sc)
    return sc


_INDEX_RE = re.compile(r"(\w+)\[(\d+|\*)\]")


def with_values(scenario: Scenario, changes: dict[str, Any]) -> Scenario:
    """A copy of ``scenario`` with dotted keys of its file replaced, validated again.

    ``{"radio.fc": 28e9, "base_station.position": [0, 0, 5.5],
    "base_station.arrays[*].shape": [16, 16], "base_station.arrays[0].tilt_deg": 10.0}``;
    ``[*]`` sets the key in every table of the array. Setting a value to ``None`` removes the key.
    Raises :class:`ScenarioError` naming the key if the result is invalid (design sweeps).
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    if not isinstance(changes, dict):
        raise TypeError(f"changes: expected a dict of dotted keys, got {type(changes).__name__}")
    raw = copy.deepcopy(scenario.raw)
    for dotted, value in changes.items():
        if not isinstance(dotted, str) or not dotted:
            raise TypeError(f"changes: keys must be dotted key strings, got {dotted!r}")
        *parents, last = dotted.split(".")
        targets = [raw]
        for part in parents:
            m = _INDEX_RE.fullmatch(part)
            name, idx = (m.group(1), m.group(2)) if m else (part, None)
            nxt = []
            for t in targets:
                if idx is None:
                    nxt.append(t.setdefault(name, {}))
                    continue
                arr = t.get(name)
                if not isinstance(arr, list):
                    raise ScenarioError(
                        f"{scenario.path.name}: '{dotted}': no array of tables {name!r}"
                    )
                if idx == "*":
                    nxt.extend(arr)
                elif int(idx) < len(arr):
                    nxt.append(arr[int(idx)])
                else:
                    raise ScenarioError(
                        f"{scenario.path.name}: '{dotted}': {name} has {len(arr)} tables"
                    )
            targets = nxt
        for t in targets:
            if not isinstance(t, dict):
                raise ScenarioError(f"{scenario.path.name}: '{dotted}': not a table")
            if value is None:
                t.pop(last, None)
            else:
                t[last] = copy.deepcopy(value)
    return scenario_from_dict(raw, scenario.path)


def _derive_user(sec: dict, raw: dict, where: str) -> None:
    """Fill the keys the shared builders read from a ``user`` file's friendlier ones."""
    from .constants import wavelength

    radio = sec["radio"]
    lam = float(wavelength(radio["fc"]))
    for i, (arr, given) in enumerate(
        zip(sec["base_station"]["arrays"], raw["base_station"]["arrays"])
    ):
        if "spacing_m" in given and "spacing_wavelengths" in given:
            raise ScenarioError(
                f"{where}: 'base_station.arrays[{i}].spacing_m' and '.spacing_wavelengths' both "
                "given; keep one"
            )
        arr["elevation_deg"] = -arr["tilt_deg"]
        arr["spacing"] = (
            arr["spacing_m"] if "spacing_m" in arr else arr["spacing_wavelengths"] * lam
        )
    if "n_rb" not in radio:
        n_rb = int(np.floor(0.983 * radio["bandwidth"] / (12 * radio["scs"]) + 1e-9))
        if n_rb < 1:
            raise ScenarioError(
                f"{where}: 'radio.bandwidth' {radio['bandwidth']:g} Hz holds no resource block of "
                f"12 subcarriers at radio.scs = {radio['scs']:g} Hz"
            )
        radio["n_rb"] = n_rb


def _check_placement(sc: Scenario) -> None:
    """Build tunnel and trajectory once; base station, arrays and route must lie inside."""
    where, sec = sc.path.name, sc.sections
    if sc.family == "halili2022":
        w, h = sec["tube"]["width"], sec["tube"]["height"]
        for key, val, lim in (
            ("transmitter.tx_y", sec["transmitter"]["tx_y"], w / 2),
            ("vehicle.lane_y", sec["vehicle"]["lane_y"], w / 2),
        ):
            if not abs(val) < lim:
                raise ScenarioError(
                    f"{where}: '{key}' = {val:g} m lies outside the {w:g} m wide tube (|y| < {lim:g})"
                )
        for key, val in (
            ("transmitter.tx_z", sec["transmitter"]["tx_z"]),
            ("vehicle.rx_height", sec["vehicle"]["rx_height"]),
        ):
            if not 0 < val < h:
                raise ScenarioError(
                    f"{where}: '{key}' = {val:g} m lies outside the {h:g} m high tube (0 < z < {h:g})"
                )
        veh = sec["vehicle"]
        n = veh["speed"] * veh["duration"] / veh["spacing"]
        if n > MAX_SAMPLES:
            raise ScenarioError(
                f"{where}: 'vehicle.spacing' {veh['spacing']:g} m gives {n:.3g} samples over the "
                f"drive (speed x duration / spacing), more than {MAX_SAMPLES:g}"
            )
        return
    _check_sizes(sc)
    tun = sc.tunnel()
    bs = np.asarray(sec["base_station"]["position"], dtype=float)
    if sc.family == "jiang2023":
        if not tun.contains(bs):
            raise ScenarioError(
                f"{where}: 'base_station.position' {bs.tolist()} lies outside the tunnel walls"
            )
    else:
        _check_arrays_inside(sc, tun, bs)
    sc.trajectory(tun)


#: most trajectory samples a scenario file may ask for
MAX_SAMPLES = 1_000_000
#: most elements per array (64 x 64)
MAX_ELEMENTS = 4096
#: largest channel tensor (elements x tones x symbols, complex128) a file may ask for
MAX_TENSOR_BYTES = 2 * 2**30


def _check_sizes(sc: Scenario) -> None:
    """Refuse sizes that would exhaust memory before anything is allocated."""
    where, sec = sc.path.name, sc.sections
    tr = sec["trajectory"]
    if sc.family == "jiang2023":
        levels = np.asarray(sec.get("noise", {}).get("levels", np.zeros((0, 2))), dtype=float)
        if levels.size and np.any(levels[:, 0] > 180.0):
            raise ScenarioError(f"{where}: 'noise.levels' angle sigmas must be <= 180 deg")
        return
    radio = sec["radio"]
    n_rb = radio.get("n_rb", 273)
    if 12 * n_rb * radio["scs"] > radio["bandwidth"] * 1.0001:
        raise ScenarioError(
            f"{where}: 'radio.n_rb' {n_rb} resource blocks at radio.scs = {radio['scs']:g} Hz "
            f"occupy {12 * n_rb * radio['scs']:g} Hz, more than radio.bandwidth = "
            f"{radio['bandwidth']:g} Hz"
        )
    n_tones = -(-12 * n_rb // radio["comb"])
    for i, arr in enumerate(sec["base_station"]["arrays"]):
        m = arr["shape"][0] * arr["shape"][1]
        if m > MAX_ELEMENTS:
            raise ScenarioError(
                f"{where}: 'base_station.arrays[{i}].shape' {arr['shape']} has {m} elements, "
                f"more than {MAX_ELEMENTS}"
            )
        size = 16 * m * n_tones * radio["n_symbols"]
        if size > MAX_TENSOR_BYTES:
            raise ScenarioError(
                f"{where}: 'base_station.arrays[{i}].shape' {arr['shape']} x {n_tones} tones x "
                f"{radio['n_symbols']} symbols needs a {size / 2**30:.1f} GiB channel tensor, "
                f"more than {MAX_TENSOR_BYTES / 2**30:g} GiB (fewer elements, radio.n_symbols or "
                "a larger radio.comb)"
            )
    n = abs(tr["x_end"] - tr["x_start"]) / (tr["speed"] * tr["period"])
    if n > MAX_SAMPLES:
        raise ScenarioError(
            f"{where}: 'trajectory.period' {tr['period']:g} s gives {n:.3g} epochs "
            f"(|x_end - x_start| / (speed period)), more than {MAX_SAMPLES:g}"
        )


def _check_arrays_inside(sc: Scenario, tun, bs: np.ndarray) -> None:
    where = sc.path.name
    if not tun.contains(bs, margin=1e-6):
        raise ScenarioError(
            f"{where}: 'base_station.position' {bs.tolist()} lies outside the tunnel "
            "(in a wall, above the roof, under the road or beyond its ends)"
        )
    try:
        arrays = sc.arrays()
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ScenarioError):
            raise
        raise ScenarioError(f"{where}: base_station.arrays: {exc}") from None
    lo = np.array([tun.x_range[0], -tun.width / 2, 0.0])
    hi = np.array([tun.x_range[1], tun.width / 2, tun.height])
    for i, arr in enumerate(arrays):
        full = f"base_station.arrays[{i}]"
        if not tun.contains(arr.origin, margin=1e-6):
            raise ScenarioError(
                f"{where}: '{full}.offset' puts the reference antenna at {arr.origin.tolist()}, "
                "outside the tunnel"
            )
        # elements: inside the tunnel's bounding box (the paper's 10 x 10 URA at 4.8 m reaches a
        # few cm above the 12-facet polygon near the crown, so facets would reject the paper)
        out = ~np.all((arr.world > lo - 1e-9) & (arr.world < hi + 1e-9), axis=-1)
        if np.any(out):
            raise ScenarioError(
                f"{where}: '{full}.shape' {arr.M} elements reach {arr.world[int(np.argmax(out))].round(3).tolist()}, "
                f"outside the tunnel's cross-section (|y| <= {tun.width / 2:g}, 0 <= z <= {tun.height:g} m)"
            )


def template(name: str, preset: str | os.PathLike) -> str:
    """A commented TOML template named ``name`` holding ``preset``'s values.

    Every key is documented in a comment from the schema (doc, unit, range, default). A preset of
    the JAVELIN family (``italiano2026-*``) becomes a ``user`` file (your own tunnel): kind
    ``semicircular``, arrays with ``tilt_deg``, the trajectory as ``lane`` or ``slalom``; a
    ``user`` preset is copied; Jiang and Halili presets keep their family.
    """
    if not isinstance(name, str) or not _NAME_RE.fullmatch(name):
        raise ValueError(
            f"name: expected a scenario name of letters, digits, '.', '_' or '-', got {name!r}"
        )
    sc = load_scenario(preset)
    vals = {k: v for k, v in sc.raw.items()}
    family = sc.family
    if family == "italiano2026":
        family, vals = "user", _italiano_to_user(sc.raw)
    vals["name"] = name
    vals["description"] = f"My tunnel, from {sc.name}: {sc.description}".strip()
    head = (
        f"Scenario {name!r}, written by `tunnelkit scenarios new {name} --from {sc.name}`.\n"
        f"Load it with tk.load_scenario('{name}.toml'); check it with `tunnelkit scenarios {name}.toml`.\n"
        "Units: SI (m, s, Hz) and degrees; x along the tunnel, y across (+y = left), z up, road at z = 0."
    )
    return render_template(family, vals, head)


def _italiano_to_user(raw: dict) -> dict:
    out = {k: v for k, v in raw.items() if k not in ("paper", "requires")}
    tun = dict(raw["tunnel"])
    tun["kind"] = "semicircular"
    out["tunnel"] = tun
    bs = dict(raw["base_station"])
    arrs = []
    for a in bs.get("arrays", []):
        a = dict(a)
        a["tilt_deg"] = -a.pop("elevation_deg")
        arrs.append(a)
    bs["arrays"] = arrs
    out["base_station"] = bs
    tr = dict(raw["trajectory"])
    amp = tr.pop("slalom_amplitude", 0.0)
    wl = tr.pop("slalom_wavelength", 20.0)
    if amp > 0:
        tr.update(kind="slalom", amplitude=amp, wavelength=wl)
    else:
        tr["kind"] = "lane"
    out["trajectory"] = tr
    return out


def check_all(paths=None) -> list[tuple[str, str | None]]:
    """``[(name, error or None), ...]`` for every preset (or the given names/paths)."""
    out = []
    for n in list_scenarios() if paths is None else paths:
        try:
            load_scenario(n)
            out.append((str(n), None))
        except (ScenarioError, TypeError) as exc:
            out.append((str(n), str(exc)))
    return out


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
