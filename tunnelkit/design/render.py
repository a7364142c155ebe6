"""A design sweep's records written out: a row and a report as JSON, the report as a fixed-width
text table (what ``tunnelkit design`` prints), and :func:`over_target`, the stretches of the route
above the target in words. The records' ``to_json`` and ``to_table`` call it.
"""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, positive

#: exported: the stretches in words; the rest are the records' methods' bodies, on records checked
#: at construction (:mod:`tunnelkit.design.records`)
__all__ = ["over_target"]


def _fin(v):
    return float(v) if v is not None and np.isfinite(v) else None


def _fins(v):
    return None if v is None else [_fin(x) for x in np.asarray(v, float).ravel()]


#: a row's JSON scalar keys, in order (besides the fields handled apart in :func:`row_json`)
_SCALARS = (
    "srnf_valid_share", "peb_median_m", "peb_p90_m", "predicted_median_m", "predicted_p90_m",
    "met_share", "error_median_m", "error_p90_m", "error_p90_route_m", "rmse_m",
    "unit_yield", "pcrlb_rms_m", "hybrid_bound_rms_m", "rmse_over_pcrlb",
    "rmse_over_hybrid_bound", "unit_rmse_over_pcrlb_min", "predicted_drive_rms_m",
    "rmse_over_predicted_drive", "rmse_over_predicted",
)  # fmt: skip


def row_json(row) -> dict:
    """The row as JSON: ``array, n_elements, aperture_diagonal_m, status, reason, gaps`` (the
    epochs where the array cannot fix the position, named; empty when none), the
    scalars of :class:`~tunnelkit.design.records.DesignRow` (``null`` when not computed or not finite),
    ``error_p90_ci95_m, rmse_ci95_m, unit_yield_ci95, unit_p90_m``, the counts ``runs,
    units, drives_per_unit`` and ``per_epoch {x_m, peb_m, predicted_m,
    error_median_m}``; on the ray-traced channel's route also ``error_model`` (the
    tracker's measurement-noise model, :func:`tunnelkit.design.traced.error_model_summary`,
    with ``told_sigmas`` the long-run sigmas its tracker is told); with dead reckoning
    measured, ``dead_reckoning_p90_m`` and ``dead_reckoning_rmse_m`` (the same drives,
    every measurement dropped); with units, each unit's ``unit_rmse_m`` (and
    ``dead_reckoning_unit_rmse_m``)."""
    out = {
        "array": row.array,
        "n_elements": int(row.n_elements),
        "aperture_diagonal_m": _fin(row.aperture_diagonal_m),
        "status": row.status,
        "reason": row.reason,
        "gaps": row.gaps,
        "srnf_valid_share_by_surface": {
            k: _fin(v) for k, v in row.srnf_valid_share_by_surface.items()
        },
        **{k: _fin(getattr(row, k)) for k in _SCALARS},
        "error_p90_ci95_m": _fins(row.error_p90_ci95_m),
        "rmse_ci95_m": _fins(row.rmse_ci95_m),
        "unit_yield_ci95": _fins(row.unit_yield_ci95),
        "unit_p90_m": _fins(row.unit_p90_m),
        "unit_rmse_m": _fins(row.unit_rmse_m),
        "runs": int(row.runs),
        "units": int(row.units),
        "drives_per_unit": int(row.drives_per_unit),
        "per_epoch": {
            "x_m": _fins(row.x_m),
            "peb_m": _fins(row.peb_m),
            "predicted_m": _fins(row.predicted_m),
            "error_median_m": _fins(row.error_median_epoch_m),
        },
    }
    if row.error_model is not None:
        out["error_model"] = dict(row.error_model)
    if row.dead_reckoning_p90_m is not None:
        out["dead_reckoning_p90_m"] = _fin(row.dead_reckoning_p90_m)
        out["dead_reckoning_rmse_m"] = _fin(row.dead_reckoning_rmse_m)
        out["dead_reckoning_unit_rmse_m"] = _fins(row.dead_reckoning_unit_rmse_m)
    return out


def paired_ratios(rows) -> dict:
    """What pairing over units compares in a sweep (its rows share their drives unit by unit),
    by array: ``radio_gain`` (dead reckoning's RMSE over the tracker's) and
    ``against_smaller`` (the array's RMSE over the next smaller array's, on their common
    units), each ``{"against", "units", "ratio", "ci95"}`` from
    :func:`~tunnelkit.design.intervals.paired_rmse_ratio` (``ci95`` ``None`` below two units or
    with a drive lost)."""
    from .intervals import paired_rmse_ratio

    def entry(against, num, den):
        n = min(len(num), len(den))
        ratio, ci = paired_rmse_ratio(num[:n], den[:n])
        return {"against": against, "units": n, "ratio": _fin(ratio), "ci95": _fins(ci)}

    out, prev = {}, None
    with_units = (r for r in rows if r.unit_rmse_m is not None)
    for r in sorted(with_units, key=lambda r: (r.n_elements, r.aperture_diagonal_m)):
        e = out.setdefault(r.array, {})
        if r.dead_reckoning_unit_rmse_m is not None:
            e["radio_gain"] = entry("dead reckoning", r.dead_reckoning_unit_rmse_m, r.unit_rmse_m)
        if prev is not None:
            e["against_smaller"] = entry(prev.array, r.unit_rmse_m, prev.unit_rmse_m)
        prev = r
    return out


def report_json(report) -> dict:
    """The report as JSON: the scenario, every input, the criterion, the rows, the recommendation
    and the warnings."""
    return {
        "scenario": report.scenario,
        "inputs": dict(report.settings),
        "criterion": report.criterion,
        "arrays": [row_json(r) for r in report.rows],
        "paired": paired_ratios(report.rows),
        "recommendation": dict(report.recommendation),
        "warnings": list(report.warnings),
    }


def report_table(report) -> str:
    """A fixed-width text table; the criterion above it, recommendation and warnings below."""
    s = report.settings
    imp = s["impairments"]
    q = f"p{100 * s['share']:g}"
    st = s["settle_s"]
    lines = [
        f"Array design for {report.scenario}: fc {s['fc'] / 1e9:g} GHz, bandwidth "
        f"{s['bandwidth'] / 1e6:g} MHz ({s['n_rb']} RB at {s['scs'] / 1e3:g} kHz); target {s['target']:g} m on {100 * s['share']:g} % "
        f"of the settled route (the epochs {st:g} s after the start, --settle), required "
        f"unit yield {100 * s['required_yield']:g} %",
        f"impairments ({s.get('impairments_preset', 'custom')}): phase "
        f"{imp['phase_error_deg']:g} deg, gain {imp['gain_error_db']:g} "
        f"dB, spatial wideband {'on' if imp['spatial_wideband'] else 'off'}, diffuse share "
        f"{imp['dmc_share']:.10g}; Monte-Carlo: units of {s['drives_per_unit']} drives "
        f"({s['mode']} route, {s['units']} units first, up to {s['max_units']}), seed "
        f"{s['seed']}"
        + (f", entry fix {s['start_sigma_m']:g} m per axis" if "start_sigma_m" in s else ""),
        f"criterion: {_CRITERION_TEXT[s['criterion']]}",
        f"{'array':>7s} {'M':>5s} {'SR-NF ok':>9s} {'PEB ' + q:>9s} {'pred ' + q:>9s} "
        f"{'units':>5s} {'unit yield [95% CI]':>20s} {'err ' + q:>9s} {'95% CI':>21s} "
        f"{'route ' + q:>9s} {'RMSE':>9s} {'PCRLB':>9s} {'hybrid':>9s}  status",
    ]
    for r in report.rows:
        if r.peb_median_m is None:  # nothing computed: the reason only
            lines.append(f"{r.array:>7s} {r.n_elements:5d}  {r.reason}")
            continue
        ci = r.error_p90_ci95_m
        cis = f"[{_cm(ci[0]).strip()}, {_cm(ci[1]).strip()}]" if ci else "-"
        yc = r.unit_yield_ci95
        ys = f"{100 * r.unit_yield:.0f}% [{100 * yc[0]:.0f}, {100 * yc[1]:.0f}]" if yc else "-"
        lines.append(
            f"{r.array:>7s} {r.n_elements:5d} {100 * r.srnf_valid_share:8.1f}% "
            f"{_cm(r.peb_p90_m)} {_cm(r.predicted_p90_m)} {r.units:5d} {ys:>20s} "
            f"{_cm(r.error_p90_m)} {cis:>21s} {_cm(r.error_p90_route_m)} {_cm(r.rmse_m)} "
            f"{_cm(r.pcrlb_rms_m)} {_cm(r.hybrid_bound_rms_m)}  {r.status}"
        )
    rec = report.recommendation
    lines.append(f"recommendation ({rec['basis']}): {rec['array'] or 'none'} — {rec['reason']}")
    lines.append(
        f"Bounds: PEB the ideal snapshot position error bound (of one epoch's fix; the "
        f"tracker fuses epochs and may go below it, and a bound's p90 bounds no error's p90); "
        f"the tracker's lower bounds (of trackers nearly unbiased for the fixed route), checked "
        f"by Monte-Carlo: PCRLB every unit's posterior CRLB over the drive (settled RMS), hybrid the same pooled over units, the "
        f"calibration a fixed unknown per unit (both beside RMSE). Prediction (not a bound, decides nothing): pred, "
        f"the first-order RMS error of the tracker's fix under the impairments. err: "
        f"Monte-Carlo 2-D error, {q} its {s['share']:g}-quantile pooled over units on the "
        f"settled route (CI: Woodruff's interval over units, a unit's drives one cluster; "
        f"information only: at 20 units it covered 83-98 %, docs/results/design-units.md), route {q} on the whole route; unit "
        f"yield: the share of units whose own {q} meets the target (Wilson interval)."
    )
    lines.append(_CHANNEL_TEXT[s.get("channel", "image")])
    paired = paired_ratios(report.rows)
    for r in report.rows:
        if r.srnf_valid_share_by_surface:
            per = ", ".join(
                f"{k} {100 * v:.0f} %" for k, v in r.srnf_valid_share_by_surface.items()
            )
            lines.append(f"  SR-NF valid, {r.array}: {per}")
        for what, y in (
            ("predicted error", r.predicted_m),
            ("median error", r.error_median_epoch_m),
        ):
            if y is not None and r.x_m is not None:
                spans = over_target(r.x_m[: len(y)], y, s["target"])
                if spans:
                    lines.append(f"  {r.array}: {what} above the target at x = {spans}")
        em = r.error_model
        los = em.get("los") if em else None
        direct = em.get("direct") if em else None
        if direct:
            tab, sv = direct["told_deg"], direct["survey"]
            saz, sel = tab["sigma_azimuth"], tab["sigma_elevation"]
            told = (
                f"told a constant azimuth {saz[0]:.3g} deg, elevation {sel[0]:.3g} deg (no "
                "survey of this route ships)"
                if sv is None
                else f"told its angle sigmas by its measured elevation, a survey of {sv['runs']} "
                f"drives of seed {sv['seed']} ({sv['bins']} bins) times {sv['scale']:g}: azimuth "
                f"{min(saz):.2g}-{max(saz):.3g} deg, elevation {min(sel):.2g}-{max(sel):.3g} deg"
            )
            lines.append(
                f"  {r.array}: traced route, the direct fit's line of sight (tracker direct: every "
                f"atom tied to one UE position, started from the track's prediction), {told}"
            )
        elif los:
            tab = los["table_deg"]
            saz, sel = tab["sigma_azimuth"], tab["sigma_elevation"]
            lines.append(
                f"  {r.array}: traced route, the line of sight alone (tracker los), told "
                f"its angle sigmas by its measured elevation from a survey of {los['runs']} drives "
                f"of seed {los['seed']} ({los['epochs']} epochs, {los['bins']} bins): azimuth "
                f"{min(saz):.2g}-{max(saz):.3g} deg, elevation {min(sel):.2g}-{max(sel):.3g} deg"
            )
        elif em and em.get("kind") == "traced-measured":
            sg = em["sigmas"]
            lines.append(
                f"  {r.array}: traced route, noise measured on seed {em['seed']} "
                f"({em['runs']} drives): {sg['phi_deg']:.3g} / {sg['psi_deg']:.3g} deg, "
                f"{sg['kappa_m']:.3g} m, {sg['delta_d_m']:.3g} m; geometry pre-filter"
            )
            tg = em.get("told_sigmas")
            if tg:
                lines.append(
                    f"  {r.array}: the tracker is told their long-run value "
                    f"{tg['phi_deg']:.3g} / {tg['psi_deg']:.3g} deg, {tg['kappa_m']:.3g} m, "
                    f"{tg['delta_d_m']:.3g} m"
                )
        by = em.get("chosen_by_predicted_rms_m") if em else None
        if by:
            told = ", ".join(f"{k} {v:.3g} m" for k, v in by.items())
            lines.append(
                f"  {r.array}: --traced-tracker auto chose {em['tracker']}: its told model "
                f"predicts the smaller RMS error over the settled route ({told})"
                + (f"; no line-of-sight survey: {em['auto_fallback']}" if "auto_fallback" in em
                   else "")
            )  # fmt: skip
        if em and em.get("kind") == "traced-measured" and r.predicted_drive_rms_m is not None:
            ratio = r.rmse_over_predicted_drive
            lines.append(
                f"  {r.array}: posterior CRLB of the sigmas the tracker is told (settled "
                f"RMS; a prediction, the traced errors are not Gaussian) "
                f"{r.predicted_drive_rms_m:.3g} m"
                + ("" if ratio is None else f", tracker RMSE / it {ratio:.3g}")
            )
        pair = paired.get(r.array, {})
        if r.dead_reckoning_p90_m is not None:
            gain = None
            if r.rmse_m is not None and r.dead_reckoning_rmse_m:
                gain = 1 - r.rmse_m / r.dead_reckoning_rmse_m
            lines.append(
                f"  {r.array}: dead reckoning on the same drives (every measurement dropped): "
                f"{q} {r.dead_reckoning_p90_m:.3g} m, RMSE {r.dead_reckoning_rmse_m:.3g} m"
                + (
                    ""
                    if gain is None
                    else f"; the radio's gain in RMSE {100 * gain:.2g} % (dead reckoning's RMSE "
                    f"over the tracker's {_ratio_text(pair.get('radio_gain'))})"
                )
            )
        if "against_smaller" in pair:
            p = pair["against_smaller"]
            lines.append(f"  {r.array}: its RMSE over the {p['against']}'s on the same drives "
                         f"{_ratio_text(p)}")  # fmt: skip
    lines.extend(f"warning: {w}" for w in report.warnings)
    return "\n".join(lines)


def over_target(x, y, target: float) -> str:
    """The stretches of the route where ``y > target`` (non-finite counts), as text:
    ``"45.0..38.1 m, 12.5 m"`` in route order; ``""`` when none."""
    x = finite_array("x", x, ndim=1)
    try:
        y = np.asarray(y, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"y: expected real numbers (NaN allowed), got {type(y).__name__}") from None
    if y.shape != x.shape:
        raise ValueError(f"y: expected one value per x, shape {x.shape}, got {y.shape}")
    target = positive("target", target)
    bad = ~(y <= target)
    out, i = [], 0
    while i < bad.size:
        if not bad[i]:
            i += 1
            continue
        j = i
        while j + 1 < bad.size and bad[j + 1]:
            j += 1
        out.append(f"{x[i]:.1f} m" if i == j else f"{x[i]:.1f}..{x[j]:.1f} m")
        i = j + 1
    return ", ".join(out)


_CHANNEL_TEXT = {
    "image": (
        "channel: the image method's eq. 1 decided (specular paths only). On the paper tunnel "
        "the ray-traced channel (diffuse and second-order paths) gave errors of metres where "
        "this one gives millimetres (notebook 08, section 9): read the table as optimistic."
    ),
    "sionna": "channel: the ray-traced channel decided (Sionna RT, the array's measured errors).",
}

_CRITERION_TEXT = {
    "achievable": (
        "achievable (the design's tracker models each reflection's wavefront on its virtual UE; "
        "SR-NF validity is information, not a gate)"
    ),
    "srnf": ("srnf (an eq. 51 estimator: an epoch counts only where SR-NF holds on every surface)"),
}


def _ratio_text(p) -> str:
    """``"2.13x [1.71, 2.65] (95 %, paired over 6 units)"``; ``"-"`` when not measured."""
    if p is None or p["ratio"] is None:
        return "-"
    ci = p["ci95"]
    return f"{p['ratio']:.3g}x" + (
        f" [{ci[0]:.3g}, {ci[1]:.3g}] (95 %, paired over {p['units']} units)" if ci else
        " (one unit: no interval)" if p["units"] < 2 else " (a drive lost: no interval)"
    )  # fmt: skip


def _cm(v) -> str:
    if v is None:
        return "        -"
    return f"{100 * v:7.3g}cm" if np.isfinite(v) else "      inf"
