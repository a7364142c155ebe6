"""The notes under Italiano 2026's Tables 1-2 (``tunnelkit reproduce javelin-table1|2``): what
each column and row is, which kind of seed the table ran on, the radio's gain over dead
reckoning, the channel, route model and odometry it ran with."""

from __future__ import annotations

import numpy as np

from .._validate import boolean, choice, instance, integer, sequence
from ..odometry import MODELS
from ..simulation.drives import HELD_OUT_SEED, TUNING_SEEDS
from ..tracking.javelin.config import MOTION_STEPS

__all__ = [
    "DEAD_RECKONING",
    "NOTES",
    "RT_NOTES",
    "gain_note",
    "nuisance_note",
    "odometry_note",
    "radio_gains",
    "seed_note",
    "step_note",
]

#: the baseline row of every condition: the column's tracker on the same V2X speed and heading
#: messages, from the same start, with every radio measurement dropped (predict only)
DEAD_RECKONING = "dead reckoning"

NOTES = [
    "ours: mean over runs of per-run metrics; each run is one drive through the signal route, "
    "measured through every route from the same tensors.",
    "route 'paper': CPD and eq. 11-24 as published (extract_paths(refine='joint')); 'ML': the "
    "joint maximum-likelihood fit of eq. 1 (refine='ml', at the CRLB); 'coherent': the paper's "
    "route with coherent paths separated by the array (refine='coherent').",
    "design 'paper': section 4.2 as printed (sigma_phi = sigma_psi = 2 deg, sigma_kappa = "
    "sigma_dd = 1.5 m, sigma_nu = 0.2 m/s, sigma_theta = 1 deg, sigma_P = 10 m, p = 0.99, "
    "zeta = 1, gamma = 0.2, curvature of a reflection = distance to the reflection point, eq. 51). "
    "'paper design + VUE curvature': the same parameters, the curvature of a reflection modelled "
    "as the distance to its VUE (the exact wavefront's radius, what the ML route measures).",
    "design 'ours' on the ML route (designs.ours_ml): Doppler clutter rejection, global "
    "nearest neighbour, mirrored VUE motion, no update at birth, the step on the midpoint of two "
    "V2X messages, curvature centred on the VUE, measurement noise = the RMS extraction error of the ML route measured on seed 0 drives.",
    "Both designs start from the true first position with 1 m uncertainty (the paper's open-sky fix).",
    "NoRRMs: road markings removed with the LoS blocked (our reading of the paper).",
    "TeNFiLoc-L takes the earliest path as LoS when eq. 61 fails, uses its curvature only when "
    "plausible (|d - kappa| within the clock-bias support, range within 200 m), else its delay "
    "distance, and holds its last fix on epochs without one.",
    f"Seeds: designs were chosen on the tuning seeds {TUNING_SEEDS} (simulation.TUNING_SEEDS); "
    f"simulation.HELD_OUT_SEED ({HELD_OUT_SEED}) was never looked at while choosing anything.",
]


def step_note(motion_step: str | None = None) -> str:
    """How a table's JAVELIN stepped on the V2X messages: ``None`` each design its own (the
    paper's eq. 62, ours the midpoint), or every design made to take ``motion_step`` (a name of
    :data:`~tunnelkit.tracking.javelin.config.MOTION_STEPS`)."""
    if motion_step is not None:
        choice("motion_step", motion_step, MOTION_STEPS)
    lag = (
        "on a turning drive the held heading lags the chord by half a step, which on the slalom "
        "drive alone is 0.33 m RMS of dead reckoning's error with noise-free messages (0.027 m "
        "stepping on the midpoint). Where either message is missing the midpoint step is held "
        "(every step, with messages slower than the epochs)."
    )
    if motion_step is None:
        return (
            "Motion step: the paper's design steps from epoch k-1 into k on the V2X message of "
            "k-1 held over the step (eq. 62); ours (and the dead reckoning of its columns) on the "
            "mean of the messages of k-1 and k (JavelinConfig(motion_step='midpoint'), "
            "tracking.javelin.motion.midpoint_messages): " + lag
        )
    if motion_step == "midpoint":
        return (
            "Motion step: every JAVELIN here, the paper's design too (and so dead reckoning), "
            "steps from epoch k-1 into k on the mean of the V2X messages of k-1 and k "
            "(motion_step='midpoint'), not on the message of k-1 held over the step (eq. 62): "
            + lag
        )
    return (
        "Motion step: every JAVELIN here, ours too (and so dead reckoning), steps from epoch k-1 "
        "into k on the V2X message of k-1 held over the step (eq. 62, motion_step='held'), as "
        "the paper's design does; ours steps on the midpoint of two by default: " + lag
    )


def seed_note(seed: int) -> str:
    """Which kind of seed a table ran on: the held-out seed, a tuning seed (our design's column
    is then scored on drives its choices were made on), or another seed."""
    seed = integer("seed", seed, minimum=0)
    if seed == HELD_OUT_SEED:
        return f"This table: seed {seed}, the held-out seed: no design choice saw its drives."
    if seed in TUNING_SEEDS:
        return (
            f"This table: seed {seed}, a tuning seed: choices of our design were made on its "
            "drives, so the 'our design' column is not a held-out result (the held-out seed: "
            f"--seed {HELD_OUT_SEED})."
        )
    return (
        f"This table: seed {seed}, neither a tuning seed {TUNING_SEEDS} nor the held-out seed "
        f"({HELD_OUT_SEED}): no design choice saw its drives."
    )


def odometry_note(odometry: str, told: bool = False) -> str:
    """What the V2X messages of the named model (:data:`tunnelkit.odometry.MODELS`) carry, and
    whether JAVELIN is ``told`` it."""
    told = boolean("told", told)
    m = MODELS[choice("odometry", odometry, tuple(MODELS))]
    return (
        f"V2X messages of the {odometry} odometry model (tunnelkit.odometry): speed scale error "
        f"sigma {100 * m.speed_scale:g} %, heading bias {np.degrees(m.heading_bias):g} deg at the "
        f"start, yaw-rate bias {np.degrees(m.yaw_rate_bias) * 3600:g} deg/h, angle random walk "
        f"{np.degrees(m.heading_drift) * 60:g} deg/sqrt(h), "
        f"{'a message every epoch' if m.rate is None else f'{m.rate:g} Hz'}, "
        f"{100 * m.dropout:g} % lost (the last one held); the paper draws white noise only. "
        + (
            "JAVELIN is told the model: the speed scale factor, the heading bias and the yaw-rate "
            "bias are states of its filter, with the model's priors and the heading bias's random "
            "walk (JavelinConfig.told)."
            if told
            else "JAVELIN is not told the model: its motion noise stays the white 0.2 m/s and 1 deg."
        )
    )


def gain_note(gains: dict) -> str:
    """The radio's gain per JAVELIN row and column (``{row: {column: gain or None}}``, as
    :func:`radio_gains` returns it) as one note."""
    gains = instance("gains", gains, dict, "a dict of rows")
    parts = [
        f"{name}: " + ", ".join("-" if g is None else f"{g:.2f}x" for g in by_col.values())
        for name, by_col in gains.items()
    ]
    return (
        "Dead reckoning: the column's JAVELIN on the same drives, start and V2X speed/heading "
        "messages with every radio measurement dropped. The radio's gain (dead reckoning's "
        "2-D RMSE / JAVELIN's, above 1 the radio helps), columns in order: "
        + ("; ".join(parts) if parts else "none measured")
        + "."
    )


RT_NOTES = [
    "Ray-traced channel: each epoch's tensor is every path Sionna RT 2.2 traces per antenna "
    "element (LoS, specular up to the scenario's max_depth, diffuse scattering; ITU concrete "
    "shell, asphalt road as ITU very_dry_ground, metal RRMs; tunnelkit.rt.settings), in eq. 1's "
    "sign convention (tunnelkit.rt.elements); noise and clock bias drawn per run. The number of "
    "paths to extract and the truth are the image method's first-order specular paths; "
    "the image channel's designs are unchanged (chosen on the image channel).",
]


def nuisance_note(nuisance: dict) -> str:
    """The route model's note: ``nuisance``'s ``second_order`` / ``diffuse_floor``."""
    nuisance = instance("nuisance", nuisance, dict, "a dict")
    n2, floor = nuisance.get("second_order", 0), nuisance.get("diffuse_floor", False)
    return (
        f"Route model: the first-order paths plus up to {n2} strongest second-order specular "
        "paths the image method predicts (fitted, then left out of the tracker's measurements)"
        + (
            "; the ML fit tested against noise + the epoch's diffuse power (ray tracer)."
            if floor
            else "."
        )
    )


def radio_gains(columns: list[str], rows: list[list]) -> dict[str, dict[str, float | None]]:
    """The radio's gain per JAVELIN row and column of a table (``columns``, ``rows`` as
    :func:`~.javelin_tables.table_rows` returns them): dead reckoning's 2-D RMSE over JAVELIN's
    on the same drives (above 1 the radio helps; None where either is missing)."""
    sequence("columns", columns), sequence("rows", rows)
    rmse = {r[0]: r[2:-1] for r in rows if r[1] == "rmse_2d_m"}
    out: dict[str, dict[str, float | None]] = {}
    for name, values in rmse.items():
        cond = name.rpartition("-")[2]
        base = rmse.get(f"{DEAD_RECKONING}-{cond}")
        if not name.startswith("JAVELIN-") or base is None:
            continue
        out[name] = {
            label: (b / v if v and b is not None and v is not None else None)
            for label, v, b in zip(columns[2:-1], values, base, strict=True)
        }
    return out
