"""Side-by-side comparison of two path lists (image method vs Sionna RT) for tables and checks."""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .._validate import choice, instance, integer, positive, sequence, vector
from ..arrays import ArrayGeometry
from ..constants import C
from ..propagation import Path, Tunnel3D

__all__ = ["compare_paths", "lower_into_tunnel", "plate_occluders", "time_engines", "worst_errors"]


#: The difference columns of :func:`compare_paths` (NaN unless both engines found the path).
_DIFF_COLS = (
    "|d delay| [s]",
    "|d az| [deg]",
    "|d el| [deg]",
    "|d Doppler| [Hz]",
    "|d point| [m]",
    "max |d length_m| [m]",
)


def _key(p: Path) -> tuple[str, str]:
    return (p.kind, p.surface)


def plate_occluders(tunnel: Tunnel3D, path: Path, ue, origin) -> list[str]:
    """Names of the RRM plates that a leg of ``path`` crosses (UE -> point -> ``origin``).

    The image method treats plates as reflectors only; a ray tracer also sees them as obstacles,
    so such a path exists in the image method and not in Sionna.
    """
    instance("tunnel", tunnel, Tunnel3D)
    instance("path", path, Path)
    ue, origin = vector("ue", ue, 3), vector("origin", origin, 3)
    legs = [(ue, origin)] if path.kind == "los" else [(ue, path.point), (path.point, origin)]
    hit = []
    for f in tunnel.plates:
        if f.name == path.surface:
            continue
        for a, b in legs:
            da, db = float(f.plane.signed_distance(a)), float(f.plane.signed_distance(b))
            if da * db < 0 and bool(f.contains(a + da / (da - db) * (b - a), tol=0.0)):
                hit.append(f.name)
                break
    return hit


def _paths(name: str, paths) -> list[Path]:
    """A list of :class:`Path` (an engine may find none)."""
    out = sequence(name, paths, empty=True)
    for i, p in enumerate(out):
        instance(f"{name}[{i}]", p, Path)
    return out


def compare_paths(image: list[Path], other: list[Path]) -> list[dict]:
    """One row per path found by either engine, with both values and their differences.

    Columns: path, found ("both", "image only", "sionna only"), delay [ns], |d delay| [s],
    |d az|, |d el| [deg], |d Doppler| [Hz], |d point| [m], max |d length| over the antennas
    [m], and |Gamma| of each engine.
    """
    a = {_key(p): p for p in _paths("image", image)}
    b = {_key(p): p for p in _paths("other", other)}
    rows = []
    for key in list(a) + [k for k in b if k not in a]:
        p, q = a.get(key), b.get(key)
        row = {
            "path": key[1] or "LoS",
            "found": "both" if p and q else ("image only" if p else "sionna only"),
        }
        ref = p or q
        row["delay [ns]"] = ref.length / C * 1e9
        if p and q:
            diffs = (
                abs(p.length - q.length) / C,
                abs(np.degrees(np.angle(np.exp(1j * (p.azimuth - q.azimuth))))),
                abs(np.degrees(p.elevation - q.elevation)),
                abs(p.doppler - q.doppler),
                float(np.max(np.abs(p.point - q.point))),
                float(np.max(np.abs(p.lengths - q.lengths))),
            )
            row.update(zip(_DIFF_COLS, diffs, strict=True))
        else:
            row.update(dict.fromkeys(_DIFF_COLS, float("nan")))
        row["|Gamma| image"] = abs(p.reflection_coefficient) if p else float("nan")
        row["|Gamma| sionna"] = abs(q.reflection_coefficient) if q else float("nan")
        rows.append(row)
    return rows


def worst_errors(rows: list[dict]) -> dict[str, float]:
    """Largest difference per column over the rows found by both engines."""
    for i, r in enumerate(sequence("rows", rows, empty=True)):
        if not isinstance(r, dict) or "found" not in r:
            raise TypeError(f"rows[{i}]: expected a row of compare_paths, got {type(r).__name__}")
    both = [r for r in rows if r["found"] == "both"]
    return {k: max(r[k] for r in both) for k in _DIFF_COLS} if both else {}


def time_engines(
    tunnel: Tunnel3D,
    array,
    ue,
    ue_velocity,
    *,
    fc: float,
    repeat: int = 3,
    engines: tuple[str, ...] = ("image", "sionna"),
    **options,
) -> dict:
    """Run each engine ``repeat`` times on one epoch; ``{engine: (paths, median seconds)}``.

    The Sionna engine is built (scene export + load) and warmed up (JIT compilation) before the
    timed runs, so the times are per epoch in steady state. ``options`` go to the Sionna engine.
    """
    from . import ENGINES, compute_paths

    instance("tunnel", tunnel, Tunnel3D)
    instance("array", array, ArrayGeometry)
    repeat = integer("repeat", repeat, minimum=1, maximum=1000)
    for e in sequence("engines", engines):
        choice("engines", e, ENGINES)
    out = {}
    for eng in engines:
        opts = options if eng == "sionna" else {}
        compute_paths(tunnel, array, ue, ue_velocity, fc=fc, engine=eng, **opts)  # warm-up
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            paths = compute_paths(tunnel, array, ue, ue_velocity, fc=fc, engine=eng, **opts)
            times.append(time.perf_counter() - t0)
        out[eng] = (paths, float(np.median(times)))
    return out


def lower_into_tunnel(tunnel: Tunnel3D, array, *, step: float = 0.05):
    """``array`` moved down in steps of ``step`` [m] until every element is inside ``tunnel``.

    With its reference antenna at the paper's 4.8 m, the JAVELIN 10 x 10 array tilts its top row
    up to 4.998 m, above the 12-facet ceiling (4.970 m at y = 0.229 m; even the circle is only
    4.995 m there): a ray tracer sees those elements behind the concrete. One step of 5 cm
    brings every element inside, which is why the preset hangs the arrays' reference antennas
    at 4.75 m (notebook 07, section 2). Returns ``(array, shift)``.
    """
    instance("tunnel", tunnel, Tunnel3D)
    instance("array", array, ArrayGeometry)
    step = positive("step", step)
    shift = 0.0
    while not np.all(tunnel.contains(array.world - [0.0, 0.0, shift])):
        shift += step
        if shift > tunnel.height:
            raise ValueError("array: cannot be moved inside the tunnel by lowering it")
    return dataclasses.replace(array, origin=array.origin - [0.0, 0.0, shift]), shift
