"""The direct fit's column of Tables 1-2 on the ray-traced channel (``tunnelkit reproduce
javelin-table1|2 --channel sionna``).

Eq. 1's paths do not describe the traced tensor (the tables' other columns: the ML route's fit
test flags every epoch, and the line of sight it takes errs by degrees). The direct fit
(:func:`~tunnelkit.extraction.direct.fit.direct_fix`: every atom of the visibility model tied to one UE
position, one clock bias and one speed) does not fit the paths apart; started at JAVELIN's
prediction in each epoch, it gives a line of sight of tenths of a degree. Because the
measurement depends on the track (a stored drive's fixes replayed only approximate it), the
column runs its own drive
(:func:`~tunnelkit.design.traceddirect.direct_drive`) on each condition-L trial, drawn from a
generator spawned from the trial's (the other columns' draws are unchanged), and its dead
reckoning is the same JAVELIN on that drive's own V2X messages. Its configuration
(:data:`DIRECT_OPTIONS`) and its told angle sigmas by elevation (:func:`direct_table`, shipped
per scene in ``data/rt/direct/``, :mod:`tunnelkit.design.directsurvey`) were chosen on seed 0
(``docs/results/traced-models.md``).
"""

from __future__ import annotations

import numpy as np

from .._validate import integer, rng_or_error
from ..design.directsurvey import SURVEY_SCALE, survey_path, survey_record, surveyed_table
from ..design.los import ElevationSigmas
from ..design.traceddirect import direct_drive
from ..simulation.drives import scenario_route
from ..simulation.scoring import error_metrics
from .javelin_traced import LOS_START_M, los_design

__all__ = [
    "DIRECT_COLUMN",
    "DIRECT_NUISANCE",
    "DIRECT_OPTIONS",
    "direct_note",
    "direct_scores",
    "direct_table",
]

#: the direct fit's column: (label, measurement route, design); its design is the line-of-sight
#: column's JAVELIN (:func:`~.javelin_traced.los_design`)
DIRECT_COLUMN = ("direct fit under JAVELIN, line of sight", "direct", "direct")
#: the direct drive's options (:func:`~tunnelkit.design.traceddirect.direct_drive`): the fit's
#: speed told 0.1 m/s, the second-order atoms on the elements that see them, one diffuse atom
#: tried where the tied fit leaves more than 4 % of the power unmodelled, the start's height
#: told 1 cm (a vehicle's antenna height is known)
DIRECT_OPTIONS = {
    "speed_sigma": 0.1,
    "element_second_order": True,
    "diffuse": 1,
    "diffuse_above": 0.04,
    "start_height_sigma": 0.01,
}
#: the route the direct drive draws its snapshots from (``benchmarks/bench_rt_direct.py``'s)
DIRECT_NUISANCE = {"diffuse_floor": True}


def direct_table(scenario: str) -> ElevationSigmas | None:
    """The direct fix's told angle sigmas by measured elevation for ``scenario`` (a preset's
    name): the survey shipped in ``data/rt/direct/<scenario>.json`` (its command in the
    record) times :data:`~tunnelkit.design.directsurvey.SURVEY_SCALE`; None for a scene without
    one (the column is then not run)."""
    rec = survey_record(scenario)
    return None if rec is None else surveyed_table(rec)


def direct_scores(scenario: str, n_epochs: int | None, rng: np.random.Generator) -> tuple:
    """One condition-L drive of the direct column: :func:`direct_drive` of ``scenario``'s
    ray-traced route (:data:`DIRECT_NUISANCE`) with :data:`DIRECT_OPTIONS`, the line-of-sight
    column's JAVELIN started at the truth told :data:`~.javelin_traced.LOS_START_M`, told
    :func:`direct_table`; ``n_epochs`` truncates it (None: the whole drive). Returns
    ``({"JAVELIN": metrics, "dead reckoning": metrics}, (epochs without a measurement, epochs))``
    (metrics as :func:`~tunnelkit.simulation.scoring.error_metrics`)."""
    table = direct_table(scenario)
    if table is None:
        raise ValueError(
            f"scenario: {scenario!r} ships no direct fix's table ({survey_path(scenario)})"
        )
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    rng = rng_or_error("rng", rng)
    route = scenario_route(scenario, "exact", "sionna", DIRECT_NUISANCE)
    n_epochs = None if n_epochs is None else min(n_epochs, len(route.trajectory))
    out = direct_drive(
        route, rng, los_design(), None, table, n_epochs=n_epochs, start_sigma=LOS_START_M,
        **DIRECT_OPTIONS,
    )  # fmt: skip
    scores = {
        "JAVELIN": error_metrics(out.estimates["direct"], out.truth),
        "dead reckoning": error_metrics(out.estimates["dead reckoning"], out.truth),
    }
    return scores, (int(out.dropped["direct"]), len(out.truth))


def direct_note(scenario: str) -> str:
    """The direct column's note: what it runs, what it is told, where its table comes from."""
    rec = survey_record(scenario)
    if rec is None:
        raise ValueError(
            f"scenario: {scenario!r} ships no direct fix's table ({survey_path(scenario)})"
        )
    bins = ElevationSigmas.from_dict(rec["table_deg"]).describe()
    o = DIRECT_OPTIONS
    return (
        f"Column '{DIRECT_COLUMN[0]}' (condition L only): at every epoch the line-of-sight "
        "column's JAVELIN predicts with the V2X message and the direct fit "
        "(extraction.direct.fit.direct_fix: every atom of the visibility model tied to one UE position, "
        "one clock bias and one speed, the second-order atoms on the elements that see them, "
        f"{o['diffuse']} diffuse atom tried where the tied fit leaves more than "
        f"{100 * o['diffuse_above']:g} % of the tensor's power unmodelled) starts from its "
        "prediction; the fix goes to the tracker as a line of sight told its azimuth / "
        f"elevation sigmas by its elevation ({bins}, each times {SURVEY_SCALE:g}; "
        f"{rec['source']}), its speed averaged with "
        f"the next message's (told {o['speed_sigma']:g} m/s). The measurement depends on the "
        "track, so the column runs its own drive (design.traceddirect.direct_drive), drawn "
        "from a generator spawned from the trial's: its dead reckoning row is the same JAVELIN "
        "on that drive's own messages, not the other columns'. Started at the true position "
        f"told {LOS_START_M:g} m, its height told {100 * o['start_height_sigma']:g} cm (an "
        "antenna's height is known). Chosen on seed 0 (docs/results/traced-models.md)."
    )
