"""The design's channel route on the ray-traced channel: the traced treatment of the tables.

On the ray-traced channel (``tunnelkit design --mode channel --channel sionna``) the ML route's
first-order estimates lie thousands of CRLB standard deviations off (diffuse scattering,
higher-order bounces, the spatial-wideband term), and every fit fails its own residual test. The
image channel's design tracker takes each path's reported CRLB as its covariance and drops a
flagged epoch: on this channel it is told micrometres about measurements metres off, or predicts
only. The traced route changes the same two things the traced JAVELIN tables change
(:mod:`tunnelkit.studies.traced`), for each candidate array:

* **measurements**: every epoch's ML measurements (fits judged against noise + the epoch's
  diffuse power, ``diffuse_floor``), reduced to the paths that agree with one UE through the
  tunnel's planes (:func:`tunnelkit.simulation.prefilter.geometry_keep` with
  :data:`~tunnelkit.simulation.prefilter.FLOORS`), whatever the fit's own verdict
  (:func:`traced_drive`);
* **measurement noise**: the RMS extraction error of THIS array on this channel (the stored
  traced record is the paper array's; a 4x4 and a 16x16 have other errors), measured on the
  first :data:`ERROR_RUNS` drives of seed :data:`ERROR_SEED` (the choice; report the sweep on
  another seed) by :func:`measure_design_errors` and cached as JSON with its provenance
  (:func:`design_errors`: scenario, array, epochs, the ray tracer's settings and the trace
  cache's key; the paper tunnel's in ``data/rt/design/``; a record of another scene, settings, array or sionna-rt version is refused, never
  reused). The tracker (:func:`traced_javelin`) is the design's
  (:func:`~tunnelkit.design.montecarlo.javelin_config`: VUEs from the known surfaces, likelihood
  association, joint innovation test) with fixed per-quantity sigmas set to those errors at
  their long-run value (each RMS times ``sqrt((1 + r) / (1 - r))``, ``r`` the record's lag-1
  error correlation).

The report's JSON names the error model each array's traced route used
(:func:`error_model_summary`). Its bounds over the drive are those of the sigmas the tracker is
told (:func:`tunnelkit.design.tracedbounds.traced_bounds`: every first-order path measured at every epoch with independent
Gaussian errors of those sigmas), not the image channel's micrometre CRLBs: what such
measurements allow a tracker, beside what it achieves.

A drive costs about a second of CPU per epoch (its tracker milliseconds): :func:`design_drive`
keeps it for the process, and reads the drives the repository ships (``data/rt/design/*-drive.json``,
written by ``tools/traced_drive.py``: notebook 08's quick-mode 4 x 4 drive) from their record
(:func:`stored_drive`) when its key is the drive asked for (scene, ray tracer, array, epochs, the
generator's state: :func:`drive_key`), every field checked; any other drive is driven.
"""

from __future__ import annotations

import copy
import json
from collections import OrderedDict
from dataclasses import asdict
from functools import partial
from pathlib import Path

import numpy as np

from .._validate import boolean, choice, instance, integer, rng_or_error
from ..budget import check_bytes
from ..montecarlo import RUN_BYTES
from .setup import DesignSetup, parse_array
from .tracedbounds import config_sigmas

__all__ = [
    "DRIVE_KINDS",
    "ERROR_RUNS",
    "ERROR_SEED",
    "TRACED_NUISANCE",
    "design_drive",
    "design_errors",
    "design_errors_path",
    "drive_key",
    "drive_record",
    "error_model_summary",
    "keep_drives",
    "kept_drives",
    "measure_design_errors",
    "stored_drive",
    "stored_drive_path",
    "traced_drive",
    "traced_javelin",
    "traced_route",
]

#: the seed whose first :data:`ERROR_RUNS` drives measure each array's traced errors (the
#: choice; a sweep reported on it reuses those drives, :func:`design_errors` says so)
ERROR_SEED = 0
#: drives per array the traced errors are measured on (every epoch, every matched path pooled)
ERROR_RUNS = 3
#: what :func:`design_drive` keeps of a traced drive: the ML measurements the geometry test
#: keeps (the ``"paths"`` tracker's) and every epoch's (the line-of-sight tracker picks from them)
DRIVE_KINDS = ("ml-traced", "ml-all")
#: the traced route's nuisance: the ML fit judged against noise + the epoch's diffuse power
TRACED_NUISANCE = {"diffuse_floor": True}
#: the record's procedure (part of what a stored record must match)
PROCEDURE = "tunnelkit.design.traced.measure_design_errors"
#: a stored drive's procedure (part of its key, :func:`drive_key`)
DRIVE_PROCEDURE = "tunnelkit.design.traced.design_drive"
#: design drives :func:`design_drive` keeps for the process (the oldest dropped first)
DRIVES_KEPT = 64
_DRIVES: OrderedDict = OrderedDict()
_STORED_FIELDS = {"key", "drives", "made_by"}  # a stored drive's record


def _setup(setup) -> DesignSetup:
    instance("setup", setup, DesignSetup)
    if setup.channel != "sionna":
        raise ValueError(
            f"setup: the traced route needs the ray-traced channel (channel='sionna'), got "
            f"{setup.channel!r}"
        )
    return setup


def traced_route(setup: DesignSetup, spec):
    """The design's signal route of ``spec`` (:meth:`DesignSetup.signal_route`) on the
    ray-traced channel with :data:`TRACED_NUISANCE` (``setup.channel`` must be ``"sionna"``)."""
    setup = _setup(setup)
    return setup.signal_route(parse_array(spec)).with_options(**TRACED_NUISANCE)


def traced_drive(route, rng: np.random.Generator, *, n_epochs: int | None = None) -> dict:
    """One drive of the design route ``route`` (:func:`traced_route`; LoS and road markings as
    the image channel's design drive: no condition) measured by the ML route, through
    :func:`tunnelkit.simulation.drives.simulate_routes` with the traced adapters: ``{"ml",
    "ml-all", "ml-traced"}`` (``"ml-all"`` every epoch's ML measurements, its fit test ignored;
    ``"ml-traced"`` those :func:`~tunnelkit.simulation.prefilter.geometry_keep` keeps)."""
    from ..signal_route import SignalRoute
    from ..simulation.drives import simulate_routes
    from ..simulation.prefilter import FLOORS, traced_measurements

    instance("route", route, SignalRoute)
    if route.raytraced is None:
        raise ValueError("route: expected a route on the ray-traced channel (traced_route)")
    rng = rng_or_error("rng", rng)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    return simulate_routes(
        route,
        rng,
        condition=None,
        extractions=("ml",),
        n_epochs=n_epochs,
        adapters={
            "ml-all": ("ml", partial(traced_measurements, floors=FLOORS, prefilter=False)),
            "ml-traced": ("ml", partial(traced_measurements, floors=FLOORS)),
        },
    )


def design_drive(
    setup: DesignSetup,
    spec,
    rng: np.random.Generator,
    *,
    n_epochs: int | None = None,
    kind: str = "ml-traced",
):
    """The design sweep's drive of ``spec`` on the ray-traced channel: the ``kind`` drive
    (:data:`DRIVE_KINDS`: ``"ml-traced"``, default, or ``"ml-all"``) of :func:`traced_drive` on
    :func:`traced_route`, kept for the process (both kinds, from one extraction). Its key is ``setup``
    itself (the object: a frozen setup builds the same route every time), the array,
    ``n_epochs`` and the state of ``rng`` at the start; a drive asked for again (the same setup
    and seed in another sweep: another entry fix, dead reckoning) is a copy of the kept one, and
    ``rng`` is moved to the state the drive left it in: bit for bit what driving again gives
    (the ML extraction draws nothing from ``rng``, the entry fix is drawn after the drive),
    without the extraction's cost. At most :data:`DRIVES_KEPT` drives are kept, the oldest
    dropped first; an equal setup built anew, or one sent to another process, drives again. A
    drive not kept is read from its stored record when the repository ships one of this key
    (:func:`stored_drive`: the same numbers, both kinds, checked on load) and driven
    otherwise."""
    setup = _setup(setup)
    spec = parse_array(spec)
    rng = rng_or_error("rng", rng)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    kind = choice("kind", kind, DRIVE_KINDS)
    start = json.dumps(rng.bit_generator.state, sort_keys=True, default=str)
    key = (id(setup), spec, n_epochs, start)  # the spec: its label and spacing
    kept = _DRIVES.get(key)
    # the entry holds the setup: its id is not reused
    if kept is not None and kept[0] is setup and kind in kept[1]:
        _DRIVES.move_to_end(key)
        rng.bit_generator.state = copy.deepcopy(kept[2])
        return copy.deepcopy(kept[1][kind])
    drives = _stored(setup, spec, rng, n_epochs)
    if drives is None:
        both = traced_drive(traced_route(setup, spec), rng, n_epochs=n_epochs)
        drives = {k: both[k] for k in DRIVE_KINDS}
    if kept is not None and kept[0] is setup:  # a kind kept before stays as it was
        drives.update(kept[1])
    _DRIVES[key] = (setup, copy.deepcopy(drives), copy.deepcopy(rng.bit_generator.state))
    while len(_DRIVES) > DRIVES_KEPT:
        _DRIVES.popitem(last=False)
    return drives[kind]


def kept_drives(setup: DesignSetup) -> list:
    """The drives :func:`design_drive` keeps for ``setup`` (oldest first), each ``(key, drives,
    end)``: the array, ``n_epochs``, the generator's start state (JSON), ``{kind: drive}`` and
    its end state. Pickled, :func:`keep_drives` gives them back in another process
    (``benchmarks/bench_design_los.py --drives-cache``)."""
    setup = _setup(setup)
    return [(k[1:], copy.deepcopy(v[1]), copy.deepcopy(v[2])) for k, v in _DRIVES.items()
            if v[0] is setup]  # fmt: skip


def keep_drives(setup: DesignSetup, entries) -> None:
    """Keep ``entries`` (:func:`kept_drives`' list) as :func:`design_drive`'s drives of
    ``setup``, which a sweep of the same arrays and seed then reads instead of driving; a drive
    of another route (its truth not this route's first epochs) is refused."""
    from ..simulation.drives import DriveData

    setup = _setup(setup)
    if not isinstance(entries, list | tuple) or not entries:
        raise ValueError(f"entries: expected kept_drives' non-empty list, got {entries!r:.40}")
    for e in entries:
        ok = isinstance(e, tuple) and len(e) == 3 and isinstance(e[0], tuple) and len(e[0]) == 3
        ok = ok and isinstance(e[1], dict) and bool(e[1]) and set(e[1]) <= set(DRIVE_KINDS)
        if not ok or not all(isinstance(d, DriveData) for d in e[1].values()):
            raise ValueError(f"entries: expected kept_drives' tuples, kinds from {DRIVE_KINDS}")
        for d in e[1].values():
            truth = setup.trajectory.position[: len(d.truth)]
            if not np.array_equal(d.truth, truth):
                raise ValueError(f"entries: a drive of another route than {setup.name!r}'s")
        _DRIVES[(id(setup), *e[0])] = (setup, copy.deepcopy(e[1]), copy.deepcopy(e[2]))
    while len(_DRIVES) > DRIVES_KEPT:
        _DRIVES.popitem(last=False)


def stored_drive_path(setup: DesignSetup, spec, n_epochs: int | None = None) -> Path:
    """Where the repository stores :func:`design_drive`'s drive of ``spec`` (``n_epochs``: its
    first epochs, all by default): ``data/rt/design/<scenario>-<array>[-T<n_epochs>]-drive.json``
    (written by ``tools/traced_drive.py``); which drive it holds is its key (:func:`drive_key`)."""
    from ..scenarios import data_dir

    return data_dir() / "rt" / "design" / f"{_record_stem(setup, spec, n_epochs)}-drive.json"


def drive_key(setup: DesignSetup, spec, rng: np.random.Generator, n_epochs=None) -> dict:
    """What a stored drive must match to be read for :func:`design_drive` (``setup``, ``spec``,
    ``rng`` at the start, ``n_epochs``): the record format, the procedure, scenario, array,
    epochs (None: the whole route), nuisance, the ray tracer's settings and the trace cache's
    key (scene, arrays, trajectory, radio, sionna-rt version), the odometry model the drive's
    messages are drawn from and the generator's state."""
    from ._drivestore import FORMAT

    setup = _setup(setup)
    rng = rng_or_error("rng", rng)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    return {
        "format": FORMAT,
        **_provenance(setup, spec, n_epochs),
        "procedure": DRIVE_PROCEDURE,
        "odometry": asdict(setup.trajectory.odometry),  # the drive's V2X messages are drawn
        "rng_start": copy.deepcopy(rng.bit_generator.state),
    }


def drive_record(setup: DesignSetup, spec, rng: np.random.Generator, n_epochs=None) -> dict:
    """:func:`design_drive`'s drive of ``spec`` from ``rng``, driven now (never read from a
    store), as the record :func:`stored_drive` reads: ``{"key": drive_key(...), "drives": {kind:
    ...}}``, each of :data:`DRIVE_KINDS` (:func:`~tunnelkit.design._drivestore.drive_to_record`).
    ``rng`` ends where the drive leaves it."""
    from ._drivestore import drive_to_record

    setup = _setup(setup)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    key = drive_key(setup, spec, rng, n_epochs)
    both = traced_drive(traced_route(setup, spec), rng, n_epochs=n_epochs)
    end = rng.bit_generator.state
    return {"key": key, "drives": {k: drive_to_record(both[k], end) for k in DRIVE_KINDS}}


def stored_drive(
    setup: DesignSetup, spec, rng: np.random.Generator, n_epochs=None, *, path=None,
    kind: str = "ml-traced",
):  # fmt: skip
    """:func:`design_drive`'s ``kind`` drive (:data:`DRIVE_KINDS`) read from ``path`` (default
    :func:`stored_drive_path`), or None: no file, or a file of another key (:func:`drive_key`):
    another generator state (another seed or run) silently, anything else (another scene, ray
    tracer, format) with a warning
    naming what differs; the caller then drives. A file of this key is checked field by field
    (:func:`~tunnelkit.design._drivestore.drive_from_record`: fields, shapes, types, finite
    values, the generator's end state) and refused (``ValueError`` naming it) when anything is
    off, never half-used. On success ``rng`` is moved to the state the drive left it in."""
    import os

    setup = _setup(setup)
    spec = parse_array(spec)
    rng = rng_or_error("rng", rng)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    kind = choice("kind", kind, DRIVE_KINDS)
    if path is not None and (not isinstance(path, str | os.PathLike) or not str(path)):
        raise TypeError(f"path: expected a file path, got {path!r}")
    drives = _stored(setup, spec, rng, n_epochs, path)
    return None if drives is None else drives[kind]


def _stored(setup, spec, rng, n_epochs, path=None) -> dict | None:
    """:func:`stored_drive` for checked arguments: every kind, ``{kind: drive}``, or None."""
    import warnings

    from ._drivestore import drive_from_record

    if path is None:
        p = stored_drive_path(setup, spec, n_epochs)
    else:
        p = Path(path)
    if not p.is_file():
        return None
    try:
        rec = json.loads(p.read_text())
    except (ValueError, UnicodeDecodeError) as exc:
        raise ValueError(f"path: {p} is not a stored drive ({exc})") from None
    if not isinstance(rec, dict) or "key" not in rec:
        raise ValueError(f"path: {p} is not a stored drive (expected its key and drives)")
    key, now = rec["key"], drive_key(setup, spec, rng, n_epochs)

    def same(a, b):
        return json.dumps(a, sort_keys=True, default=str) == json.dumps(
            b, sort_keys=True, default=str
        )

    if not isinstance(key, dict) or not same(key.get("rng_start"), now["rng_start"]):
        return None  # another drive of this array and route
    differ = [k for k in now if not same(key.get(k), now[k])] + sorted(set(key) - set(now))
    if differ:
        warnings.warn(
            f"{p} holds this drive made with other {', '.join(differ)} than now: driven again "
            "(tools/traced_drive.py rewrites it)",
            RuntimeWarning,
            stacklevel=3,
        )
        return None  # (a record of another format is passed over before its fields are read)
    if not {"key", "drives"} <= set(rec) <= _STORED_FIELDS:
        raise ValueError(f"path: {p} is not a stored drive (expected its key and drives)")
    if not isinstance(rec["drives"], dict) or set(rec["drives"]) != set(DRIVE_KINDS):
        raise ValueError(f"path: {p} drives: expected one drive of each kind {DRIVE_KINDS}")
    route, out, ends = traced_route(setup, spec), {}, []
    for k in DRIVE_KINDS:
        out[k], end = drive_from_record(
            rec["drives"][k], route, f"path: {p} {k}", now["rng_start"]["bit_generator"]
        )
        ends.append(end)
    if not same(ends[0], ends[1]):
        raise ValueError(f"path: {p} drives: the kinds end in different generator states")
    rng.bit_generator.state = ends[0]
    return out


def _error_trial(route, n_epochs, _input, rng):
    return traced_drive(route, rng, n_epochs=n_epochs)["ml-all"]


def _provenance(setup: DesignSetup, spec, n_epochs: int | None) -> dict:
    """What a stored record must match: scenario, array, epochs, procedure, nuisance and the
    scene (:func:`tunnelkit.simulation.prefilter.scene_provenance` of the array's traced route)."""
    from ..simulation.prefilter import scene_provenance

    route = traced_route(setup, spec)
    T = len(setup.trajectory)
    return {
        "procedure": PROCEDURE,
        "scenario": setup.name,
        "array": parse_array(spec).label,
        "n_epochs": None if n_epochs is None or n_epochs >= T else int(n_epochs),
        "nuisance": dict(TRACED_NUISANCE),
        **scene_provenance(route),
    }


def measure_design_errors(
    setup: DesignSetup,
    spec,
    runs: int = ERROR_RUNS,
    seed: int = ERROR_SEED,
    *,
    n_epochs: int | None = None,
    progress: bool = False,
) -> dict:
    """``spec``'s traced measurement noise, measured: ``runs`` design drives on the ray-traced
    channel (drive ``i`` from the ``i``-th child of ``seed``, as run ``i`` of a sweep on
    ``seed``: :func:`~tunnelkit.runner.run_trials`), every epoch's ML measurements
    (``"ml-all"`` of :func:`traced_drive`), their RMS errors per kind of path
    (:func:`~tunnelkit.simulation.analysis.extraction_errors`, the ``"all"`` row the sigmas),
    and of the same epochs the path taken for the line of sight against the true one
    (:func:`~tunnelkit.design.los.los_errors`: ``los_rows``, one per epoch with a path, measured
    elevation, azimuth error, elevation error [rad]; the line-of-sight tracker's survey,
    :mod:`tunnelkit.design.tracedlos`). Returns the record (provenance, ``seed``, ``runs``,
    ``columns``, ``rows``, ``los_rows``, the wall time) :func:`design_errors` stores."""
    import time

    from ..runner import run_trials
    from ..simulation.analysis import error_correlations, extraction_errors

    setup = _setup(setup)
    spec = parse_array(spec)
    runs = integer("runs", runs, minimum=1)
    check_bytes("runs", runs * RUN_BYTES, f"{runs} traced drives")
    seed = integer("seed", seed, minimum=0)
    progress = boolean("progress", progress)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    route = traced_route(setup, spec)
    t0 = time.perf_counter()
    drives = run_trials(
        partial(_error_trial, route, n_epochs), runs, seed, inputs=[None] * runs,
        progress=progress, desc=f"traced errors {spec.label}",
    )  # fmt: skip
    cols, rows = extraction_errors(drives)
    corr = error_correlations(drives)
    from .los import LOS_WINDOW_M, los_errors

    try:
        los = los_errors(drives).tolist()
    except ValueError:  # no epoch with a path: no survey (the line-of-sight tracker refuses it)
        los = []
    return {
        **_provenance(setup, spec, n_epochs),
        "seed": seed,
        "runs": runs,
        "wall_s": round(time.perf_counter() - t0, 1),
        "columns": list(cols),
        "rows": [[r[0], *(float(x) if isinstance(x, float) else x for x in r[1:])] for r in rows],
        "correlation": corr,
        "los_window_m": LOS_WINDOW_M,
        "los_rows": los,
    }


def design_errors_path(setup: DesignSetup, spec, n_epochs: int | None = None) -> Path:
    """Where :func:`design_errors` keeps ``spec``'s record, ``<scenario>-<array>[-T<n_epochs>].json``:
    in ``data/rt/design/`` when the repository ships it (the paper tunnel's arrays), else in the
    ray-tracing cache's ``design-errors/`` (:func:`tunnelkit.rt.cache.default_cache_dir`)."""
    from ..rt.cache import default_cache_dir
    from ..scenarios import data_dir

    fname = f"{_record_stem(setup, spec, n_epochs)}.json"
    shipped = data_dir() / "rt" / "design" / fname
    return shipped if shipped.is_file() else default_cache_dir() / "design-errors" / fname


def _record_stem(setup: DesignSetup, spec, n_epochs: int | None) -> str:
    """``<scenario>-<array>[-T<n_epochs>]`` (no tail for the whole route)."""
    setup = _setup(setup)
    spec = parse_array(spec)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    T = len(setup.trajectory)
    tail = "" if n_epochs is None or n_epochs >= T else f"-T{n_epochs}"
    name = "".join(c if c.isalnum() or c in "-_." else "_" for c in setup.name)
    return f"{name}-{spec.label}{tail}"


def _mismatch(stored: dict, current: dict) -> list[str]:
    from ..simulation.prefilter import check_provenance

    out = []
    for k in ("procedure", "scenario", "array", "n_epochs", "nuisance"):
        if json.dumps(stored.get(k), default=str) != json.dumps(current[k], default=str):
            out.append(f"{k}: stored {stored.get(k)!r}, now {current[k]!r}")
    try:
        unchecked = check_provenance(stored, current)
    except ValueError as exc:
        out.append(str(exc).removeprefix("record: "))
    else:
        out += [f"{u}: absent from the record" for u in unchecked]
    return out


def design_errors(
    setup: DesignSetup,
    spec,
    *,
    n_epochs: int | None = None,
    path=None,
    measure: bool = True,
    progress: bool = False,
) -> dict:
    """``spec``'s traced-error record (:func:`measure_design_errors`), read from ``path``
    (default :func:`design_errors_path`) when its provenance matches the current scene, array,
    epochs and ray tracer; a record that does not match is refused (``ValueError`` naming what
    differs: delete it to re-measure), never reused. A missing record is measured on
    :data:`ERROR_RUNS` drives of seed :data:`ERROR_SEED` and stored (``measure=False``:
    ``FileNotFoundError`` instead). The record gains ``path``."""
    setup = _setup(setup)
    spec = parse_array(spec)
    measure = boolean("measure", measure)
    progress = boolean("progress", progress)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    if path is None:
        p = design_errors_path(setup, spec, n_epochs)
    else:
        import os

        if not isinstance(path, str | os.PathLike) or not str(path):
            raise TypeError(f"path: expected a file path, got {path!r}")
        p = Path(path)
    current = _provenance(setup, spec, n_epochs)
    if p.is_file():
        rec = json.loads(p.read_text())
        differ = _mismatch(rec, current)
        if differ:
            raise ValueError(
                f"path: {p} holds traced errors of another scene, array or ray tracer ("
                + "; ".join(differ)
                + "); delete it to re-measure"
            )
    else:
        if not measure:
            raise FileNotFoundError(f"path: no traced errors at {p}")
        rec = measure_design_errors(setup, spec, n_epochs=n_epochs, progress=progress)
        p.parent.mkdir(parents=True, exist_ok=True)
        tmp = p.with_name(f".{p.name}.tmp")
        tmp.write_text(json.dumps(rec, indent=1, default=str) + "\n")
        tmp.replace(p)
    if not any(r[0] == "all" for r in rec.get("rows", [])):
        raise ValueError(f"path: {p} holds no 'all' row of extraction_errors")
    return {**rec, "path": str(p)}


def _sigmas(record: dict) -> dict:
    row = {r[0]: r for r in record["rows"]}["all"]
    names = ("phi_deg", "psi_deg", "kappa_m", "delta_d_m")
    vals = [float(v) for v in row[2:6]]
    if not all(np.isfinite(v) and v > 0 for v in vals):
        raise ValueError(f"record: the 'all' row's sigmas must be finite and > 0, got {vals}")
    return dict(zip(names, vals, strict=True))


def traced_javelin(setup: DesignSetup, spec, record: dict):
    """The design's tracker (:func:`~tunnelkit.design.montecarlo.javelin_config`: VUEs from the
    known surfaces, likelihood association, joint innovation test) with the measurement noise of
    ``record`` (:func:`design_errors`): fixed sigmas (the ``"all"`` row:
    :func:`~tunnelkit.tracking.javelin.measured.design_from_errors`, at their long-run value when
    the record carries the errors' lag-1 correlation, as the shipped records do; the RMS as it
    is for a record without it) in place of each path's reported CRLB, which on this channel is thousands of times too
    small."""
    from ..tracking.javelin.arraydesign import array_design
    from ..tracking.javelin.measured import design_from_errors
    from .geometry import KINDS

    setup = _setup(setup)
    spec = parse_array(spec)
    if not isinstance(record, dict) or "rows" not in record:
        raise TypeError("record: expected the dict of design_errors")
    s = _sigmas(record)
    crlb = {
        "d": s["delta_d_m"],
        "direction": float(np.radians(s["phi_deg"])),
        "kappa": s["kappa_m"],
    }
    # the design's tracker (montecarlo.javelin_config) with the tunnel's known planes
    planes = [f.plane for f in setup.tunnel.surfaces if f.kind in KINDS]
    base = array_design(crlb, setup.signal_route(spec).min_d, planes)
    base = base.with_(noise=base.noise.fallback)
    return design_from_errors(record["rows"], base=base, correlation=record.get("correlation"))


def error_model_summary(record: dict | None, config=None, los: dict | None = None) -> dict:
    """What the report's JSON says about an array's measurement-noise model: ``{"kind":
    "reported-crlb"}`` (``record`` None: each path's reported CRLB, the image channel's), or the
    traced record's ``kind`` "traced-measured", sigmas (the RMS errors), the errors' lag-1
    correlation (the tracker's sigmas are the RMS times ``sqrt((1 + r) / (1 - r))``; None for a
    record without it), seed, runs, file and scene key; with ``config`` (the tracker's
    JavelinConfig, :func:`traced_javelin`) also ``told_sigmas``, the sigmas it is told; with
    ``los`` (the line-of-sight tracker's table and survey,
    :func:`tunnelkit.design.tracedlos.los_summary`) ``tracker`` "los" and ``los`` (else
    ``tracker`` "paths")."""
    if record is None:
        return {"kind": "reported-crlb"}
    if not isinstance(record, dict) or "rows" not in record:
        raise TypeError("record: expected the dict of design_errors or None")
    if los is not None:  # the line-of-sight tracker's summary (its module loaded with it)
        from .tracedlos import SUMMARY_KEYS

        if not isinstance(los, dict) or set(los) != set(SUMMARY_KEYS):
            raise TypeError(f"los: expected the dict of tracedlos.los_summary or None, got {los!r}")
    told = {}
    if config is not None:
        c = config_sigmas(config)
        told = {"told_sigmas": {"phi_deg": float(np.degrees(c["phi"])),
                                "psi_deg": float(np.degrees(c["psi"])),
                                "kappa_m": c["kappa"], "delta_d_m": c["d"]}}  # fmt: skip
        if los is not None:  # its angles are the table's (``los``), these only the fallback
            told["told_sigmas"] = {k: told["told_sigmas"][k] for k in ("kappa_m", "delta_d_m")}
    return {
        "kind": "traced-measured",
        "sigmas": _sigmas(record),
        "correlation": record.get("correlation"),
        "seed": record.get("seed"),
        "runs": record.get("runs"),
        "n_epochs": record.get("n_epochs"),
        "prefilter": "geometry_keep",
        "path": record.get("path"),
        "rt_key": record.get("rt_key"),
        **told,
        "tracker": "paths" if los is None else "los",
        **({} if los is None else {"los": los}),
    }
