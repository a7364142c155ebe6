"""The ray-traced channel's own columns of Tables 1-2 (``tunnelkit reproduce javelin-table1|2
--channel sionna``).

On that channel the ML route's own fit test flags every epoch (eq. 1 does not describe the traced
tensor), so the tables' ML columns carry no measurement. Two columns use the radio there:

- :data:`TRACED_COLUMN`: the traced design (measurement noise measured on the channel,
  :func:`~tunnelkit.studies.traced.traced_design`) fed every epoch's ML measurements that the
  geometry-consistency test keeps (the ``"ml-traced"`` drive of
  :func:`~tunnelkit.studies.traced.simulate_traced`);
- :data:`LOS_COLUMN`: the line of sight alone, as the array design's line-of-sight tracker takes
  it (:mod:`tunnelkit.design.tracedlos`): of every epoch's ML measurements (``"ml-all"``) the path
  taken for the line of sight, without truth, told its angle sigmas by its measured elevation
  from the survey the array design keeps for the scene's array (:func:`los_survey`: the first 3
  design drives of seed 0), fed to the traced column's JAVELIN (``designs.ours_ml`` with the
  traced sigmas, not the design's tracker of known surfaces) reading what it is told
  (:func:`los_design`). The tables start
  every tracker at the true position told 1 m; this one is told :data:`LOS_START_M`, the size of
  the start it has (told 1 m, it lets angles of degrees move a start that is right:
  ``docs/results/baselines.md``).
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from .._validate import boolean, instance, text
from ..design import DesignSetup
from ..design.los import ElevationSigmas
from ..design.traced import design_errors
from ..design.tracedlos import SUMMARY_KEYS, los_javelin, los_summary, los_table, told_los
from ..scenarios import data_dir, load_scenario
from ..simulation.prefilter import FLOORS
from ..studies.traced import traced_design, traced_errors

__all__ = [
    "LOS_COLUMN",
    "LOS_START_M",
    "TRACED_COLUMN",
    "los_design",
    "los_drive",
    "los_note",
    "los_survey",
    "traced_note",
]

#: the traced design fed the ML route's measurements of every epoch that the geometry pre-filter
#: keeps: (label, measurement route, design)
TRACED_COLUMN = ("traced design + geometry test, ML route", "ml-traced", "traced")
#: the design's line-of-sight tracker on the ML route's measurements of every epoch
LOS_COLUMN = ("line of sight told by elevation, ML route", "ml-los", "los")
#: [m] the start uncertainty the line-of-sight column is told (the tables start at the truth)
LOS_START_M = 0.1


@functools.cache
def los_design():
    """The line-of-sight column's JAVELIN: the traced column's design reading each
    measurement's covariance (:func:`tunnelkit.design.tracedlos.los_javelin`)."""
    return los_javelin(traced_design())


def _array_label(sc) -> str:
    """The loaded scenario's base-station array as the design names it ("10x10"; the schema's
    arrays are half-wavelength URAs); its arrays must share one shape (the survey is of one
    array)."""
    shapes = {tuple(int(v) for v in t["shape"]) for t in sc.section("base_station")["arrays"]}
    if len(shapes) != 1:
        raise ValueError(
            f"scenario: {sc.name!r} mounts arrays of {len(shapes)} shapes; the line-of-sight "
            "column's survey is of one array"
        )
    rows, cols = shapes.pop()
    return f"{rows}x{cols}"


def los_survey(scenario: str, progress: bool = False):
    """The line-of-sight column's table and what the report says of it: ``(table, summary)``
    (:func:`tunnelkit.design.tracedlos.los_table` and ``los_summary``, the record's path from
    the repository's root when it ships it) of the record the array
    design keeps for ``scenario``'s array on the ray-traced channel
    (:func:`tunnelkit.design.traced.design_errors`: shipped for the paper's straight tunnel,
    else measured once on 3 drives of seed 0 and cached)."""
    if "\0" in text("scenario", scenario):
        raise ValueError("scenario: a name or path holds no null character")
    boolean("progress", progress)
    sc = load_scenario(scenario)  # read once: its arrays, then the design's setup
    setup = DesignSetup.from_scenario(sc, channel="sionna")
    record = design_errors(setup, _array_label(sc), progress=progress)
    table = los_table(record)
    summary = los_summary(record, table)
    where = Path(str(summary["path"]))
    if where.is_relative_to(data_dir().parent):  # the repository's: named from its root
        summary["path"] = str(where.relative_to(data_dir().parent))
    return table, summary


def los_drive(drive, table):
    """``drive`` (an ``"ml-all"`` drive of :func:`~tunnelkit.studies.traced.simulate_traced`)
    cut to the path taken for the line of sight and told its sigmas from ``table``
    (:func:`tunnelkit.design.tracedlos.told_los` with :func:`los_design`'s sigmas)."""
    instance("table", table, ElevationSigmas)
    return told_los(drive, table, los_design().config)


def los_note(summary: dict) -> str:
    """The line-of-sight column's note: its pick, its table (from ``summary``,
    :func:`los_survey`'s) and its start."""
    instance("summary", summary, dict)
    missing = [k for k in SUMMARY_KEYS if k not in summary]
    if missing:
        raise ValueError(f"summary: expected los_survey's summary, missing {missing}")
    bins = ElevationSigmas.from_dict(summary["table_deg"]).describe()
    return (
        f"Column '{LOS_COLUMN[0]}': the line of sight alone as the array design takes it "
        "(design.tracedlos): of every epoch's ML measurements (the fit's own test ignored) the "
        f"path taken for the line of sight (within {summary['window_m']:g} m of the earliest "
        "arrival, the lowest in elevation; no truth), told its azimuth / elevation sigmas by "
        f"its measured elevation ({bins}: {summary['bins']} bins of the {summary['epochs']} "
        f"epochs the design surveyed on {summary['runs']} drives of seed {summary['seed']}, "
        f"{summary['path']}; the design's drives: the scene's ray tracer, no visibility "
        "condition), fed to the traced column's JAVELIN (its curvature and delay sigmas); started "
        f"at the true position told {LOS_START_M:g} m (the other columns are told 1 m)."
    )


def traced_note(nuisance: dict | None, rt_info: dict | None = None) -> str:
    """The traced column's note, its numbers read from the stored record (checked against the
    current scene, :func:`~tunnelkit.studies.traced.traced_errors`), and whether the table's
    route (its nuisance, its ray-tracer settings ``rt_info["rt_settings"]``) is the one they
    were measured on."""
    for name, value in (("nuisance", nuisance), ("rt_info", rt_info)):
        if value is not None:
            instance(name, value, dict)
    rec = traced_errors()
    a = {r[0]: r for r in rec["rows"]}["all"]
    corr = rec.get("correlation") or {}
    r_txt = ", ".join(f"{q} {v['r']:.2f}" for q, v in corr.items() if np.isfinite(v["r"]))
    same = dict(nuisance or {}) == rec["nuisance"]
    mine, theirs = (rt_info or {}).get("rt_settings"), rec.get("rt_settings") or {}
    other = sorted(k for k in mine or {} if mine[k] != theirs.get(k))
    return (
        f"Column '{TRACED_COLUMN[0]}': designs.ours_ml with its measurement noise set to the ML "
        f"route's RMS error on the ray-traced channel ({a[2]:.3g} deg, {a[3]:.3g} deg, "
        f"{a[4]:.3g} m, {a[5]:.3g} m over {a[1]} matched paths; {rec['scenario']}, condition "
        f"{rec['condition']}, seed {rec['seed']}, {rec['runs']} runs: "
        "studies.traced.measure_traced_errors on children 0.."
        f"{rec['runs'] - 1} of seed {rec['seed']}, stored in data/rt/traced_errors.json; Table 1's "
        "JAVELIN-L run 0 at that seed is child 0, one of those drives)"
        + (
            f", each sigma times sqrt((1 + r) / (1 - r)) for the lag-1 correlation r of one "
            f"path's errors from epoch to epoch ({r_txt}; simulation.error_correlations)"
            if r_txt
            else ""
        )
        + ", fed every epoch's ML "
        "measurements "
        "(the fit's own test ignored) that the geometry-consistency test keeps "
        f"(path_consistency.epoch_consistency, floors {np.degrees(FLOORS[0]):.2g} deg and "
        f"{FLOORS[1]:.2g} m, chosen on the straight drive at seed 0)."
        + (
            ""
            if same
            else f" The sigmas were measured on the route with {rec['nuisance']}, this table "
            f"runs {dict(nuisance or {})} (pass --diffuse-floor for the route they belong to)."
        )
        + (
            " This table's ray tracer differs from the one the sigmas were measured with ("
            + ", ".join(f"{k}: {theirs.get(k)!r} there, {mine[k]!r} here" for k in other)
            + "): they are applied as they are, not re-measured."
            if other
            else ""
        )
    )
