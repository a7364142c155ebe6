"""A traced design drive as a JSON record, and back, checked field by field.

A design drive on the ray-traced channel (:func:`tunnelkit.design.traced.design_drive`) costs
about a second of CPU per epoch (every epoch's ML extraction runs every re-initialisation on that
channel), while the tracker that reads it costs a few milliseconds. Its measurements can
therefore be stored (:func:`tunnelkit.design.traced.drive_record`, written by
``tools/traced_drive.py``) and read back (:func:`tunnelkit.design.traced.stored_drive`). This
module holds the two halves of that: :func:`drive_to_record` encodes what the drive drew and
measured (per epoch the tracker's input, after the geometry pre-filter or not, the true paths they were
matched to, the V2X messages, the generator's state after the drive), and
:func:`drive_from_record` decodes it, refusing (``ValueError`` naming the file) anything that is
not what an encoded drive holds: a missing or extra field, a wrong length or shape, a number of
the wrong type (an integer where a float was written, a boolean for an integer), a NaN or an
infinity where the drive has none, a generator state of another kind. What is not stored is
taken from the route the drive is asked on (times, truth, velocities, the clock bias's support).
Floats are written as Python writes them (``repr``: read back bit for bit), a NaN as ``null``.
"""

from __future__ import annotations

import numbers

import numpy as np

__all__ = ["FORMAT", "drive_from_record", "drive_to_record", "generator_state"]

#: the record's format (part of a stored drive's key: a record of another format is not read);
#: 2: both kinds of the drive (the geometry pre-filter's measurements and every epoch's)
FORMAT = 2
#: the tracker's per-path measurements of one epoch: name -> (trailing shape, NaN allowed)
_PATH_FIELDS = {
    "phi": ((), False),
    "psi": ((), False),
    "kappa": ((), True),  # NaN: far field
    "d": ((), True),
    "v": ((), True),
}
#: the reported uncertainty, stored when the route reports it (null otherwise)
_REPORTED = {"cov": (3, 3), "sigma_d": (), "bias_cov": (4, 4)}
_EPOCH_KEYS = {"measurements", "truth_index", "kinds", "sources"}
_DRIVE_KEYS = {"base_station", "speed", "heading", "los", "n_true", "faults", "epochs", "rng_end"}


def _floats(x: np.ndarray) -> list:
    """``x`` as nested lists of Python floats, NaN as None."""
    return np.where(np.isnan(x), None, x.astype(object)).tolist() if x.size else x.tolist()


def drive_to_record(drive, rng_end: dict) -> dict:
    """The stored part of ``drive`` (a :class:`~tunnelkit.simulation.drives.DriveData` of the
    traced design route) and ``rng_end``, the generator's ``bit_generator.state`` after it."""
    epochs = []
    for k, pm in enumerate(drive.epochs):
        meas = None
        if pm is not None:
            meas = {f: _floats(np.asarray(getattr(pm, f), float)) for f in _PATH_FIELDS}
            meas["source"] = [int(s) for s in pm.source]
            for f in _REPORTED:
                val = getattr(pm, f)
                meas[f] = None if val is None else _floats(np.asarray(val, float))
        epochs.append(
            {
                "measurements": meas,
                "truth_index": [int(i) for i in drive.truth_index[k]],
                "kinds": [str(s) for s in drive.kinds[k]],
                "sources": _floats(np.asarray(drive.sources[k], float).reshape(-1, 3)),
            }
        )
    return {
        "base_station": _floats(np.asarray(drive.base_station, float)),
        "speed": _floats(np.asarray(drive.speed, float)),
        "heading": _floats(np.asarray(drive.heading, float)),
        "los": [bool(x) for x in drive.los],
        "n_true": [int(x) for x in drive.n_true],
        "faults": [str(f) for f in drive.faults],
        "epochs": epochs,
        "rng_end": generator_state("rng_end", rng_end, rng_end.get("bit_generator")),
    }


def _keys(where: str, rec, want: set) -> dict:
    if not isinstance(rec, dict):
        raise ValueError(f"{where}: expected an object, got {type(rec).__name__}")
    if set(rec) != want:
        missing, extra = sorted(want - set(rec)), sorted(set(rec) - want)
        raise ValueError(f"{where}: fields missing {missing}, unexpected {extra}")
    return rec


def _array(where: str, value, shape: tuple, kind: str, nan: bool = False) -> np.ndarray:
    """``value`` (nested lists) as an array of ``shape`` (None: any length) whose every item is a
    Python ``kind`` ("float": a float, or None for NaN when ``nan``; "int"; "bool")."""
    if value == [] and shape and shape[0] in (0, None) and None not in shape[1:]:
        raw = np.zeros((0, *shape[1:]), dtype=object)  # JSON's [] for no row
    else:
        try:
            raw = np.array(value, dtype=object)
        except ValueError:
            raw = None
    if (
        raw is None
        or not isinstance(value, list)
        or raw.ndim != len(shape)
        or any(s is not None and s != n for s, n in zip(shape, raw.shape, strict=True))
    ):
        want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
        got = raw.shape if raw is not None else "ragged"
        raise ValueError(f"{where}: expected shape {want}, got {got}")
    items = raw.ravel().tolist()
    if kind == "bool":
        if not all(isinstance(x, bool) for x in items):
            raise ValueError(f"{where}: expected booleans")
        return raw.astype(bool)
    if kind == "int":
        if not all(isinstance(x, int) and not isinstance(x, bool) for x in items):
            raise ValueError(f"{where}: expected integers")
        return raw.astype(int) if raw.size else np.zeros(raw.shape, int)
    if not all(isinstance(x, float) or (nan and x is None) for x in items):
        raise ValueError(f"{where}: expected floats" + (" or null (NaN)" if nan else ""))
    out = np.array([np.nan if x is None else x for x in items], float).reshape(raw.shape)
    if not np.all(np.isfinite(out) | np.isnan(out)) or (not nan and not np.all(np.isfinite(out))):
        raise ValueError(f"{where}: expected finite values")
    return out


def generator_state(where: str, state, kind) -> dict:
    """``state`` checked as a numpy bit generator's state of ``kind`` (e.g. ``"PCG64"``): the
    fields that kind has, integers in their range."""
    if not isinstance(state, dict) or state.get("bit_generator") != kind or not kind:
        raise ValueError(f"{where}: expected the state of a {kind} bit generator")
    ref = getattr(np.random, str(kind), None)
    if ref is None:
        raise ValueError(f"{where}: unknown bit generator {kind!r}")
    want = ref(0).state
    _keys(where, state, set(want))
    inner = state["state"]
    _keys(f"{where}.state", inner, set(want["state"]))

    def whole(name, x, top):
        if not isinstance(x, numbers.Integral) or isinstance(x, bool) or not 0 <= int(x) < top:
            raise ValueError(f"{where}.{name}: expected an integer in [0, {top})")

    for name, x in inner.items():
        whole(f"state.{name}", x, 2**128)
    for name in set(want) - {"bit_generator", "state"}:
        whole(name, state[name], 2**32)
    return {**state, "state": dict(inner)}


def drive_from_record(rec: dict, route, where: str, rng_kind: str):
    """The :class:`~tunnelkit.simulation.drives.DriveData` that ``rec`` (the ``"drive"`` part of
    a stored record, :func:`drive_to_record`) holds on ``route`` (the traced design route it was
    driven on: times, truth, velocities and the clock bias's support come from it), and the
    generator's state after the drive, checked as a ``rng_kind`` state. ``where`` names the file
    in every refusal (``ValueError``)."""
    from ..simulation.drives import DriveData
    from ..tracking.measurements import PathMeasurements

    rec = _keys(where, rec, _DRIVE_KEYS)
    traj = route.trajectory
    T = len(rec["epochs"]) if isinstance(rec["epochs"], list) else -1
    if not 1 <= T <= len(traj):
        raise ValueError(f"{where}: expected 1 to {len(traj)} epochs, got {T}")
    los = _array(f"{where} los", rec["los"], (T,), "bool")
    n_true = _array(f"{where} n_true", rec["n_true"], (T,), "int")
    if np.any(n_true < 0):
        raise ValueError(f"{where} n_true: expected counts >= 0")
    if not isinstance(rec["faults"], list) or not all(isinstance(f, str) for f in rec["faults"]):
        raise ValueError(f"{where} faults: expected a list of text")
    epochs, tidx, kinds, sources, failed = [], [], [], [], []
    for k, ep in enumerate(rec["epochs"]):
        at = f"{where} epoch {k}"
        ep = _keys(at, ep, _EPOCH_KEYS)
        m = ep["measurements"]
        n = 0
        if m is None:
            failed.append(k)
            epochs.append(None)
        else:
            m = _keys(f"{at} measurements", m, {*_PATH_FIELDS, "source", *_REPORTED})
            src = _array(f"{at} source", m["source"], (None,), "int")
            n = src.size
            if n == 0 or np.any(src < 0):
                raise ValueError(f"{at} source: expected one index >= 0 per path, at least one")
            vals = {
                f: _array(f"{at} {f}", m[f], (n, *tail), "float", nan)
                for f, (tail, nan) in _PATH_FIELDS.items()
            }
            if np.any(vals["kappa"] <= 0):
                raise ValueError(f"{at} kappa: expected curvature radii > 0 (or null: far field)")
            for f, tail in _REPORTED.items():
                vals[f] = None if m[f] is None else _array(f"{at} {f}", m[f], (n, *tail), "float")
            try:
                epochs.append(PathMeasurements(**vals, source=src))
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{at}: {exc}") from None
        ti = _array(f"{at} truth_index", ep["truth_index"], (n,), "int")
        kd = ep["kinds"]
        if not isinstance(kd, list) or not all(isinstance(s, str) for s in kd):
            raise ValueError(f"{at} kinds: expected a list of text")
        if m is not None and len(kd) != n_true[k]:
            raise ValueError(f"{at} kinds: expected n_true = {n_true[k]} kinds, got {len(kd)}")
        if np.any((ti < -1) | (ti >= max(len(kd), 1))):
            raise ValueError(f"{at} truth_index: expected -1 or the index of a true path")
        tidx.append(ti)
        kinds.append(list(kd))
        sources.append(_array(f"{at} sources", ep["sources"], (len(kd), 3), "float"))
    if len(rec["faults"]) != len(failed) or not all(
        f.startswith(f"epoch {k}: ") for f, k in zip(rec["faults"], failed, strict=False)
    ):
        raise ValueError(f"{where} faults: expected one fault per unmeasured epoch {failed}")
    config = route.config
    try:
        drive = DriveData(
            scenario="route", condition=None, t=traj.t[:T].copy(),
            truth=traj.position[:T].copy(), velocity=traj.velocity[:T].copy(),
            speed=_array(f"{where} speed", rec["speed"], (T,), "float"),
            heading=_array(f"{where} heading", rec["heading"], (T,), "float"),
            epochs=epochs, los=los, n_true=n_true,
            base_station=_array(f"{where} base_station", rec["base_station"], (3,), "float"),
            truth_index=tidx, kinds=kinds, faults=list(rec["faults"]), sources=sources,
            extraction="ml", clock_bias_limit=config.clock_bias_limit,
            reports_covariance=bool(route.options.report_covariance),
        )  # fmt: skip
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None
    if not any(np.allclose(drive.base_station, a.origin, rtol=0, atol=1e-12) for a in route.arrays):
        raise ValueError(f"{where} base_station: not the origin of one of the route's arrays")
    return drive, generator_state(f"{where} rng_end", rec["rng_end"], rng_kind)
