"""Finding, reading and validating scenario files: presets by name in ``data/scenarios/``, your
own files by path and parsed tables (:func:`scenario_from_dict`); edited copies are
:mod:`tunnelkit.scenarios.edit`'s."""

from __future__ import annotations

import copy
import os
import re
import tomllib
from pathlib import Path

from ..schema import ScenarioError, validate
from .checks import check_placement
from .model import Scenario
from .registry import require

__all__ = [
    "ALLOWED_REQUIRES",
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "MAX_NAME_LENGTH",
    "NAME_RE",
    "data_dir",
    "list_scenarios",
    "load_scenario",
    "scenario_from_dict",
    "scenario_path",
]


def data_dir() -> Path:
    """The repository's ``data/`` folder (override with ``TUNNELKIT_DATA``)."""
    env = os.environ.get("TUNNELKIT_DATA")
    return Path(env) if env else Path(__file__).resolve().parents[2] / "data"


def list_scenarios() -> list[str]:
    """Names of the presets in ``data/scenarios/``."""
    return sorted(p.stem for p in (data_dir() / "scenarios").glob("*.toml"))


#: modules a file's ``requires`` may name (they register tunnel/trajectory kinds on import;
#: loaded through :func:`tunnelkit.scenarios.registry.require`)
ALLOWED_REQUIRES = ("tunnelkit.propagation", "tunnelkit.tunnels")
#: a preset name: letters, digits, ".", "_" and "-", no directory part
NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")
#: longest preset or template name (a file name, ``NAME.toml``, must fit the file system's 255)
MAX_NAME_LENGTH = 100
#: largest scenario file read (the presets are a few KiB; a bigger file is refused before parsing)
MAX_FILE_BYTES = 1024 * 1024
#: deepest nesting of tables and arrays a scenario may have (the schema needs 4)
MAX_DEPTH = 32


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
    if len(name) > MAX_NAME_LENGTH:
        raise ScenarioError(
            f"name: {len(name)} characters, longer than the {MAX_NAME_LENGTH} a scenario name may have"
        )
    root = (data_dir() / "scenarios").resolve()
    path = (root / f"{name}.toml").resolve()
    if not NAME_RE.fullmatch(name) or not path.is_relative_to(root) or not path.is_file():
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
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ScenarioError(
                f"{path.name}: the file is {size / 2**20:.1f} MiB, larger than the "
                f"{MAX_FILE_BYTES / 2**20:g} MiB a scenario file may have"
            )
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path.name}: not valid TOML ({exc})") from None
    except RecursionError:
        raise ScenarioError(
            f"{path.name}: tables or arrays nested too deep to parse (at most {MAX_DEPTH} levels)"
        ) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path.name}: cannot read ({exc})") from None
    return scenario_from_dict(raw, path)


def scenario_from_dict(raw: dict, path: str | os.PathLike = "<dict>") -> Scenario:
    """Validate and build a scenario from a parsed table (what :func:`load_scenario` does after
    reading the file); ``path`` only labels the messages. No file is read or written.
    """
    if not isinstance(raw, dict):
        raise TypeError(f"raw: expected a dict of TOML tables, got {type(raw).__name__}")
    if not isinstance(path, str | os.PathLike):
        raise TypeError(f"path: expected a file name or path, got {type(path).__name__}")
    path = Path(path)
    where = path.name
    _check_depth(raw, where)
    raw = copy.deepcopy(raw)
    family, sections = validate(raw, where)
    for mod in sections.get("requires", []):
        if mod not in ALLOWED_REQUIRES:
            raise ScenarioError(
                f"{where}: 'requires' entries must be one of {list(ALLOWED_REQUIRES)}, got {mod!r}"
            )
    for mod in sections.get("requires", []):
        require(mod, where)
    if family == "user":
        from .userfile import derive_user  # the user family's friendlier keys, for its files only

        derive_user(sections, raw, where)
    sc = Scenario(
        name=sections["name"],
        paper=sections.get("paper", ""),
        description=sections.get("description", ""),
        path=path,
        sections=sections,
        family=family,
        raw=raw,
    )
    check_placement(sc)
    return sc


def _check_depth(raw: dict, where: str) -> None:
    """Refuse tables/arrays nested deeper than :data:`MAX_DEPTH` (walked without recursion, so a
    5,000-deep dict is an error naming the depth, not a ``RecursionError``)."""
    stack = [(raw, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise ScenarioError(
                f"{where}: raw: tables or arrays nested deeper than {MAX_DEPTH} levels"
            )
        items = node.values() if isinstance(node, dict) else node
        stack.extend((v, depth + 1) for v in items if isinstance(v, dict | list | tuple))
