"""The scenario schema's machinery: :class:`Key`, :class:`Table`, validation and the
families' tables by name (:data:`FAMILIES`); what is checked: docs/internals/scenarios.md."""

from __future__ import annotations

import difflib
import importlib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .._validate import choice, instance, record, text

__all__ = [
    "FAMILIES",
    "Key",
    "ScenarioError",
    "Table",
    "family_of",
    "validate",
]


class ScenarioError(ValueError):
    """A scenario that does not exist or whose file is malformed (the message names the key)."""


_REQUIRED = object()


#: the kinds of value a :class:`Key` describes
KEY_TYPES = ("float", "int", "str", "floats", "ints", "strs", "table", "tables", "bool")


@dataclass(frozen=True)
class Key:
    """One key of a scenario table.

    ``type`` is ``"float"``, ``"int"``, ``"str"``, ``"floats"`` / ``"ints"`` (nested lists of the
    given ``shape``, ``None`` for any length), ``"strs"`` (a list of strings), ``"table"`` (a
    sub-table described by ``table``) or ``"tables"`` (an array of such tables). Numeric ranges
    apply element-wise: ``gt``/``ge``/``lt``/``le``. ``default`` fills an absent optional key;
    ``optional=True`` without a default leaves it absent.
    """

    name: str
    type: str
    doc: str
    unit: str = ""
    default: Any = _REQUIRED
    optional: bool = False
    shape: tuple | None = None
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    choices: tuple | None = None
    table: Table | None = None

    def __post_init__(self) -> None:
        record(self, may_be_empty=("unit",), skip=("default",))
        choice("type", self.type, KEY_TYPES)

    @property
    def required(self) -> bool:
        return self.default is _REQUIRED and not self.optional

    @property
    def has_default(self) -> bool:
        return self.default is not _REQUIRED


@dataclass(frozen=True)
class Table:
    """A table's keys; with ``variants`` the key ``kind`` selects extra keys per kind."""

    keys: tuple[Key, ...]
    doc: str = ""
    variants: dict[str, tuple[Key, ...]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        record(self, may_be_empty=("doc",))
        for k in self.keys:
            instance("keys", k, Key)

    def allowed(self, kind: str | None) -> tuple[Key, ...]:
        if kind is not None:
            text("kind", kind)
        return self.keys + tuple(self.variants.get(kind, ()))


def number_text(x) -> str:
    """A bound as written in a message: ``1.0`` -> ``"1"``, ``3`` -> ``"3"``."""
    return f"{x:g}" if isinstance(x, float) else str(x)


# --- validation -------------------------------------------------------------------------------


def _fail(where: str, msg: str):
    raise ScenarioError(f"{where}: {msg}")


def _check_number(where: str, full: str, key: Key, v, integral: bool):
    what = "an integer" if integral else "a number"
    if isinstance(v, bool) or not isinstance(v, int | float):
        _fail(where, f"'{full}' must be {what}, got {v!r}")
    if integral and not isinstance(v, int):
        _fail(where, f"'{full}' must be an integer, got {v!r}")
    if not math.isfinite(v):
        _fail(where, f"'{full}' must be finite, got {v!r}")
    for bound, ok, sym in (
        (key.gt, lambda b: v > b, ">"),
        (key.ge, lambda b: v >= b, ">="),
        (key.lt, lambda b: v < b, "<"),
        (key.le, lambda b: v <= b, "<="),
    ):
        if bound is not None and not ok(bound):
            unit = f" {key.unit}" if key.unit else ""
            _fail(where, f"'{full}' must be {sym} {number_text(bound)}{unit}, got {v!r}")


def _check_nested(where: str, full: str, key: Key, v, shape, integral: bool, idx: str = ""):
    if not shape:
        _check_number(where, full + idx, key, v, integral)
        return
    if not isinstance(v, list):
        _fail(where, f"'{full}{idx}' must be a list of shape {shape_text(key.shape)}, got {v!r}")
    n = shape[0]
    if n is not None and len(v) != n:
        _fail(
            where,
            f"'{full}' must have shape {shape_text(key.shape)}, got {len(v)} items at '{full}{idx}'",
        )
    for i, item in enumerate(v):
        _check_nested(where, full, key, item, shape[1:], integral, f"{idx}[{i}]")


def shape_text(shape) -> str:
    return (
        "("
        + ", ".join("n" if s is None else str(s) for s in shape)
        + ("," if len(shape) == 1 else "")
        + ")"
    )


def _check_value(where: str, full: str, key: Key, v) -> Any:
    t = key.type
    if t in ("float", "int"):
        _check_number(where, full, key, v, t == "int")
        return v
    if t in ("floats", "ints"):
        _check_nested(where, full, key, v, key.shape or (None,), t == "ints")
        return v
    if t == "str":
        if not isinstance(v, str):
            _fail(where, f"'{full}' must be a string, got {v!r}")
        if key.choices is not None and v not in key.choices:
            near = difflib.get_close_matches(v, key.choices, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            _fail(where, f"'{full}' must be one of {list(key.choices)}, got {v!r}{hint}")
        return v
    if t == "strs":
        if not isinstance(v, list) or not all(isinstance(s, str) for s in v):
            _fail(where, f"'{full}' must be a list of strings, got {v!r}")
        return v
    if t == "table":
        if not isinstance(v, dict):
            _fail(where, f"'{full}' must be a table [{full}], got {v!r}")
        return validate_table(v, key.table, where, full)
    if t == "tables":
        if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
            _fail(where, f"'{full}' must be an array of tables [[{full}]], got {v!r}")
        return [validate_table(x, key.table, where, f"{full}[{i}]") for i, x in enumerate(v)]
    raise AssertionError(f"schema: unknown key type {t!r}")  # pragma: no cover


def validate_table(raw: dict, spec: Table, where: str, prefix: str = "") -> dict:
    """``raw`` checked against ``spec``; returns a copy with defaults filled in."""

    def full(name):
        return f"{prefix}.{name}" if prefix else name

    kind = None
    if spec.variants:
        kkey = next(k for k in spec.keys if k.name == "kind")
        if "kind" not in raw:
            _fail(where, f"missing key '{full('kind')}' (one of {list(spec.variants)})")
        kind = _check_value(where, full("kind"), kkey, raw["kind"])
    allowed = spec.allowed(kind)
    names = [k.name for k in allowed]
    for name in raw:
        if name in names:
            continue
        other = [v for v, ks in spec.variants.items() if any(k.name == name for k in ks)]
        if other:
            _fail(
                where,
                f"'{full(name)}' is not a key of kind {kind!r} (it belongs to {', '.join(map(repr, other))})",
            )
        near = difflib.get_close_matches(name, names, n=1, cutoff=0.5)
        hint = f"; did you mean '{full(near[0])}'?" if near else f"; valid keys: {', '.join(names)}"
        _fail(where, f"unknown key '{full(name)}'{hint}")
    out: dict[str, Any] = {}
    for key in allowed:
        if key.name in raw:
            out[key.name] = _check_value(where, full(key.name), key, raw[key.name])
        elif key.required:
            what = (
                f"section [{full(key.name)}]" if key.type == "table" else f"key '{full(key.name)}'"
            )
            _fail(where, f"missing {what}")
        elif key.has_default:
            d = key.default
            out[key.name] = (
                validate_table({}, key.table, where, full(key.name))
                if key.type == "table" and d == {}
                else _copy(d)
            )
    return out


def _copy(v):
    if isinstance(v, list):
        return [_copy(x) for x in v]
    if isinstance(v, dict):
        return {k: _copy(x) for k, x in v.items()}
    return v


def family_of(raw: dict, where: str) -> str:
    """The family of a parsed file: its ``paper`` key, or ``"user"`` without one."""
    if not isinstance(raw, dict):
        raise TypeError(f"raw: expected a dict of TOML tables, got {type(raw).__name__}")
    text("where", where)
    paper = raw.get("paper")
    if paper is None:
        return "user"
    if not isinstance(paper, str):
        _fail(where, f"'paper' must be a string, got {paper!r}")
    if paper not in FAMILIES or paper == "user":
        papers = [f for f in FAMILIES if f != "user"]
        near = difflib.get_close_matches(paper, papers, n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        _fail(
            where,
            f"'paper' must be one of {papers} (omit it for your own tunnel), got {paper!r}{hint}",
        )
    return paper


def validate(raw: dict, where: str) -> tuple[str, dict]:
    """``(family, normalised copy)`` of a parsed scenario file (``ScenarioError`` if malformed)."""
    text("where", where)
    fam = family_of(raw, where)
    return fam, validate_table(raw, FAMILIES[fam], where)


# --- building the specs ----------------------------------------------------------------------------------


def key_float(name, doc, unit="", **kw) -> Key:
    return Key(name, "float", doc, unit, **kw)


def key_int(name, doc, **kw) -> Key:
    return Key(name, "int", doc, **kw)


def key_str(name, doc, **kw) -> Key:
    return Key(name, "str", doc, **kw)


def key_floats(name, doc, unit="", shape=(None,), **kw) -> Key:
    return Key(name, "floats", doc, unit, shape=shape, **kw)


def key_table(name, table, doc="", **kw) -> Key:
    return Key(name, "table", doc or table.doc, table=table, **kw)


def key_tables(name, table, doc="", **kw) -> Key:
    return Key(name, "tables", doc or table.doc, table=table, **kw)


def header(paper: str | None) -> tuple[Key, ...]:
    keys = [key_str("name", "scenario name (normally the file name without .toml)")]
    if paper is not None:
        keys.append(key_str("paper", "the paper this preset rebuilds", choices=(paper,)))
    keys.append(key_str("description", "one line shown by `tunnelkit scenarios`", default=""))
    if paper is not None:
        keys.append(
            Key(
                "requires",
                "strs",
                "tunnelkit modules that register this file's kinds (allow-list: "
                "tunnelkit.propagation, tunnelkit.tunnels)",
                optional=True,
            )
        )
    return tuple(keys)


#: each family's spec: its module in this package and the name of its table there
_FAMILY_SPECS = {
    "jiang2023": ("jiang", "JIANG"),
    "italiano2026": ("tunnel3d", "ITALIANO"),
    "halili2022": ("halili", "HALILI"),
    "user": ("user", "USER"),
}


class _Families(Mapping):
    """The families' tables by name, each spec module imported when its table is first asked for
    (a file of one family loads that family's spec only)."""

    def __getitem__(self, family: str) -> Table:
        module, name = _FAMILY_SPECS[family]
        return getattr(importlib.import_module(f"tunnelkit.schema.{module}"), name)

    def __iter__(self):
        return iter(_FAMILY_SPECS)

    def __len__(self) -> int:
        return len(_FAMILY_SPECS)


#: family name -> its :class:`Table` (``jiang2023``, ``italiano2026``, ``halili2022``, ``user``)
FAMILIES: Mapping[str, Table] = _Families()
