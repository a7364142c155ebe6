"""Italiano et al. 2026, Tables 1-2: JAVELIN and TeNFiLoc on the straight and slalom drives.

Every run simulates a drive through the signal route (image method -> SRS tensor with noise and
clock bias) once per condition and measures each epoch's tensor through several extraction
routes (:data:`tunnelkit.simulation.EXTRACTIONS`): the paper's (CPD, eq. 11-24)
and the joint maximum-likelihood fit of eq. 1 (``ml``); the tensors are identical, only the
extraction differs. The table has five columns per configuration and metric: the paper's design
(section 4.2) on the paper's route, the paper's design on the ML route, the same with the
curvature of a reflection centred on its VUE (:func:`~tunnelkit.tracking.javelin.designs.paper_vue`), our design on the ML route
(:func:`~tunnelkit.tracking.javelin.designs.ours_ml`, its noise set from the measured
extraction error), and the paper's published number.
"""

from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np

from .._validate import boolean, choice, instance, integer, sequence, text
from ..odometry import MODELS, Odometry
from ..reference import load as load_reference
from ..simulation.baselines import without_radio
from ..simulation.collect import collect_drives, collect_routes, per_drive, simulate_condition
from ..simulation.drives import FLAGGED
from ..simulation.scoring import evaluate
from ..simulation.variants import drive_variant
from ..studies.traced import simulate_traced, traced_design
from ..tracking.javelin import designs
from ..tracking.javelin.config import MOTION_STEPS
from . import Report, register
from .javelin_direct import DIRECT_COLUMN, direct_note, direct_scores, direct_table
from .javelin_notes import (
    DEAD_RECKONING,
    NOTES,
    RT_NOTES,
    gain_note,
    nuisance_note,
    odometry_note,
    radio_gains,
    seed_note,
    step_note,
)
from .javelin_traced import (
    LOS_COLUMN,
    LOS_START_M,
    TRACED_COLUMN,
    los_design,
    los_drive,
    los_note,
    los_survey,
    traced_note,
)

__all__ = [
    "COLUMNS",
    "DEAD_RECKONING",
    "NOTES",
    "collect_drives",
    "collect_routes",
    "javelin_table",
    "radio_gains",
    "score_drive",
    "seed_note",
    "table_columns",
    "table_rows",
]

_METRICS = ("rmse_2d_m", "mae_2d_m", "y_mae_m")

#: the table's columns: (label, measurement route, design); a design is a name of :func:`_designs`
COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("paper design, paper route", "paper", "paper"),
    ("paper design, ML route", "ml", "paper"),
    ("paper design + VUE curvature, ML route", "ml", "paper-vue"),
    ("our design, ML route", "ml", "ours"),
)
#: the column added when the coherent route was measured too
COHERENT_COLUMN = ("our design, coherent route", "coherent", "ours-coherent")
#: the columns added on the ray-traced channel (:mod:`.javelin_traced`): :data:`TRACED_COLUMN`
#: and :data:`LOS_COLUMN`; the latter's tracker is told a start of :data:`LOS_START_M`
_START_M = {LOS_COLUMN[2]: LOS_START_M}


def _designs(traced: bool = False) -> dict:
    out = {
        "paper": designs.paper(),
        "paper-vue": designs.paper_vue(),
        "ours": designs.ours_ml(),
        "ours-coherent": designs.ours_coherent(),
    }
    if traced:
        out["traced"] = traced_design()
        out["los"] = los_design()
    return out


def table_columns(
    routes, columns: tuple[tuple[str, str, str], ...] | None = None
) -> tuple[tuple[str, str, str], ...]:
    """The columns a table of ``routes`` (names of measured routes) has: ``columns`` (default
    :data:`COLUMNS`, plus :data:`COHERENT_COLUMN` when that route is present) without those whose
    route is missing."""
    instance("routes", routes, (dict, list, tuple), "route names")
    if columns is not None:
        sequence("columns", columns)
    routes = tuple(routes)
    if columns is None:
        columns = COLUMNS + ((COHERENT_COLUMN,) if "coherent" in routes else ())
        columns += tuple(c for c in (TRACED_COLUMN, LOS_COLUMN, DIRECT_COLUMN) if c[1] in routes)
    columns = tuple(c for c in columns if c[1] in routes)
    if not columns:
        raise ValueError(f"routes: none of the table's routes present, got {list(routes)}")
    return columns


def _step(motion_step: str | None) -> str | None:
    """``motion_step`` checked: ``None`` (each design its own) or a name of ``MOTION_STEPS``."""
    return None if motion_step is None else choice("motion_step", motion_step, MOTION_STEPS)


def score_drive(
    drives: dict,
    cond: str,
    columns: tuple[tuple[str, str, str], ...],
    told=None,
    motion_step: str | None = None,
) -> dict[tuple[str, str], dict[str, float]]:
    """One drive of condition ``cond``, measured through each route (``{route: DriveData}``),
    scored in every column: ``{(configuration, column label): metrics}``. JAVELIN runs with the
    column's design; TeNFiLoc (no design of its own) on LoS drives, in the paper design's
    columns; dead reckoning (:data:`DEAD_RECKONING`: the column's JAVELIN, start and V2X
    messages with every measurement dropped) in every column, the baseline the radio must beat.
    Each (route, method, design) is evaluated once. Draws no random numbers. ``told`` (an
    :class:`~tunnelkit.odometry.Odometry`): every JAVELIN is told that odometry model
    (:meth:`~tunnelkit.tracking.javelin.JavelinConfig.told`: its bias states); ``None`` the
    designs as they are (the paper's white motion noise). ``motion_step``: how the designs step
    on the messages, ``None`` each its own (the paper's design holds the message of the
    previous epoch, eq. 62; ours step on the midpoint of two), or every JAVELIN the same, a
    name of :data:`~tunnelkit.tracking.javelin.config.MOTION_STEPS`."""
    instance("drives", drives, dict, "drives per route (a dict)")
    text("cond", cond)
    sequence("columns", columns)
    table_designs = _designs(traced=any(c[2] in ("traced", "los") for c in columns))
    if told is not None:
        instance("told", told, Odometry)
        table_designs = {k: d.with_(config=d.config.told(told)) for k, d in table_designs.items()}
    if _step(motion_step) is not None:
        table_designs = {
            k: d.with_(config=replace(d.config, motion_step=motion_step))
            for k, d in table_designs.items()
        }
    cache: dict[tuple[str, str, str], dict[str, float]] = {}
    out = {}
    for label, route, design in columns:
        entries = [(f"JAVELIN-{cond}", "JAVELIN", design)]
        if cond == "L" and design == "paper":  # once per route
            entries.append(("TeNFiLoc-L", "TeNFiLoc", "none"))
        entries.append((f"{DEAD_RECKONING}-{cond}", DEAD_RECKONING, design))
        for name, method, dname in entries:
            key = (route, method, dname)
            if key not in cache:
                drive = drives[route]
                if method == DEAD_RECKONING:
                    drive, method = without_radio(drive), "JAVELIN"
                cache[key] = evaluate(
                    drive, table_designs.get(dname), method=method,
                    sigma_p0_ue=_START_M.get(dname, 1.0),
                ).metrics  # fmt: skip
            out[(name, label)] = cache[key]
    return out


def _rows(scores: dict, reference: str, columns) -> tuple[list[str], list[list]]:
    """Rows ``[configuration, metric, <mean per column>, paper]`` from ``{(name, label): [metrics
    per drive]}``; configurations in the paper's order, extra ones after."""
    ref = {r["configuration"]: r for r in load_reference(reference)}
    names = list(dict.fromkeys(n for n, _ in scores))
    order = {n: i for i, n in enumerate(ref)}
    names.sort(key=lambda n: order.get(n, len(order)))
    rows = []
    for name in names:
        for metric in _METRICS:
            row: list = [name, metric]
            for label, _, _ in columns:
                lst = scores.get((name, label))
                row.append(float(np.mean([m[metric] for m in lst])) if lst else None)
            row.append(ref.get(name, {}).get(metric))
            rows.append(row)
    return ["configuration", "metric", *(c[0] for c in columns), "paper"], rows


def table_rows(
    routes: dict[str, dict[str, list]],
    reference: str,
    columns: tuple[tuple[str, str, str], ...] | None = None,
    progress: bool = False,
) -> tuple[list[str], list[list]]:
    """Rows ``[configuration, metric, <one value per column>, paper]``, means over runs.

    ``routes`` is :func:`collect_routes`' output (``{route: {condition: drives}}``); ``columns``
    as :func:`table_columns`; each drive is scored by :func:`score_drive`. ``progress``: a tqdm
    bar over the drives scored (nothing here draws random numbers).
    """
    instance("routes", routes, dict, "drives per route (a dict)")
    text("reference", reference)
    boolean("progress", progress)
    from tqdm.auto import tqdm

    columns = table_columns(routes, columns)
    used = list(dict.fromkeys(route for _, route, _ in columns))
    total = sum(len(d) for r in used for d in routes[r].values())
    bar = tqdm(total=total, desc=f"{reference}: scoring drives", leave=False, disable=not progress)
    scores: dict[tuple[str, str], list[dict[str, float]]] = {}
    for route in used:
        mine = tuple(c for c in columns if c[1] == route)
        for cond, drives in routes[route].items():
            for drive in drives:
                for key, metrics in score_drive({route: drive}, cond, mine).items():
                    scores.setdefault(key, []).append(metrics)
                bar.update()
    bar.close()
    return _rows(scores, reference, columns)


def _simulate_and_score(
    scenario,
    n_epochs,
    extractions,
    columns,
    cond,
    rng,
    channel="image",
    nuisance=None,
    length=None,
    odometry="white",
    told=False,
    los_table=None,
    motion_step=None,
    direct=False,
):
    """One trial of :func:`javelin_table`: a drive (:func:`~tunnelkit.simulation.collect.simulate_condition`) scored in every column on
    the worker (:func:`score_drive`), so only the metrics travel back; also each route's fault
    count. ``length``: the drive of :func:`~tunnelkit.simulation.variants.drive_variant` instead of
    the preset's (built on the worker, once per process); ``odometry`` a name of
    :data:`tunnelkit.odometry.MODELS`; ``told``: JAVELIN is told that model (:func:`score_drive`);
    ``los_table``: the line-of-sight column's table (:func:`.javelin_traced.los_survey`);
    ``motion_step`` as :func:`score_drive` takes it; ``direct``: a condition-L trial also runs
    the direct column's own drive (:func:`.javelin_direct.direct_scores`) from a generator
    spawned from ``rng`` (the other columns' draws unchanged)."""
    route = scenario if length is None else drive_variant(scenario, length)
    odo = MODELS[odometry]
    if any(c[1] == TRACED_COLUMN[1] for c in columns):  # the traced columns: more adapters
        drives = simulate_traced(
            route, rng, condition=cond, n_epochs=n_epochs, channel=channel, nuisance=nuisance,
            odometry=odo,
        )  # fmt: skip
        drives[LOS_COLUMN[1]] = los_drive(drives["ml-all"], los_table)
        drives = {e: drives[e] for e in (*extractions, TRACED_COLUMN[1], LOS_COLUMN[1])}
    else:
        drives = simulate_condition(
            route, n_epochs, extractions, cond, rng, channel=channel, nuisance=nuisance,
            odometry=odo,
        )  # fmt: skip
    faults = {
        e: (len(d.faults), sum(f.endswith(FLAGGED) for f in d.faults), len(d.t))
        for e, d in drives.items()
    }
    scored = tuple(c for c in columns if c != DIRECT_COLUMN)
    out = score_drive(drives, cond, scored, odo if told else None, motion_step)
    if direct and cond == "L":
        one, (n_drop, n_ep) = direct_scores(scenario, n_epochs, rng.spawn(1)[0])
        out[(f"JAVELIN-{cond}", DIRECT_COLUMN[0])] = one["JAVELIN"]
        out[(f"{DEAD_RECKONING}-{cond}", DIRECT_COLUMN[0])] = one[DEAD_RECKONING]
        faults[DIRECT_COLUMN[1]] = (n_drop, 0, n_ep)
    return out, faults


def javelin_table(
    scenario: str,
    reference: str,
    conditions: tuple[str, ...],
    runs: int,
    seed: int,
    progress: bool,
    extractions: tuple[str, ...] = ("paper", "ml"),
    n_epochs: int | None = None,
    channel: str = "image",
    nuisance: dict | None = None,
    length: float | None = None,
    odometry: str = "white",
    told_odometry: bool = False,
    motion_step: str | None = None,
    **parallel,
) -> Report:
    """One table: per configuration and metric, one value per (route, design) column and the
    paper's number beside (``n_epochs`` truncates the drives, for quick checks; ``parallel``
    goes to :func:`~tunnelkit.runner.run_trials`). Each trial simulates one drive and scores
    it where it ran, so scoring runs in parallel too; the drives are the same as
    :func:`collect_routes`' (drive ``i`` draws from the ``i``-th child of ``seed``) and the table
    equals :func:`table_rows` on them.

    ``channel="sionna"`` runs every drive on the ray-traced channel
    (:class:`~tunnelkit.rt.cache.RayTracedChannel`): the epochs the conditions need (with and,
    for NoRRMs, without the road markings) are traced here first, once, into the cache; the
    trials then read the cache and draw noise and clock bias per run. ``nuisance``: the route's
    ``second_order`` (second-order paths in the model) and ``diffuse_floor`` (the ML fit tested
    against noise + diffuse power), :class:`~tunnelkit.signal_route.SignalRoute`. ``length``
    (image channel, straight lane): the drive lengthened to ``length`` metres ending where the
    preset's ends (:func:`~tunnelkit.simulation.variants.drive_variant`; 120 m: UE ranges 5-125 m);
    ``None`` the preset's drive. ``odometry``: the V2X messages' model, a name of
    :data:`tunnelkit.odometry.MODELS` (the paper's "white" by default); ``told_odometry``:
    JAVELIN is told that model (its bias states, :func:`score_drive`; a model other than white);
    ``motion_step``: how JAVELIN steps on the messages, ``None`` as each design does, or the
    same for every design (:func:`score_drive`). On the
    ray-traced channel the line-of-sight column's table is the array design's survey of the
    scene's array (:func:`.javelin_traced.los_survey`: read, or measured once on 3 traced drives
    and cached, before any trial); a scene it cannot survey (arrays of two shapes, a stale
    record) is refused. There too, on a scene that ships the direct fit's table
    (:func:`.javelin_direct.direct_table`) with the paper's messages and steps (no ``length``,
    white ``odometry``, no ``motion_step``), every condition-L trial also runs the direct
    column's own drive (:data:`.javelin_direct.DIRECT_COLUMN`). :func:`table_rows` scores the
    image channel's columns."""
    sequence("conditions", conditions)
    _step(motion_step)
    choice("odometry", odometry, tuple(MODELS))
    if boolean("told_odometry", told_odometry) and odometry == "white":
        raise ValueError("told_odometry: the tracker is told the white model already (default)")
    integer("runs", runs, minimum=1)
    sequence("extractions", extractions)
    if length is not None:
        if channel != "image" or nuisance:
            raise ValueError(
                "length: a lengthened drive runs on the image channel without route nuisances "
                "(the ray-traced cache holds the preset's tunnel)"
            )
        drive_variant(scenario, length)  # checked (and built) before any trial runs
        length = float(length)
    rt_info = _prepare_channel(scenario, conditions, n_epochs, channel, progress)
    # the line-of-sight column's table: the array design's survey of the scene's array
    traced = LOS_COLUMN[1] in _traced_routes(tuple(extractions), channel)
    # the direct column: the paper's messages and steps on a scene whose table is shipped
    plain = length is None and odometry == "white" and motion_step is None
    direct = traced and plain and "L" in conditions and direct_table(scenario) is not None
    table, survey = los_survey(scenario, progress) if traced else (None, None)
    extractions, done = per_drive(
        scenario,
        conditions,
        runs,
        seed,
        progress,
        extractions,
        lambda e: functools.partial(
            _simulate_and_score,
            scenario,
            n_epochs,
            e,
            table_columns(_traced_routes(e, channel, direct)),
            channel=channel,
            nuisance=nuisance,
            length=length,
            odometry=odometry,
            told=told_odometry,
            los_table=table,
            motion_step=motion_step,
            direct=direct,
        ),
        **parallel,
    )
    return _report(
        scenario,
        reference,
        conditions,
        extractions,
        done,
        channel,
        nuisance,
        length,
        rt_info,
        seed=seed,
        odometry=odometry,
        told=told_odometry,
        survey=survey,
        motion_step=motion_step,
        direct=direct,
    )


def _traced_routes(
    extractions: tuple[str, ...], channel: str, direct: bool = False
) -> tuple[str, ...]:
    """``extractions`` plus the traced columns' routes on the ray-traced channel (when the ML
    route is measured: the traced columns' drives are its measurements), and with ``direct``
    the direct column's (its own drive, :mod:`.javelin_direct`)."""
    if channel == "sionna" and "ml" in extractions and set(extractions) <= {"paper", "ml"}:
        more = (DIRECT_COLUMN[1],) if direct else ()
        return (*extractions, TRACED_COLUMN[1], LOS_COLUMN[1], *more)
    return tuple(extractions)


def _report(
    scenario,
    reference,
    conditions,
    extractions,
    done,
    channel,
    nuisance,
    length,
    rt_info,
    seed,
    odometry="white",
    told=False,
    survey=None,
    motion_step=None,
    direct=False,
):
    """The :class:`Report` of :func:`javelin_table` from its drives' results ``done = [(condition,
    (scores, faults)), ...]`` in drive order (also from a subset of whole runs); ``seed`` the
    seed they were drawn from (:func:`seed_note`); ``survey``: what the line-of-sight column
    was told (:func:`.javelin_traced.los_survey`'s summary); ``motion_step`` the step every
    JAVELIN was made to take (``None``: each design's own); ``direct``: the table has the
    direct column."""
    extractions = _traced_routes(extractions, channel, direct)
    columns = table_columns(extractions)
    scores: dict[tuple[str, str], list[dict[str, float]]] = {}
    faults = dict.fromkeys(extractions, 0)
    flagged = dict.fromkeys(extractions, 0)
    epochs = dict.fromkeys(extractions, 0)
    for cond in conditions:  # the order of table_rows: condition, then run
        for c, (one, _) in done:
            if c == cond:
                for key, metrics in one.items():
                    scores.setdefault(key, []).append(metrics)
    for _, (_, nf) in done:
        for e, (n, n_flag, n_ep) in nf.items():
            faults[e] += n
            flagged[e] += n_flag
            epochs[e] += n_ep
    cols, rows = _rows(scores, reference, columns)
    gains = radio_gains(cols, rows)
    on = "" if channel == "image" else ", ray-traced channel (Sionna RT)"
    if length is not None:
        traj = drive_variant(scenario, length).trajectory.position
        on += f", {length:g} m drive (x = {traj[0, 0]:g} m to {traj[-1, 0]:g} m)"
    if odometry != "white":
        on += f", {odometry} odometry" + (" (JAVELIN told it)" if told else "")
    if motion_step is not None:
        on += ", every JAVELIN stepping on " + (
            "the midpoint of two messages" if motion_step == "midpoint" else "eq. 62's held message"
        )
    return Report(
        title=f"Italiano 2026 {reference.split('_')[-1].title()} - {scenario}{on}: JAVELIN vs "
        "TeNFiLoc",
        columns=cols,
        rows=rows,
        meta={
            "scenario": scenario,
            "seed": seed,
            "extraction_failures": faults,
            "flagged_epochs": flagged,
            "epochs": epochs,
            **({"drive_length_m": length} if length is not None else {}),
            **({"channel": channel, **rt_info} if channel != "image" else {}),
            **({"nuisance": dict(nuisance)} if nuisance else {}),
            **({"odometry": odometry} if odometry != "white" else {}),
            **({"told_odometry": True} if told else {}),
            **({"los_survey": survey} if survey is not None else {}),
            **({"motion_step": motion_step} if motion_step is not None else {}),
            "radio_gain": gains,
        },
        notes=[
            *NOTES,
            seed_note(seed),
            gain_note(gains),
            *(RT_NOTES if channel == "sionna" else []),
            *([traced_note(nuisance, rt_info)] if TRACED_COLUMN[1] in extractions else []),
            *([los_note(survey)] if survey is not None else []),
            *([direct_note(scenario)] if direct else []),
            *([nuisance_note(nuisance)] if nuisance else []),
            *([odometry_note(odometry, told)] if odometry != "white" else []),
            step_note(motion_step),
            "Epochs flagged by the ML route's own fit test (fit_ok = False: a path missed, merged "
            "or in a wrong basin, or the snapshot in the threshold region) carry no measurement "
            "(the tracker predicts only); flagged epochs per route: "
            + ", ".join(f"{e} {flagged[e]} of {epochs[e]}" for e in extractions)
            + ".",
        ],
    )


def _prepare_channel(scenario, conditions, n_epochs, channel, progress) -> dict:
    """Trace the epochs a ray-traced table needs into the cache (nothing for the image channel);
    returns the cache's numbers for the report's meta."""
    from ..signal_route import CHANNELS
    from ..simulation.drives import CONDITIONS, scenario_route

    if channel not in CHANNELS:
        raise ValueError(f"channel: expected one of {CHANNELS}, got {channel!r}")
    if channel == "image":
        return {}
    route = scenario_route(scenario, channel=channel)
    T = len(route.trajectory) if n_epochs is None else min(int(n_epochs), len(route.trajectory))
    tunnels = [route.tunnel] if any(CONDITIONS[c].rrms for c in conditions) else []
    if not all(CONDITIONS[c].rrms for c in conditions):
        tunnels.append(route.tunnel.without_plates())
    info = {"rt_settings": route.raytraced.settings.record()}
    for tun in tunnels:
        st = route.raytraced.prepare(tun, range(T), progress=progress)
        var = route.raytraced.variant(tun)
        info[f"rt_cache_{var}"] = {
            "directory": st["directory"],
            "bytes": st["bytes"],
            "newly_traced": st["traced"],
            "median_trace_s": float(np.median(st["trace_s"])),
        }
    return info


@register(
    "javelin-table1",
    help="Italiano 2026 Table 1: straight drive, JAVELIN (L, N@0.5, N, NoRRMs) vs TeNFiLoc-L, "
    "paper and ML routes",
    default_runs=20,
    bytes_per_run=1024 * 1024,
    channels=("image", "sionna"),
    lengths=True,
    odometries=True,
)
def javelin_table1(
    runs: int,
    seed: int,
    progress: bool,
    channel: str = "image",
    nuisance: dict | None = None,
    length: float | None = None,
    odometry: str = "white",
    told_odometry: bool = False,
    motion_step: str | None = None,
    **parallel,
) -> Report:
    """Table 1 (straight trajectory); ``nuisance``, ``length`` (the drive lengthened, e.g.
    120 m: UE ranges 5-125 m; ``tunnelkit reproduce javelin-table1 --length 120``),
    ``odometry``, ``told_odometry`` and ``motion_step`` as in :func:`javelin_table`."""
    return javelin_table(
        "italiano2026-straight",
        "italiano2026_table1",
        ("L", "N@0.5", "N", "NoRRMs"),
        runs,
        seed,
        progress,
        channel=channel,
        nuisance=nuisance,
        length=length,
        odometry=odometry,
        told_odometry=told_odometry,
        motion_step=motion_step,
        **parallel,
    )


@register(
    "javelin-table2",
    help="Italiano 2026 Table 2: slalom drive, JAVELIN (L, N@0.5, N) vs TeNFiLoc-L, paper and "
    "ML routes",
    default_runs=20,
    bytes_per_run=1024 * 1024,
    channels=("image", "sionna"),
    odometries=True,
)
def javelin_table2(
    runs: int,
    seed: int,
    progress: bool,
    channel: str = "image",
    nuisance: dict | None = None,
    odometry: str = "white",
    told_odometry: bool = False,
    motion_step: str | None = None,
    **parallel,
) -> Report:
    """Table 2 (slalom trajectory); ``nuisance``, ``odometry``, ``told_odometry`` and
    ``motion_step`` as in :func:`javelin_table`."""
    return javelin_table(
        "italiano2026-slalom",
        "italiano2026_table2",
        ("L", "N@0.5", "N"),
        runs,
        seed,
        progress,
        channel=channel,
        nuisance=nuisance,
        odometry=odometry,
        told_odometry=told_odometry,
        motion_step=motion_step,
        **parallel,
    )
