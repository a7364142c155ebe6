"""The recommendation confirmed on the channel route: what the system achieves decides.

The bound route (:mod:`tunnelkit.design.fastroute`) draws each path's measurement from the
extraction's error model; the channel route synthesises the tensor and runs the extraction. Near
the target the two can disagree: the bound route cannot have the extraction's outliers (a path
merged, a fit in its threshold region), and it reads the ideal channel 1.2-1.5 times
optimistic in error p90 (docs/results/design-answer.md). :func:`confirm_on_channel` re-runs the
candidates the recommendation rests on, on the channel route with the same impairments, runs
and seed:

* the recommended array, and every smaller candidate the bound route left ``"undecided"``
  (its 95 % interval straddling the target);
* with no recommendation, the smallest candidate that is neither not met (on the bound route) nor in error;
* while none of those is met on the channel route, the next larger candidate the bound route did
  not rule out (not met or in error), one at a time (:func:`next_candidate`): a marginal array
  (its channel-route interval straddling the target) then comes with the larger one that meets
  it, not with "none" (28 GHz example at 2 deg: 8 x 8 undecided on the channel route, 20 runs).

Each is judged again from its channel-route error quantile and 95 % interval
(:func:`tunnelkit.design.verdict.judge`, the same rule), and the recommendation is taken from
those rows alone: the smallest candidate met on the channel route, ``route: "channel"`` in its
JSON; the bound route's rows stay in the report beside them (``confirmation`` in the JSON).

Under calibration error the channel route judges the extraction's fits against noise plus the
impairment power it was told about (``RouteOptions.model_error_floor``,
:mod:`tunnelkit.signal_route.judging`: the calibration share of the received power at a 1 %
false-alarm quantile of the array's draw, :func:`~tunnelkit.signal_route.judging.
calibration_floor`, plus the diffuse share; ``model_error_share`` (the expectation) and
``model_error_false_alarm`` in the inputs) and hands the tracker the design's per-path
impairment budget beside the CRLB at the estimate (:mod:`tunnelkit.design.channelbudget`).
Before, the white-noise test alone flagged the fits and a flagged epoch carried no measurement:
28 GHz example, 0.5 deg, the first 10 epochs of one drive (seed 0): 6 of 10 flagged on 4 x 4 and
10 of 10 on 8 x 8, after the re-judge 1 and 0 (the 4 x 4 one an unresolved pair, which stays
flagged); the fits needed 0.01-0.07 of the closed form. The settled median error on the channel
route went from 0.42 / 0.97 m (4 x 4 / 8 x 8, 2 runs) to 1.8 / 0.49 cm (20 runs; p90 10.3 / 3.6
cm), the bound route's 1.1 / 0.42 cm (p90 8.3 / 2.6 cm): both recommend 8 x 8 (docs/results/
design-answer.md).

At 2 deg the channel route's 8 x 8 had a tail (p90 65 cm, 4 runs) the bound route did not
(8.3 cm): on the drives that carried it the calibration error's quadratic phase drove every
path's unresolved curvature to 3-7 m the same way every epoch, and seen from the reference
antenna (the URA's corner) that moved every direction by 5-8 mrad (``RouteOptions.
centroid_unresolved``: such paths are reported far-field from the array's centroid). After
it, 10 runs: error p90 8.9 cm [4.3, 15.5] (seed 0, undecided; bound route 9.2 cm) and 5.9 cm
[4.1, 8.5] (seed 8675309, met; bound route 5.7 cm).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

from .._parallel import TRIAL_TIMEOUT_S
from .._validate import instance, integer, positive, record, sequence
from ..budget import check_bytes
from ..montecarlo import RUN_BYTES
from .report import DesignReport
from .setup import DesignSetup, parse_array
from .unitsweep import score_row
from .verdict import MIN_RUNS_CI, recommend

__all__ = ["ConfirmedReport", "confirm_on_channel", "confirmation_candidates", "next_candidate"]


@dataclass
class ConfirmedReport(DesignReport):
    """A :class:`~tunnelkit.design.report.DesignReport` whose recommendation the channel route
    decided: ``confirmation`` the channel route's rows, ``bound_recommendation`` the bound
    route's recommendation it replaces."""

    confirmation: list = field(default_factory=list)
    bound_recommendation: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        record(self, may_be_empty=("warnings", "confirmation"))

    def to_json(self) -> dict:
        out = super().to_json()
        out["confirmation"] = {
            "route": "channel",
            "arrays": [r.to_json() for r in self.confirmation],
            "bound_recommendation": dict(self.bound_recommendation),
        }
        return out

    def to_table(self) -> str:
        lines = [super().to_table(), "confirmed on the channel route (synthesis and extraction):"]
        for r in self.confirmation:
            ci = r.error_p90_ci95_m
            cis = f"[{100 * ci[0]:.2f}, {100 * ci[1]:.2f}] cm" if ci else "-"
            p90 = "-" if r.error_p90_m is None else f"{100 * r.error_p90_m:.2f} cm"
            lines.append(f"  {r.array:>7s}: error p90 {p90} {cis}, {r.status}")
        b = self.bound_recommendation
        lines.append(f"  the bound route recommended {b.get('array') or 'none'}")
        return "\n".join(lines)


def confirmation_candidates(report: DesignReport) -> list[str]:
    """The arrays :func:`confirm_on_channel` re-runs (module docstring), smallest first."""
    instance("report", report, DesignReport)
    order = sorted(report.rows, key=lambda r: (r.n_elements, r.aperture_diagonal_m))
    rec = report.recommendation.get("array")
    if rec is None:
        open_ = [r.array for r in order if r.status not in ("not met", "error")]
        return open_[:1]
    at = [r.array for r in order].index(rec)
    return [r.array for r in order[:at] if r.status == "undecided"] + [rec]


def next_candidate(report: DesignReport, confirmed) -> str | None:
    """The array :func:`confirm_on_channel` runs next when none of ``confirmed`` (the labels
    already re-run) is met on the channel route: the smallest candidate of ``report`` larger than
    all of them that the bound route did not call not met or in error; ``None`` when none is
    left."""
    instance("report", report, DesignReport)
    done = sequence("confirmed", confirmed, empty=True)
    order = sorted(report.rows, key=lambda r: (r.n_elements, r.aperture_diagonal_m))
    labels = [r.array for r in order]
    unknown = [a for a in done if a not in labels]
    if unknown:
        raise ValueError(f"confirmed: {unknown[0]!r} is not a candidate of the report")
    start = max((labels.index(a) for a in done), default=-1) + 1
    rest = [r.array for r in order[start:] if r.status not in ("not met", "error")]
    return rest[0] if rest else None


def confirm_on_channel(
    report: DesignReport,
    setup: DesignSetup,
    *,
    units: int | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float | None = None,
    trial_timeout: float | None = TRIAL_TIMEOUT_S,
    progress: bool = False,
) -> ConfirmedReport:
    """``report`` (a bound-route :func:`~tunnelkit.design.report.design_sweep` with units) with
    its recommendation re-decided on the channel route (module docstring): the candidates of
    :func:`confirmation_candidates`, ``units`` units each (default the report's), its seed,
    impairments, target, share, criterion and epochs; ``workers`` / ``scheduler`` /
    ``timeout`` / ``trial_timeout`` as :func:`~tunnelkit.design.montecarlo.sweep_montecarlo`'s."""
    from ..signal_route.judging import FLOOR_FALSE_ALARM, impairment_share
    from .achievable import DesignImpairments
    from .montecarlo import sweep_montecarlo

    instance("report", report, DesignReport)
    instance("setup", setup, DesignSetup)
    s = report.settings
    if s.get("mode") != "bound" or not s.get("units"):
        raise ValueError(
            "report: expected a bound-route sweep with units (mode 'bound', units > 0)"
        )
    units = s["units"] if units is None else integer("units", units, minimum=1)
    trial_timeout = positive("trial_timeout", trial_timeout, none=True)
    check_bytes("units", units * RUN_BYTES, f"{units} units' calibration draws")
    d = s["drives_per_unit"]
    labels = confirmation_candidates(report)
    by = {r.array: r for r in report.rows}
    imp = DesignImpairments(**s["impairments"])
    rows, warnings = [], list(report.warnings)
    sp = s["spacing_wl"]  # per array (the sweep's) or one value (the command line's)
    sp = sp if isinstance(sp, list | tuple) else [sp] * len(s["arrays"])
    all_specs = [parse_array(a, w) for a, w in zip(s["arrays"], sp, strict=True)]

    def run(labels):
        res = sweep_montecarlo(
            setup,
            [x for x in all_specs if x.label in labels],
            units * d,
            s["seed"],
            mode="channel",
            impairments=None if imp.ideal else imp,
            workers=workers,
            scheduler=scheduler,
            timeout=timeout,
            trial_timeout=trial_timeout,
            progress=progress,
            n_epochs=s["n_epochs"],
            **({"start_sigma": s["start_sigma_m"]} if "start_sigma_m" in s else {}),
            dead_reckoning=bool(s.get("dead_reckoning", False)),
            drives_per_unit=d,
        )
        for a in labels:
            row = copy.deepcopy(by[a])
            # the image channel's channel route gives no bound or prediction over the drive
            # (no error model; score_row fills the traced route's prediction)
            row.pcrlb_rms_m = row.hybrid_bound_rms_m = row.rmse_over_pcrlb = None
            row.rmse_over_hybrid_bound = row.unit_rmse_over_pcrlb_min = None
            row.predicted_drive_rms_m = None
            row.rmse_over_predicted_drive = None
            score_row(
                row,
                res[a],
                s["criterion"],
                s["target"],
                s["share"],
                settle=s["settle_s"],
                required=s["required_yield"],
            )
            rows.append(row)

    if labels:
        run(labels)
    rec = recommend(rows, s["target"], s["share"], units, s["required_yield"])
    # none met: the next larger candidate, one at a time (module docstring)
    while rows and rec.get("array") is None and units >= MIN_RUNS_CI:
        nxt = next_candidate(report, [r.array for r in rows])
        if nxt is None:
            break
        run([nxt])
        rec = recommend(rows, s["target"], s["share"], units, s["required_yield"])
    rec["route"] = "channel"
    if not rows:
        rec["reason"] = "no candidate left to confirm on the channel route"
    bound_rec = dict(report.recommendation, route="bound")
    if rec.get("array") != bound_rec.get("array"):
        warnings.append(
            f"the channel route does not confirm the bound route's recommendation "
            f"({bound_rec.get('array') or 'none'} -> {rec.get('array') or 'none'})"
        )
    if units < MIN_RUNS_CI:
        warnings.append(f"confirmation with {units} units: every verdict is undecided")
    # the expectation of the floor the channel route's fit test allows for (0: the white-noise
    # test alone); the test takes the calibration part at its draw's false-alarm quantile
    share = 0.0 if imp.ideal else impairment_share(imp.channel_impairments())
    settings = dict(
        s,
        confirm_route="channel",
        confirm_units=units,
        model_error_share=share,
        model_error_false_alarm=FLOOR_FALSE_ALARM,
        # the channel route's tracker on the ray-traced channel: its default, chosen per array
        **({"confirm_traced_tracker": "auto"} if setup.channel == "sionna" else {}),
    )
    return ConfirmedReport(report.scenario, report.rows, rec, settings, warnings, rows, bound_rec)
