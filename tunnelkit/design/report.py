"""A design sweep and its recommendation: one row per candidate array, decided by the share of
manufactured units that meet the target.

:func:`design_sweep` places every candidate, computes its ideal PEB and predicted error, runs
the Monte-Carlo over manufactured units (:mod:`tunnelkit.design.unitsweep`) and gives the
verdict; :class:`DesignReport` holds the rows, the recommendation, every input and the warnings
(JSON or a text table). The explorer's quick look is :mod:`tunnelkit.design.explore`'s.
How it works, step by step: docs/internals/design.md.
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from .._parallel import TRIAL_TIMEOUT_S, parallel_options
from .._physical import start_spread
from .._validate import boolean, choice, integer, nonnegative, positive, probability, sequence
from ..budget import check_bytes, check_elements
from ..settling import SETTLE_S
from .achievable import DesignImpairments, predicted_error
from .bounds import route_bounds, route_geometry
from .impairments import (
    CALIBRATED_GAIN_ERROR_DB,
    CALIBRATED_PHASE_ERROR_DEG,
    MEASURED_DIFFUSE_SHARE,
    WIDEBAND_CYCLES,
    design_impairments,
    implausible_impairments,
    wideband_cycles,
)
from .records import DesignReport, DesignRow
from .setup import ArraySpec, DesignSetup, parse_array
from .trackerfix import MODES, START_SIGMA_M
from .verdict import (
    CRITERIA,
    DRIVES_PER_UNIT,
    MAX_UNITS,
    MIN_RUNS_CI,
    REQUIRED_YIELD,
    counted_epochs,
    gate,
    judge,
    recommend,
    share_quantile,
)

__all__ = ["DesignReport", "DesignRow", "design_sweep"]


# --- the sweep ------------------------------------------------------------------------------


def _impairment_fields(imp: DesignImpairments) -> dict:
    """The impairment settings as plain values (the report's inputs)."""
    return {k: (v if isinstance(v, (bool, str)) else float(v)) for k, v in asdict(imp).items()}


def _bound_row(setup, spec, impairments, criterion, target, share, eps_phi, epochs, settle):
    """The bound part of one candidate's row (placement checked first)."""
    row = DesignRow(spec.label, spec.n_elements, spec.aperture(setup.fc))
    try:
        setup.arrays(spec)
        g = route_geometry(setup, spec, epochs=epochs)
        sr = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g, peb=False)
        r = predicted_error(setup, spec, impairments, geometry=g)
    except (ValueError, ArithmeticError) as exc:
        row.reason = str(exc)
        return row
    x, peb, pred = r.x, r.peb, r.predicted
    # an error larger than the tunnel is no fix: that epoch's prediction is a gap (infinite)
    lo, hi = setup.tunnel.x_range
    extent = float(np.linalg.norm([hi - lo, setup.tunnel.width, setup.tunnel.height]))
    beyond = np.isfinite(pred) & (pred > extent)
    pred = np.where(beyond, np.inf, pred)
    valid = r.valid & ~beyond
    reasons = [r.reason] if not np.all(r.valid) else []
    if beyond.any():
        reasons.append(f"predicted error beyond the tunnel's extent ({extent:.4g} m) at "
                       f"{int(beyond.sum())} of {beyond.size} epochs: no fix there")  # fmt: skip
    why = "; ".join(reasons)
    if not np.any(valid):
        row.reason = f"no epoch of the route has a defined prediction: {why}"
        return row
    # an epoch where the array cannot fix the position is a gap of that epoch (infinite:
    # counted as missed), named in ``gaps``; the other epochs stand
    row.gaps = why
    t = setup.trajectory.t[: len(x)]
    k = counted_epochs(t, settle)
    row.x_m, row.peb_m, row.predicted_m = x, peb, pred
    row.srnf_valid_share = float(sr.srnf_valid.mean())
    row.srnf_valid_share_by_surface = sr.surface_validity()
    gated = gate(pred, sr.srnf_valid, criterion)[k]
    row.peb_median_m = float(np.median(peb[k]))
    row.peb_p90_m = share_quantile(peb[k], share)
    row.predicted_median_m = float(np.median(pred[k]))
    row.predicted_p90_m = share_quantile(pred[k], share)
    row.met_share = float(np.mean(gated <= target))
    row.srnf_valid = sr.srnf_valid
    row.status, row.reason = judge(target, share=share)
    return row


def design_sweep(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    criterion: str = "achievable",
    impairments="calibrated",
    eps_phi: float = 0.15,
    units: int = 0,
    drives_per_unit: int = DRIVES_PER_UNIT,
    required_yield: float = REQUIRED_YIELD,
    max_units: int = MAX_UNITS,
    settle: float = SETTLE_S,
    seed: int = 0,
    mode: str = "bound",
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    n_epochs: int | None = None,
    timeout: float | None = None,
    trial_timeout: float | None = TRIAL_TIMEOUT_S,
    start_sigma: float = START_SIGMA_M,
    dead_reckoning: bool = False,
    traced_tracker: str | None = None,
) -> DesignReport:
    """Every candidate of ``arrays`` evaluated and judged (docs/internals).

    ``target`` [m] on ``share`` of the settled route (the epochs at least ``settle`` [s] after
    the start, default :data:`~tunnelkit.settling.SETTLE_S`); ``criterion`` ``"achievable"``
    (default, the design's VUE-curvature tracker) or ``"srnf"`` (an eq. 51 route: SR-NF a
    gate); ``impairments``: ``"calibrated"`` (default: a calibrated manufactured array in a
    tunnel's measured diffuse power, :mod:`tunnelkit.design.impairments`), ``"ideal"``, a
    ``design.DesignImpairments`` or a dict of its fields. The Monte-Carlo runs manufactured units (one calibration draw each) of
    ``drives_per_unit`` drives on the ``mode`` route (``"bound"``: drawn from the error model;
    ``"channel"``: synthesis and extraction), seeded by ``seed``: ``units`` in the first batch
    (0: bounds and predictions only), then, for every array still undecided, as many again
    until its unit yield's 95 % interval lies on one side of ``required_yield`` or
    ``max_units`` is reached (the sequential rule). ``workers`` / ``scheduler`` / ``timeout`` /
    ``trial_timeout`` go to each batch's task set; ``n_epochs`` truncates the route;
    ``start_sigma`` [m] the entry fix's standard deviation per axis (the tracker's start and the
    prior of the bounds over the drive); ``dead_reckoning``: each drive also run with every
    measurement dropped, the rows' ``dead_reckoning_*`` (what the radio adds); ``traced_tracker`` the ray-traced channel's tracker (``"auto"``, its default,
    ``"los"``, ``"paths"`` or ``"direct"``: :data:`tunnelkit.design.tracedtracker.TRACED_TRACKERS`). An array that does not
    fit, or whose bound or Monte-Carlo is undefined, is a row with status ``"error"`` and the
    reason; the sweep goes on."""
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    if isinstance(arrays, (str, ArraySpec)):
        arrays = [arrays]
    specs = list(dict.fromkeys(parse_array(a) for a in sequence("arrays", arrays, empty=True)))
    if not specs or len({s.label for s in specs}) < len(specs):  # rows and results go by label
        raise ValueError("arrays: give candidate arrays, at most one spacing per size")
    timeout = positive("timeout", timeout, none=True)
    trial_timeout = positive("trial_timeout", trial_timeout, none=True)
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    if share == 0:
        raise ValueError("share: expected a share in (0, 1], got 0")
    criterion = choice("criterion", criterion, CRITERIA)
    mode = choice("mode", mode, MODES)
    eps_phi = positive("eps_phi", eps_phi)
    units = integer("units", units, minimum=0)
    drives_per_unit = integer("drives_per_unit", drives_per_unit, minimum=1, maximum=100)
    required_yield = probability("required_yield", required_yield)
    max_units = integer("max_units", max_units, minimum=1)
    if units > max_units:
        raise ValueError(
            f"units: the first batch ({units} units) is larger than max_units ({max_units}); "
            "raise max_units (--max-units) or give fewer units"
        )
    settle = nonnegative("settle", settle)
    seed = integer("seed", seed, minimum=0)
    start_sigma = start_spread("start_sigma", start_sigma)
    dead_reckoning = boolean("dead_reckoning", dead_reckoning)
    if traced_tracker is None:  # the default: chosen per array on the traced channel's route
        traced_tracker = "auto" if (mode, setup.channel) == ("channel", "sionna") else "paths"
    elif traced_tracker != "paths":  # the names load when another is asked for
        from .tracedtracker import checked_tracker

        traced_tracker = checked_tracker(traced_tracker, mode, setup.channel)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1, maximum=len(setup.trajectory))
    workers, scheduler = parallel_options(workers, scheduler)
    traced_array = setup.channel != "image" and impairments == "calibrated"
    if traced_array:  # the traced route's tracker is told errors measured on an ideal array
        impairments = "ideal"
    imp = design_impairments(impairments, setup, specs)
    fields = _impairment_fields(imp)
    T = len(setup.trajectory)
    T = T if n_epochs is None else n_epochs
    counted_epochs(setup.trajectory.t[:T], settle)  # a settle window that leaves an epoch
    if units:
        # the largest array's drives at the cap: what one batch's results may hold at most
        check_bytes(
            "max_units",
            8 * (2 if dead_reckoning else 1) * len(specs) * max_units * drives_per_unit * T,
            f"{len(specs)} arrays x {max_units} units x {drives_per_unit} drives x {T} epochs "
            "of errors",
        )
    if mode == "channel" and units:
        # each drive synthesises the largest candidate's tensor and a noise draw of its size:
        # the band's tone count is refused here, before any bound is computed
        cfg, big = setup.config, max(s.n_elements for s in specs)
        check_elements(
            "bandwidth",
            2 * big * cfg.n_tones * cfg.n_symbols,
            16,
            f"a {big} x {cfg.n_tones} tones x {cfg.n_symbols} symbols channel tensor and its noise "
            f"at bandwidth = {cfg.bandwidth:g} Hz",
        )
    epochs = None if n_epochs is None or n_epochs >= len(setup.trajectory) else np.arange(n_epochs)
    rows = [
        _bound_row(setup, s, imp, criterion, target, share, eps_phi, epochs, settle) for s in specs
    ]
    warnings = [f"{r.array}: {r.reason}" for r in rows if r.status == "error"]
    warnings += [f"{r.array}: {r.gaps}" for r in rows if r.gaps]
    todo = [s for s, r in zip(specs, rows) if r.status == "bound only"]
    if units and todo:
        from .unitsweep import run_units, sweep_options  # the Monte-Carlo by units, when asked for

        kw = sweep_options(imp, mode, workers, scheduler, timeout, progress, n_epochs, start_sigma,
                           dead_reckoning, drives_per_unit, traced_tracker, trial_timeout)  # fmt: skip
        judged = {"settle": settle, "required": required_yield, "cap": max_units}
        run_units(setup, rows, todo, units, max_units, seed, kw, warnings,
                  (criterion, target, share), judged)  # fmt: skip
    if units == 0:
        warnings.append("no Monte-Carlo (units 0): bounds and predictions only, no recommendation")
    elif units < MIN_RUNS_CI:
        warnings.append(
            f"units {units}: fewer than {MIN_RUNS_CI} units in the first batch; every array "
            "gets more units until its yield is decided or the cap is reached"
        )
    capped = [r.array for r in rows if r.status == "undecided" and r.units >= max_units]
    if capped:
        warnings.append(
            f"{', '.join(capped)}: the unit yield's interval still straddles the required "
            f"{100 * required_yield:g} % at the cap of {max_units} units (--max-units)"
        )
    reused = sorted(
        r.array
        for r in rows
        if r.error_model and r.error_model.get("seed") == seed and mode == "channel"
    )
    if units and reused:
        warnings.append(
            f"{', '.join(reused)}: the traced route's measurement noise was measured on this "
            f"seed's first drives (seed {seed}); report the sweep on another seed"
        )
    if traced_array:
        warnings.append(
            "impairments: the ray-traced channel carries its own diffuse and second-order "
            "power; the array on it is ideal (no calibration error: the traced route's tracker "
            "is told errors measured on an ideal array)"
        )
    warnings += _plausibility(setup, specs, target, imp)
    if criterion == "srnf" and units:
        warnings.append(
            "criterion srnf: the Monte-Carlo tracker models the VUE curvature; the SR-NF gate "
            "stands for an eq. 51 estimator"
        )
    settings = {
        "scenario": setup.name,
        "arrays": [s.label for s in specs],
        "spacing_wl": [s.spacing_wl for s in specs],
        "fc": setup.fc,
        "bandwidth": float(setup.config.bandwidth),
        "scs": float(setup.config.scs),
        "n_rb": int(setup.config.n_rb),
        "target": target,
        "share": share,
        "settle_s": settle,
        "criterion": criterion,
        "impairments": fields,
        "impairments_preset": impairments if isinstance(impairments, str) else "custom",
        "eps_phi": eps_phi,
        "units": units,
        "drives_per_unit": drives_per_unit,
        "required_yield": required_yield,
        "max_units": max_units,
        "seed": seed,
        "mode": mode,
        "n_epochs": n_epochs,
        "min_units_ci": MIN_RUNS_CI,
        "workers": workers,
        "scheduler": scheduler,
        "timeout_s": timeout,
    }
    if setup.channel != "image":  # (the image channel's JSON as before; a bound sweep: no tracker)
        settings.update(channel=setup.channel, traced_tracker={"channel": traced_tracker}.get(mode))
    if start_sigma != START_SIGMA_M:  # (the default's JSON as before)
        settings["start_sigma_m"] = start_sigma
    if dead_reckoning:
        settings["dead_reckoning"] = True
    usable = [r for r in rows if r.status != "error"]
    rec = recommend(usable, target, share, units, required_yield)
    return DesignReport(setup.name, rows, rec, settings, warnings)


#: road-tunnel cross-sections beyond these are valid inputs but not road tunnels (a value in cm
#: for m, say): the report warns
PLAUSIBLE_WIDTH_M, PLAUSIBLE_HEIGHT_M = 40.0, 15.0
#: NR FR1 (up to 7.125 GHz) and its SRS subcarrier spacings [Hz] (TS 38.211, numerologies 0-2)
FR1_MAX_HZ, FR1_SCS_HZ = 7.125e9, (15e3, 30e3, 60e3)


def _plausibility(setup, specs, target: float, imp) -> list[str]:
    """Warnings for valid but implausible inputs: a cross-section no road tunnel has, a target
    no narrower than the tunnel, and the ideal array (the optimistic case) said as such."""
    out = []
    w, h = float(setup.tunnel.width), float(setup.tunnel.height)
    if w > PLAUSIBLE_WIDTH_M or h > PLAUSIBLE_HEIGHT_M:
        out.append(
            f"tunnel: {w:g} m x {h:g} m is wider or higher than a road tunnel "
            f"({PLAUSIBLE_WIDTH_M:g} x {PLAUSIBLE_HEIGHT_M:g} m at most); a length in cm?"
        )
    if target >= w / 2:
        out.append(
            f"target: {target:g} m is half the tunnel's width ({w:g} m) or more: a lane-level "
            "answer asks for less (a value in cm?)"
        )
    cfg = setup.config
    if setup.fc < FR1_MAX_HZ and cfg.scs > max(FR1_SCS_HZ):
        out.append(
            f"radio: a {cfg.scs / 1e3:g} kHz subcarrier spacing at {setup.fc / 1e9:g} GHz is "
            f"not an NR FR1 numerology ({', '.join(f'{v / 1e3:g}' for v in FR1_SCS_HZ)} kHz); "
            f"the {cfg.bandwidth / 1e6:g} MHz band holds {cfg.n_rb} resource blocks of it "
            "(set the scenario's radio.scs and radio.n_rb for another numerology)"
        )
    wide = wideband_cycles(setup, specs)
    if not imp.spatial_wideband and wide > WIDEBAND_CYCLES and setup.channel == "image":
        out.append(
            f"impairments: the spatial-wideband term is off, yet the largest aperture spans "
            f"{wide:.2g} cycles of the {cfg.bandwidth / 1e6:g} MHz band (above "
            f"{WIDEBAND_CYCLES:g}): the band calls for it (--wideband, --wideband-model)"
        )
    out += implausible_impairments(imp)
    if imp.ideal and setup.channel == "image":
        out.append(
            "impairments: none (an ideal array and eq. 1's channel), the optimistic case; a "
            f"road-tunnel campaign at 5.9 GHz measured {100 * MEASURED_DIFFUSE_SHARE:g} % of the "
            "received power diffuse, and a calibrated 28 GHz array kept "
            f"{CALIBRATED_PHASE_ERROR_DEG:g} deg and {CALIBRATED_GAIN_ERROR_DB:g} dB per element "
            "(the default set, without --ideal)"
        )
    return out
