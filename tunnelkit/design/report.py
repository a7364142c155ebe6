"""A design sweep and its recommendation: one row per candidate array, decided from what the
tracker achieves.

:func:`design_sweep` evaluates every candidate along the route:

1. it is placed on the mount (an array with an element outside the cross-section is refused,
   per array, with the reason: :meth:`DesignSetup.arrays`);
2. the **ideal PEB** and the **achievable bound** of the design's tracker under the stated
   impairments (:func:`tunnelkit.design.achievable.achievable_bound`: each path's error mapped
   to the position as the tracker weighs it, one block per path, never below the PEB), SR-NF
   validity per surface (information under ``criterion="achievable"``, a gate under ``"srnf"``);
3. the **pre-screen**: a candidate on which even an estimator at the achievable bound would miss
   the target on ``share`` of the counted epochs is hopeless and gets no Monte-Carlo;
4. the **Monte-Carlo** of the design's tracker on the others, all arrays x runs as one task set
   (:func:`tunnelkit.design.montecarlo.sweep_montecarlo`), and the verdict of
   :mod:`tunnelkit.design.verdict` (error quantile with a bootstrap 95 % interval).

:class:`DesignReport` holds the rows, the recommendation, every input and the warnings, as JSON
(:meth:`DesignReport.to_json`) or a text table (:meth:`DesignReport.to_table`).
:func:`smallest_meeting` is the explorer's bound-only pre-screen (achievable bound, or PEB and SR-NF
under ``criterion="srnf"``).
"""

from __future__ import annotations

from dataclasses import asdict
from functools import partial

import numpy as np

from .._validate import boolean, choice, finite_array, integer, positive, probability, sequence
from ..budget import check_elements
from ..montecarlo import parallel_options
from .achievable import DesignImpairments, achievable_bound, path_error_model
from .bounds import route_bounds, route_geometry
from .montecarlo import MODES, START_SIGMA_M, sweep_montecarlo
from .records import DesignReport, DesignRow, over_target
from .setup import ArraySpec, DesignSetup, parse_array
from .verdict import (
    CRITERIA,
    MIN_RUNS_CI,
    bootstrap_quantile_ci,
    counted_epochs,
    gate,
    implied_quantile,
    judge,
    recommend,
    screen_bound,
    share_quantile,
)

__all__ = ["DesignReport", "DesignRow", "design_sweep", "over_target", "smallest_meeting"]


def smallest_meeting(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    criterion: str = "achievable",
    impairments=None,
    eps_phi: float = 0.15,
    epochs=None,
) -> tuple[ArraySpec | None, float]:
    """The first array of ``arrays`` (in the order given) whose **bound** meets ``target`` on
    ``share`` of the route, and its met share; ``(None, best share)`` if none.

    A bound-only pre-screen for the explorer (the answer is :func:`design_sweep` with runs):
    with ``criterion="achievable"`` (default) the achievable bound under ``impairments``
    (``None``: the PEB), SR-NF only information; with ``"srnf"`` (an eq. 51 estimator) an epoch
    where SR-NF fails counts as missed. Arrays that do not fit are skipped; ``epochs``
    subsamples the route."""
    sequence("arrays", arrays), epochs is None or finite_array("epochs", epochs, ndim=1)
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    if share == 0:
        raise ValueError("share: expected a share in (0, 1], got 0")
    criterion = choice("criterion", criterion, CRITERIA)
    imp = _design_impairments(impairments)
    best = 0.0
    for spec in (parse_array(a) for a in arrays):
        try:
            g = route_geometry(setup, spec, epochs=epochs)
        except ValueError:
            continue
        b = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g, peb=False)
        if criterion == "srnf" and b.srnf_valid.mean() < share:
            continue
        a = achievable_bound(setup, spec, imp, geometry=g)
        met = float(np.mean(gate(a.achievable, b.srnf_valid, criterion) <= target))
        if met >= share:
            return spec, met
        best = max(best, met)
    return None, best


# --- the sweep ------------------------------------------------------------------------------


def _impairment_fields(imp: DesignImpairments) -> dict:
    """The impairment settings as plain values (the report's inputs)."""
    return {k: (v if isinstance(v, (bool, str)) else float(v)) for k, v in asdict(imp).items()}


def _design_impairments(impairments) -> DesignImpairments:
    """``impairments`` (None, a dict of fields or a ``DesignImpairments``) as the object the
    achievable bound and the error model take."""
    if impairments is None:
        return DesignImpairments()
    if isinstance(impairments, dict):
        return DesignImpairments(**impairments)
    if not isinstance(impairments, DesignImpairments):
        raise TypeError(
            f"impairments: expected a design.DesignImpairments or a dict of its fields, got "
            f"{type(impairments).__name__}"
        )
    return impairments


def _achievable_bound(setup, spec, impairments, geometry):
    r = achievable_bound(setup, spec, impairments, geometry=geometry)  # and PEB + impairments:
    a, n = r.achievable, np.where(np.isfinite(r.noise), r.noise, 0.0)
    imp = np.where(np.isfinite(a), a**2 - n**2, np.inf)
    return r.x, r.peb, r.achievable, np.sqrt(np.clip(imp, 0.0, None) + r.peb**2)


def _sweep_montecarlo(setup, specs, runs, seed, **kw) -> dict:
    """:func:`tunnelkit.design.montecarlo.sweep_montecarlo` (one task set for every array)."""
    return sweep_montecarlo(setup, specs, runs, seed, **kw)


def _error_models(impairments: DesignImpairments, mode: str):
    """The bound route's error model per array under ``impairments`` (``None``: the ideal)."""
    if mode != "bound" or impairments.ideal:
        return None
    return partial(path_error_model, impairments=impairments)


def _run_montecarlo(setup, specs, runs, seed, kw) -> tuple[dict, dict]:
    """One task set for all ``specs``; if it fails on an array's input, each array alone, so
    one undefined array is reported with its reason instead of losing the sweep."""
    try:
        return _sweep_montecarlo(setup, specs, runs, seed, **kw), {}
    except (ValueError, ArithmeticError) as exc:
        if len(specs) == 1:
            return {}, {specs[0].label: f"Monte-Carlo failed: {exc}"}
    out, failed = {}, {}
    for s in specs:
        try:
            out.update(_sweep_montecarlo(setup, [s], runs, seed, **kw))
        except (ValueError, ArithmeticError) as exc:
            failed[s.label] = f"Monte-Carlo failed: {exc}"
    return out, failed


def _field(res, name):
    return res[name] if isinstance(res, dict) else getattr(res, name)


def _bound_row(setup, spec, impairments, criterion, target, share, eps_phi, epochs) -> DesignRow:
    """The bound part of one candidate's row (placement checked first)."""
    row = DesignRow(spec.label, spec.n_elements, spec.aperture(setup.fc))
    try:
        setup.arrays(spec)
        g = route_geometry(setup, spec, epochs=epochs)
        sr = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g, peb=False)
        x, peb, ach, imp_only = _achievable_bound(setup, spec, impairments, g)
    except (ValueError, ArithmeticError) as exc:
        row.reason = str(exc)
        return row
    bad = np.isnan(peb) | np.isnan(ach) | (np.isinf(ach) & np.isfinite(peb))
    if bad.any():
        row.reason = (
            f"bound undefined (NaN, or a per-path bound the tracker needs) at {int(bad.sum())} "
            f"of {bad.size} epochs: the array cannot be evaluated on this route"
        )
        return row
    t = setup.trajectory.t[: len(x)]
    k = counted_epochs(t)
    row.x_m, row.peb_m, row.achievable_m = x, peb, ach
    row.srnf_valid_share = float(sr.srnf_valid.mean())
    row.srnf_valid_share_by_surface = sr.surface_validity()
    gated = gate(ach, sr.srnf_valid, criterion)[k]
    row.peb_median_m = float(np.median(peb[k]))
    row.peb_p90_m = share_quantile(peb[k], share)
    row.achievable_median_m = float(np.median(ach[k]))
    row.achievable_p90_m = share_quantile(ach[k], share)
    row.met_share = float(np.mean(gated <= target))
    scr = gate(screen_bound(peb, imp_only), sr.srnf_valid, criterion)[k]  # the pre-screen
    row.screen_m = implied_quantile(scr, share)
    row.srnf_valid = sr.srnf_valid
    row.status, row.reason = judge(target, row.screen_m, share=share)
    return row


def score_row(row, res, criterion, target, share, seed, n_boot) -> None:
    """Fill ``row`` from one array's Monte-Carlo result (errors (runs, T)) and judge it."""
    errors = np.asarray(_field(res, "errors"), float)
    t = np.asarray(_field(res, "t"), float)
    if errors.ndim != 2 or errors.shape[1] != t.size:
        raise ValueError(f"errors: expected (runs, {t.size}), got shape {errors.shape}")
    runs = errors.shape[0]
    k = counted_epochs(t)
    valid = row.srnf_valid[: t.size]
    lost = np.where(np.isfinite(errors), errors, np.inf)  # no estimate: an infinite error
    e = gate(lost, valid, criterion)[:, k]
    rng = np.random.default_rng([0xB007, int(seed), *row.array.encode()])
    row.runs = runs
    row.error_median_epoch_m = np.median(lost, axis=0)
    row.error_median_m = float(np.median(e))
    row.error_p90_m = share_quantile(e, share)
    row.error_p90_ci95_m = bootstrap_quantile_ci(e, share, rng, n_boot=n_boot)
    sq = np.where(np.isfinite(errors[:, k]), errors[:, k], np.inf) ** 2
    row.rmse_m = float(np.sqrt(sq.mean()))
    idx = rng.integers(0, runs, size=(n_boot, runs))
    boot = np.sqrt(sq.mean(axis=1)[idx].mean(axis=1))
    row.rmse_ci95_m = [float(v) for v in np.quantile(boot, [0.025, 0.975], method="inverted_cdf")]
    row.error_model = getattr(res, "error_model", None)
    dr = getattr(res, "dead_reckoning", None)
    if dr is not None:  # the same drives, every measurement dropped: what the radio adds
        dr = np.asarray(dr, float)
        row.dead_reckoning_p90_m = share_quantile(dr[:, k], share)  # never lost: no NaN
        row.dead_reckoning_rmse_m = float(np.sqrt(np.mean(dr[:, k] ** 2)))
    ach = np.sqrt(np.mean(np.asarray(row.achievable_m)[k] ** 2))
    row.rmse_over_achievable = row.rmse_m / ach if ach > 0 else None
    _drive_bounds(row, res, k)
    row.status, row.reason = judge(
        target,
        row.screen_m,
        runs=runs,
        error_q=row.error_p90_m,
        ci=row.error_p90_ci95_m,
        share=share,
    )


def _drive_bounds(row, res, k) -> None:
    """RMS over the counted epochs ``k`` of ``res.drive`` (surfaces known) and ``res.learned``
    (VUEs learnt); the tracker's RMSE over the bound of the VUEs it ran with."""
    known, learned = getattr(res, "drive", None), getattr(res, "learned", None)
    if known is not None and learned is not None:
        rms = [float(np.sqrt(np.mean(np.asarray(b)[k] ** 2))) for b in (known, learned)]
        row.drive_bound_known_rms_m, row.drive_bound_learned_rms_m = rms
        row.tracker_vues, bound = res.vues, rms[0] if res.vues == "known" else rms[1]
        row.rmse_over_tracker_bound = row.rmse_m / bound if bound > 0 else None


def design_sweep(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    criterion: str = "achievable",
    impairments=None,
    eps_phi: float = 0.15,
    runs: int = 0,
    seed: int = 0,
    mode: str = "bound",
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    n_epochs: int | None = None,
    timeout: float | None = None,
    n_boot: int = 2000,
    start_sigma: float = START_SIGMA_M,
    dead_reckoning: bool = False,
) -> DesignReport:
    """Every candidate of ``arrays`` evaluated and judged (module docstring).

    ``target`` [m] on ``share`` of the settled route; ``criterion`` ``"achievable"`` (default,
    the design's VUE-curvature tracker) or ``"srnf"`` (an eq. 51 route: SR-NF a gate);
    ``impairments``: a ``design.DesignImpairments`` or a dict of its fields (``None``: ideal);
    ``runs`` drives per array (0: bounds only) on the ``mode`` route (``"bound"``: drawn from
    the error model; ``"channel"``: synthesis and extraction), seeded by ``seed``; ``workers``
    / ``scheduler`` / ``timeout`` go to the one task set; ``n_epochs`` truncates the route;
    ``n_boot`` bootstrap resamples; ``start_sigma`` [m] the entry fix's standard deviation per
    axis (the tracker's start and the prior of the bounds over the drive; default
    :data:`~tunnelkit.design.montecarlo.START_SIGMA_M`, the open-sky fix); ``dead_reckoning``:
    each drive also run with every measurement dropped, the rows' ``dead_reckoning_*`` (what
    the radio adds). An array that does not fit, or whose bound or Monte-Carlo
    is undefined, is a row with status ``"error"`` and the reason; the sweep goes on."""
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    if isinstance(arrays, (str, ArraySpec)):
        arrays = [arrays]
    specs = list(dict.fromkeys(parse_array(a) for a in sequence("arrays", arrays, empty=True)))
    if not specs:
        raise ValueError("arrays: give at least one candidate array")
    if timeout is not None:
        timeout = positive("timeout", timeout)
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    if share == 0:
        raise ValueError("share: expected a share in (0, 1], got 0")
    criterion = choice("criterion", criterion, CRITERIA)
    mode = choice("mode", mode, MODES)
    eps_phi = positive("eps_phi", eps_phi)
    runs = integer("runs", runs, minimum=0)
    seed = integer("seed", seed, minimum=0)
    n_boot = integer("n_boot", n_boot, minimum=100)
    start_sigma = positive("start_sigma", start_sigma)
    dead_reckoning = boolean("dead_reckoning", dead_reckoning)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    workers, scheduler = parallel_options(workers, scheduler)
    imp = _design_impairments(impairments)
    fields = _impairment_fields(imp)
    if mode == "channel" and runs:
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
    T = len(setup.trajectory)
    epochs = None if n_epochs is None or n_epochs >= T else np.arange(n_epochs)
    rows = [_bound_row(setup, s, imp, criterion, target, share, eps_phi, epochs) for s in specs]
    warnings = [f"{r.array}: {r.reason}" for r in rows if r.status == "error"]
    todo = [s for s, r in zip(specs, rows) if r.status == "bound only"]
    hopeless = [r.array for r in rows if r.status == "hopeless"]
    if runs and hopeless:
        warnings.append(
            f"{', '.join(hopeless)}: even an estimator at the achievable bound would miss "
            f"{target:g} m on {100 * share:g} % of the route; Monte-Carlo skipped"
        )
    if runs and todo:
        kw = {
            "mode": mode,
            "error_models": _error_models(imp, mode),
            "impairments": None if imp.ideal else imp,
            "workers": workers,
            "scheduler": scheduler,
            "timeout": timeout,
            "progress": progress,
            "n_epochs": n_epochs,
            "start_sigma": start_sigma,
            "dead_reckoning": dead_reckoning,
        }
        results, failed = _run_montecarlo(setup, todo, runs, seed, kw)
        for r in rows:
            if r.array in failed:
                r.status, r.reason = "error", failed[r.array]
                warnings.append(f"{r.array}: {r.reason}")
            elif r.array in results:
                score_row(r, results[r.array], criterion, target, share, seed, n_boot)
    if runs == 0:
        warnings.append(
            "no Monte-Carlo (runs 0): the recommendation rests on bounds only, a "
            "necessary condition, not an answer"
        )
    elif runs == 1:
        warnings.append(
            "runs 1: one drive gives no confidence interval; every verdict is undecided "
            f"(use --runs {2 * MIN_RUNS_CI})"
        )
    elif runs < MIN_RUNS_CI:
        warnings.append(
            f"runs {runs}: too few for a 95 % interval to decide (at least {MIN_RUNS_CI}); the "
            "intervals are shown, every verdict is undecided"
        )
    straddle = [r.array for r in rows if r.status == "undecided" and r.runs >= MIN_RUNS_CI]
    if straddle:
        warnings.append(f"{', '.join(straddle)}: the 95 % interval straddles the target; add runs")
    reused = sorted(
        r.array
        for r in rows
        if r.error_model and r.error_model.get("seed") == seed and mode == "channel"
    )
    if runs and reused:
        warnings.append(
            f"{', '.join(reused)}: the traced route's measurement noise was measured on this "
            f"seed's first drives (seed {seed}); report the sweep on another seed"
        )
    if criterion == "srnf" and runs:
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
        "target": target,
        "share": share,
        "criterion": criterion,
        "impairments": fields,
        "eps_phi": eps_phi,
        "runs": runs,
        "seed": seed,
        "mode": mode,
        "n_epochs": n_epochs,
        "n_boot": n_boot,
        "min_runs_ci": MIN_RUNS_CI,
        "workers": workers,
        "scheduler": scheduler,
        "timeout_s": timeout,
    }
    if setup.channel != "image":  # (the image channel's JSON as before)
        settings["channel"] = setup.channel
    if start_sigma != START_SIGMA_M:  # (the default's JSON as before)
        settings["start_sigma_m"] = start_sigma
    if dead_reckoning:
        settings["dead_reckoning"] = True
    rec = recommend([r for r in rows if r.status != "error"], target, share, runs)
    return DesignReport(setup.name, rows, rec, settings, warnings)
