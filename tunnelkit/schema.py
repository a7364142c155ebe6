"""The scenario schema: one declarative spec per family, every file validated against it on load.

A scenario file belongs to one *family*, chosen by its ``paper`` key:

* ``paper = "jiang2023"``: Jiang's 2-D tunnel (two wall lines, a 2-D base station, noise levels);
* ``paper = "italiano2026"``: the JAVELIN tunnel (semicircular facets, RRMs, URAs, 5G SRS radio);
* ``paper = "halili2022"``: Halili's drive (plain sections read into ``drive.DriveConfig``);
* no ``paper`` key: **your own tunnel** (family ``user``): a rectangular, semicircular or
  horseshoe tunnel, a base station with ULAs/URAs, a radio and a lane or slalom trajectory.

Each family is a :class:`Table` of :class:`Key` s (type, unit, range, default, doc string). The same
spec validates a file (:func:`validate`), writes a commented template and documents the schema
(:mod:`tunnelkit.schemadoc`: ``render_template``, ``to_markdown``, printed by ``tunnelkit scenarios
doc``), so the three never drift apart. Validation is strict:
``shape = [10.5, 10]``, a bool or a string where a number is expected, NaN, a value out of range,
a missing required key and an unknown key (reported with the nearest valid name) are all a
:class:`ScenarioError` naming the file, the section and the key.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from typing import Any

from ._validate import choice, instance, record, text

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

    def range_text(self) -> str:
        """``"> 0"``, ``"[-90, 90]"``, ... (empty if unbounded)."""
        lo = f"> {_num(self.gt)}" if self.gt is not None else None
        lo = f">= {_num(self.ge)}" if self.ge is not None else lo
        hi = f"< {_num(self.lt)}" if self.lt is not None else None
        hi = f"<= {_num(self.le)}" if self.le is not None else hi
        if lo and hi:
            left = "(" if self.gt is not None else "["
            right = ")" if self.lt is not None else "]"
            return f"{left}{_num(self.gt if self.gt is not None else self.ge)}, {_num(self.lt if self.lt is not None else self.le)}{right}"
        return lo or hi or ""


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


def _num(x) -> str:
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
            _fail(where, f"'{full}' must be {sym} {_num(bound)}{unit}, got {v!r}")


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


# --- the specs ----------------------------------------------------------------------------------


def _f(name, doc, unit="", **kw) -> Key:
    return Key(name, "float", doc, unit, **kw)


def _i(name, doc, **kw) -> Key:
    return Key(name, "int", doc, **kw)


def _s(name, doc, **kw) -> Key:
    return Key(name, "str", doc, **kw)


def _v(name, doc, unit="", shape=(None,), **kw) -> Key:
    return Key(name, "floats", doc, unit, shape=shape, **kw)


def _t(name, table, doc="", **kw) -> Key:
    return Key(name, "table", doc or table.doc, table=table, **kw)


def _ts(name, table, doc="", **kw) -> Key:
    return Key(name, "tables", doc or table.doc, table=table, **kw)


def _header(paper: str | None) -> tuple[Key, ...]:
    keys = [_s("name", "scenario name (normally the file name without .toml)")]
    if paper is not None:
        keys.append(_s("paper", "the paper this preset rebuilds", choices=(paper,)))
    keys.append(_s("description", "one line shown by `tunnelkit scenarios`", default=""))
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


_ANGLE_ROWS = "rows of (sigma_theta [deg], sigma_d [m]), each >= 0 (angle <= 180 deg)"

JIANG = Table(
    (
        *_header("jiang2023"),
        _t(
            "tunnel",
            Table(
                (
                    _s("kind", "tunnel model", choices=("walls2d",)),
                    _v(
                        "walls",
                        "[A, B, C] of the two parallel wall lines A x + B y + C = 0",
                        shape=(2, 3),
                    ),
                ),
                "Jiang's straight 2-D tunnel between two parallel wall lines (top view)",
            ),
        ),
        _t(
            "base_station",
            Table(
                (
                    _v(
                        "position",
                        "base station (x, y), strictly between the walls",
                        "m",
                        shape=(2,),
                    ),
                ),
                "the single base station",
            ),
        ),
        _t(
            "noise",
            Table(
                (_v("levels", _ANGLE_ROWS, shape=(None, 2), ge=0.0),),
                "measurement noise levels of Tables 2-3",
            ),
            optional=True,
        ),
        _t(
            "trajectory",
            Table(
                (
                    _s("kind", "trajectory model", choices=("piecewise_acceleration",)),
                    _v("start", "start position (x, y), inside the tunnel", "m", shape=(2,)),
                    _v("velocity", "initial velocity (vx, vy)", "m/s", shape=(2,)),
                    _f("period", "sampling period T1 (eq. 41)", "s", gt=0.0),
                    _i("steps", "number of samples", ge=2, le=1_000_000),
                    _v(
                        "segments",
                        "[duration s, a_along m/s^2, a_across m/s^2] per constant-acceleration segment",
                        shape=(None, 3),
                        optional=True,
                    ),
                ),
                "ground truth: constant acceleration per segment in the tunnel frame",
            ),
        ),
        _t(
            "tracking",
            Table(
                (
                    _f(
                        "q", "white-noise-acceleration spectral density per axis", "m^2/s^3", ge=0.0
                    ),
                    _v(
                        "p0_sigma",
                        "prior standard deviations (position, velocity)",
                        "m, m/s",
                        shape=(2,),
                        gt=0.0,
                    ),
                ),
                "filter settings of notebook 05",
            ),
            optional=True,
        ),
    ),
    "Jiang, Wang & Peng (2023): the 2-D rectangular tunnel",
)

_PLATE = Table(
    (
        _s("name", "label of the road marking", optional=True),
        _v("x_range", "extent along the tunnel (increasing)", "m", shape=(2,)),
        _f("y", "across position of the plate centre (non-zero: one side of the tunnel)", "m"),
        _f("z", "height of the plate centre", "m", ge=0.0),
        _f("width", "extent in the cross-section", "m", gt=0.0),
        _f(
            "inclination_deg", "angle to the road (90 = vertical on a wall)", "deg", gt=0.0, le=90.0
        ),
    ),
    "metallic radio-reflective road markings (RRMs)",
)

_BLOCKER = Table(
    (
        _s("name", "label", optional=True),
        _v("lo", "lower corner (x, y, z)", "m", shape=(3,)),
        _v("hi", "upper corner (x, y, z), > lo on every axis", "m", shape=(3,)),
    ),
    "axis-aligned boxes that block rays (trucks)",
)

_MAX_SIDE = 256
_SHAPE_DOC = "[rows, columns] of the URA (a ULA of n elements is [1, n]); at most 4096 elements"

_ITALIANO_ARRAY = Table(
    (
        _s("name", "label (e.g. '+x')", optional=True),
        Key("shape", "ints", _SHAPE_DOC, shape=(2,), ge=1, le=_MAX_SIDE),
        _f("azimuth_deg", "boresight azimuth from +x towards +y", "deg", ge=-360.0, le=360.0),
        _f(
            "elevation_deg",
            "boresight elevation above the horizontal (-30 = tilted down)",
            "deg",
            ge=-90.0,
            le=90.0,
        ),
        _v(
            "offset",
            "reference antenna relative to base_station.position",
            "m",
            shape=(3,),
            default=[0.0, 0.0, 0.0],
        ),
    ),
    "one planar array (lambda/2 spacing); the reference antenna sits at position + offset",
)


def _radio(user: bool) -> Table:
    return Table(
        (
            _f("fc", "carrier frequency", "Hz", gt=0.0, le=3e11),
            _f("bandwidth", "channel bandwidth", "Hz", gt=0.0),
            _f("scs", "subcarrier spacing", "Hz", gt=0.0),
            _i("comb", "SRS comb: one tone in `comb` is used", ge=1, le=64),
            _i("n_symbols", "SRS symbols per slot (Doppler needs >= 2)", ge=2, le=1024),
            _f("tx_power_dbm", "UE transmit power", "dBm", ge=-50.0, le=60.0),
            _f("noise_figure_db", "receiver noise figure", "dB", ge=0.0, le=30.0),
            _f(
                "t_ant",
                "antenna temperature",
                "K",
                gt=0.0,
                le=1e4,
                **({"default": 298.0} if user else {}),
            ),
            _i(
                "n_rb",
                "resource blocks of 12 subcarriers ("
                + (
                    "default: as many as fit in 98.3 % of the bandwidth, 273 at 100 MHz / 30 kHz"
                    if user
                    else "default 273"
                )
                + ")",
                ge=1,
                le=10_000,
                optional=True,
            ),
            _f(
                "clock_bias_sigma_ns",
                "UE clock-bias standard deviation",
                "ns",
                ge=0.0,
                default=50.0,
            ),
            _f("clock_bias_limit_ns", "UE clock-bias truncation", "ns", ge=0.0, default=100.0),
        ),
        "uplink SRS (5G NR) radio",
    )


#: the ray-traced channel's settings (``tunnelkit.rt.settings.RTSettings``; the same defaults,
#: material names and ranges, checked by tests/test_rt_channel.py)
_RT_MATERIALS = (
    "concrete",
    "asphalt",
    "metal",
    "brick",
    "marble",
    "glass",
    "medium_dry_ground",
    "wet_ground",
)
_RAYTRACING = Table(
    (
        _f(
            "scattering_coefficient",
            "diffuse scattering coefficient S of the shell and the road (0: specular only)",
            ge=0.0,
            le=1.0,
            default=0.3,
        ),
        _f(
            "metal_scattering_coefficient",
            "scattering coefficient of the metal plates and blockers",
            ge=0.0,
            le=1.0,
            default=0.0,
        ),
        _s(
            "scattering_pattern",
            "lobe of the scattered power",
            choices=("lambertian", "directive"),
            default="lambertian",
        ),
        _i(
            "alpha_r",
            "width parameter of the directive lobe (larger: narrower)",
            ge=1,
            le=100,
            default=4,
        ),
        _i("max_depth", "bounces traced (2: second-order specular on)", ge=1, le=5, default=2),
        _i("samples_per_src", "rays shot from the vehicle", ge=100, le=10_000_000, default=20_000),
        _s(
            "wall_material",
            "material of the shell (walls and ceiling)",
            choices=_RT_MATERIALS,
            default="concrete",
        ),
        _s(
            "road_material",
            "material of the road ('asphalt': ITU very_dry_ground, there is no ITU asphalt)",
            choices=_RT_MATERIALS,
            default="asphalt",
        ),
        _s("rrm_material", "material of the road markings", choices=_RT_MATERIALS, default="metal"),
        _s("antenna_pattern", "element pattern", choices=("iso", "tr38901"), default="iso"),
        _s(
            "array_tracing",
            "how the array is traced: one receiver per element, or one ray set at the centroid",
            choices=("element", "centre", "synthetic"),
            default="element",
        ),
    ),
    "the ray-traced channel (Sionna RT, `--channel sionna`): materials, diffuse scattering, depth",
)


_LANE_KEYS = (
    _f("x_start", "where the vehicle starts along the tunnel", "m"),
    _f("x_end", "where it stops (!= x_start)", "m"),
    _f("speed", "speed along the tunnel", "m/s", gt=0.0, le=100.0),
    _f("period", "time between epochs (one SRS slot each)", "s", gt=0.0),
    _f("y", "lane centre across the tunnel", "m"),
    _f("height", "UE antenna height above the road", "m", gt=0.0),
)

ITALIANO = Table(
    (
        *_header("italiano2026"),
        _t(
            "tunnel",
            Table(
                (
                    _s("kind", "tunnel model", choices=("semicircular3d",)),
                    _f("length", "length, centred on x = 0", "m", gt=0.0),
                    _f("width", "width at the road", "m", gt=0.0),
                    _f("height", "height at the centre", "m", gt=0.0),
                    _i(
                        "n_facets",
                        "planar facets approximating the half-ellipse",
                        ge=2,
                        le=360,
                        default=12,
                    ),
                    _ts("plates", _PLATE, optional=True),
                    _ts("blockers", _BLOCKER, optional=True),
                ),
                "the JAVELIN tunnel: a half-ellipse of planar facets plus the road",
            ),
        ),
        _t(
            "base_station",
            Table(
                (
                    _v("position", "base station (x, y, z), inside the tunnel", "m", shape=(3,)),
                    _ts("arrays", _ITALIANO_ARRAY),
                ),
                "the base station and its arrays",
            ),
        ),
        _t("radio", _radio(False)),
        _t("raytracing", _RAYTRACING, optional=True),
        _t(
            "trajectory",
            Table(
                (
                    _s("kind", "trajectory model", choices=("lane3d",)),
                    *_LANE_KEYS,
                    _f(
                        "slalom_amplitude",
                        "lateral swing around the lane centre",
                        "m",
                        ge=0.0,
                        default=0.0,
                    ),
                    _f("slalom_wavelength", "slalom period along x", "m", gt=0.0, default=20.0),
                ),
                "ground truth: constant speed along x, optional slalom",
            ),
        ),
    ),
    "Italiano et al. (2026): the JAVELIN tunnel",
)


def _h(name, doc, unit="", **kw) -> Key:
    return _f(name, doc, unit, **kw)


HALILI = Table(
    (
        *_header("halili2022"),
        _t(
            "tube",
            Table(
                (
                    _h("width", "tube width", "m", gt=0.0, default=10.0),
                    _h("height", "tube height", "m", gt=0.0, default=5.0),
                ),
                "rectangular tube",
            ),
            default={},
        ),
        _t(
            "transmitter",
            Table(
                (
                    _h("tx_y", "transmitter across (|tx_y| < width/2)", "m", default=4.5),
                    _h("tx_z", "transmitter height (0 < tx_z < height)", "m", default=4.5),
                    _h(
                        "pass_time",
                        "time the van passes the transmitter",
                        "s",
                        ge=0.0,
                        default=37.0,
                    ),
                ),
                "the roadside unit",
            ),
            default={},
        ),
        _t(
            "vehicle",
            Table(
                (
                    _h("lane_y", "lane centre (|lane_y| < width/2)", "m", default=-2.5),
                    _h("rx_height", "antenna height (< tube height)", "m", gt=0.0, default=2.0),
                    _h("speed", "mean speed", "m/s", gt=0.0, le=100.0, default=25.0),
                    _h("speed_amplitude", "speed variation amplitude", "m/s", ge=0.0, default=1.0),
                    _h("speed_period", "speed variation period", "s", gt=0.0, default=27.0),
                    _h("duration", "recording time", "s", gt=0.0, le=1e5, default=54.0),
                    _h(
                        "spacing",
                        "distance between stored parameter sets",
                        "m",
                        gt=0.0,
                        default=0.8,
                    ),
                ),
                "the van",
            ),
            default={},
        ),
        _t(
            "radio",
            Table(
                (
                    _h("fc", "carrier frequency", "Hz", gt=0.0, le=3e11, default=1.35e9),
                    _h("bandwidth", "sounder bandwidth", "Hz", gt=0.0, default=80e6),
                    _h("snapshot_period", "snapshot period t_s", "s", gt=0.0, default=975.3e-6),
                    _i(
                        "window_snapshots",
                        "local stationarity window M",
                        ge=2,
                        le=100_000,
                        default=32,
                    ),
                ),
                "channel sounder",
            ),
            default={},
        ),
        _t(
            "multipath",
            Table(
                (
                    _h("reflection_coeff", "amplitude per bounce", ge=0.0, le=1.0, default=0.6),
                    _i("max_order", "highest reflection order", ge=0, le=6, default=2),
                ),
                "image-method multipath",
            ),
            default={},
        ),
        _t(
            "errors",
            Table(
                (
                    _h(
                        "doppler_noise_hz",
                        "white Doppler noise at short range",
                        "Hz",
                        ge=0.0,
                        default=8.0,
                    ),
                    _h("toa_noise_s", "white ToA noise at short range", "s", ge=0.0, default=1e-9),
                    _h(
                        "noise_ref_range",
                        "noise grows as sqrt(1 + (r/ref)^2)",
                        "m",
                        gt=0.0,
                        default=300.0,
                    ),
                    _h("doppler_bias_hz", "Gauss-Markov Doppler bias", "Hz", ge=0.0, default=10.0),
                    _h("toa_bias_m", "NLOS excess delay scale", "m", ge=0.0, default=1.0),
                    _h("bias_corr_m", "bias correlation length", "m", gt=0.0, default=20.0),
                    _h(
                        "outlier_prob",
                        "probability of a Doppler outlier",
                        ge=0.0,
                        le=1.0,
                        default=0.02,
                    ),
                    _h(
                        "drop_prob",
                        "probability of a missed measurement",
                        ge=0.0,
                        lt=1.0,
                        default=0.0,
                    ),
                ),
                "measurement errors",
            ),
            default={},
        ),
        _t(
            "clock",
            Table(
                (
                    _h("clock_offset_s", "ToA clock offset", "s", ge=0.0, default=30e-9),
                    _h("clock_drift", "clock drift", "s/s", default=0.2e-9),
                    _h("cfo_hz", "residual carrier-frequency offset", "Hz", default=0.0),
                    _h("cfo_walk_hz", "CFO random walk", "Hz/sqrt(s)", ge=0.0, default=0.2),
                ),
                "clocks",
            ),
            default={},
        ),
        _t(
            "gnss",
            Table(
                (
                    _h("gnss_sigma_m", "position error of the last fix", "m", ge=0.0, default=2.0),
                    _h(
                        "gnss_sigma_v", "velocity error of the last fix", "m/s", ge=0.0, default=0.2
                    ),
                ),
                "the GNSS fix at the entrance",
            ),
            default={},
        ),
    ),
    "Halili et al. (2022): one roadside unit, Doppler and ToA",
)

USER_SHAPES = ("rectangular", "horseshoe", "semicircular")

_USER_ARRAY = Table(
    (
        _s("name", "label (e.g. '+x')", optional=True),
        Key("shape", "ints", _SHAPE_DOC, shape=(2,), ge=1, le=_MAX_SIDE),
        _f(
            "azimuth_deg",
            "boresight azimuth from +x (along the tunnel) towards +y",
            "deg",
            ge=-360.0,
            le=360.0,
            default=0.0,
        ),
        _f(
            "tilt_deg",
            "down-tilt of the boresight below the horizontal (90 = straight down)",
            "deg",
            ge=-90.0,
            le=90.0,
            default=0.0,
        ),
        _f(
            "spacing_wavelengths",
            "element spacing in wavelengths at radio.fc (ignored if spacing_m is given)",
            gt=0.0,
            le=100.0,
            default=0.5,
        ),
        _f(
            "spacing_m",
            "element spacing in metres (overrides spacing_wavelengths)",
            "m",
            gt=0.0,
            le=10.0,
            optional=True,
        ),
        _v(
            "offset",
            "reference antenna relative to base_station.position",
            "m",
            shape=(3,),
            default=[0.0, 0.0, 0.0],
        ),
    ),
    "one planar array on the mount; element 0 (a corner) is the reference antenna",
)

USER = Table(
    (
        *_header(None),
        _t(
            "tunnel",
            Table(
                (
                    _s("kind", "cross-section shape", choices=USER_SHAPES),
                    _f("length", "length along x", "m", gt=0.0, le=100_000.0),
                    _f("width", "width at the road", "m", gt=0.0, le=1000.0),
                    _f("height", "height at the centre", "m", gt=0.0, le=1000.0),
                    _f(
                        "x_start",
                        "where the tunnel starts along x (default -length/2: centred on 0)",
                        "m",
                        optional=True,
                    ),
                    _s(
                        "wall_material",
                        "walls and roof",
                        choices=("concrete", "metal"),
                        default="concrete",
                    ),
                    _s(
                        "road_material",
                        "road surface",
                        choices=("concrete", "metal"),
                        default="concrete",
                    ),
                    _ts("plates", _PLATE, optional=True),
                    _ts("blockers", _BLOCKER, optional=True),
                ),
                "your tunnel: a straight tube along x, road at z = 0, centred on y = 0",
                variants={
                    "rectangular": (),
                    "semicircular": (
                        _i(
                            "n_facets",
                            "planar facets approximating the half-ellipse",
                            ge=2,
                            le=360,
                            default=12,
                        ),
                    ),
                    "horseshoe": (
                        _i(
                            "n_facets", "planar facets of the arched roof", ge=2, le=360, default=12
                        ),
                        _f(
                            "wall_height",
                            "height of the vertical walls where the arch starts (default: height - width/2, a semicircular roof)",
                            "m",
                            gt=0.0,
                            optional=True,
                        ),
                    ),
                },
            ),
        ),
        _t(
            "base_station",
            Table(
                (
                    _v("position", "mount position (x, y, z), inside the tunnel", "m", shape=(3,)),
                    _ts("arrays", _USER_ARRAY),
                ),
                "the base-station mount and its arrays (one [[base_station.arrays]] per array)",
            ),
        ),
        _t("radio", _radio(True)),
        _t("raytracing", _RAYTRACING, optional=True),
        _t(
            "trajectory",
            Table(
                (_s("kind", "lane (straight) or slalom", choices=("lane", "slalom")), *_LANE_KEYS),
                "ground truth: constant speed along x",
                variants={
                    "lane": (),
                    "slalom": (
                        _f("amplitude", "lateral swing around the lane centre", "m", ge=0.0),
                        _f("wavelength", "slalom period along x", "m", gt=0.0),
                    ),
                },
            ),
        ),
    ),
    "your own tunnel (no `paper` key)",
)

FAMILIES: dict[str, Table] = {
    "jiang2023": JIANG,
    "italiano2026": ITALIANO,
    "halili2022": HALILI,
    "user": USER,
}
