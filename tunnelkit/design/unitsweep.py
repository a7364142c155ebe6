"""The design's Monte-Carlo by manufactured units: :func:`run_units` runs every undecided
array's units in batches (doubling up to the cap) and :func:`score_row` fills an array's row from
its errors and judges it by the unit yield (:mod:`tunnelkit.design.units`,
:mod:`tunnelkit.design.verdict`). :func:`tunnelkit.design.design_sweep` calls it when a sweep asks
for units.
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np

from ..settling import SETTLE_S
from .achievable import DesignImpairments, path_error_model
from .intervals import cluster_quantile_ci, rmse_ci
from .montecarlo import sweep_montecarlo
from .units import unit_quantiles, unit_rmse, unit_yield
from .verdict import REQUIRED_YIELD, counted_epochs, gate, judge, share_quantile

#: nothing exported: the sweep's own steps, on the arguments :func:`tunnelkit.design.design_sweep`
#: (and :func:`tunnelkit.design.confirm.confirm_on_channel`) checked at their boundary
__all__: list[str] = []


def sweep_options(imp, mode, workers, scheduler, timeout, progress, n_epochs, start_sigma,
                  dead_reckoning, drives_per_unit, traced_tracker, trial_timeout) -> dict:  # fmt: skip
    """The options of a design sweep's Monte-Carlo (:func:`run_units`' ``kw``), the bound
    route's error model per array under the impairments ``imp`` among them."""
    return {
        "mode": mode,
        "error_models": _error_models(imp, mode),
        "impairments": None if imp.ideal else imp,
        "workers": workers,
        "scheduler": scheduler,
        "timeout": timeout,
        "trial_timeout": trial_timeout,
        "progress": progress,
        "n_epochs": n_epochs,
        "start_sigma": start_sigma,
        "dead_reckoning": dead_reckoning,
        "drives_per_unit": drives_per_unit,
        "traced_tracker": traced_tracker,
    }


def _error_models(impairments: DesignImpairments, mode: str):
    """The bound route's error model per array under ``impairments`` (``None``: the ideal)."""
    if mode != "bound" or impairments.ideal:
        return None
    return partial(path_error_model, impairments=impairments)


def _sweep_montecarlo(setup, specs, runs, seed, **kw) -> dict:
    """:func:`tunnelkit.design.montecarlo.sweep_montecarlo` (the seam a test replaces)."""
    return sweep_montecarlo(setup, specs, runs, seed, **kw)


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


def _rms(v, k) -> float | None:
    return None if v is None else float(np.sqrt(np.mean(np.asarray(v, float)[k] ** 2)))


def score_row(
    row,
    res,
    criterion,
    target,
    share,
    *,
    settle: float = SETTLE_S,
    required: float = REQUIRED_YIELD,
    cap: int | None = None,
) -> None:
    """Fill ``row`` from one array's Monte-Carlo result (errors (units x drives, T), the drives
    of one unit after each other) and judge it by the unit yield."""
    errors = np.asarray(_field(res, "errors"), float)
    t = np.asarray(_field(res, "t"), float)
    if errors.ndim != 2 or errors.shape[1] != t.size:
        raise ValueError(f"errors: expected (runs, {t.size}), got shape {errors.shape}")
    d = int(getattr(res, "drives_per_unit", 1))
    runs, units = errors.shape[0], errors.shape[0] // d
    k = counted_epochs(t, settle)
    valid = row.srnf_valid[: t.size]
    lost = np.where(np.isfinite(errors), errors, np.inf)  # no estimate: an infinite error
    gated = gate(lost, valid, criterion)
    e = gated[:, k]
    row.runs, row.units, row.drives_per_unit = runs, units, d
    row.error_median_epoch_m = np.median(lost, axis=0)
    row.error_median_m = float(np.median(e))
    row.error_p90_m = share_quantile(e, share)
    row.error_p90_route_m = share_quantile(gated, share)
    # the interval over units (one cluster per unit: its drives share its calibration)
    row.error_p90_ci95_m = cluster_quantile_ci(e.reshape(units, -1), share)
    sq = np.where(np.isfinite(errors[:, k]), errors[:, k], np.inf) ** 2
    row.rmse_m = float(np.sqrt(sq.mean()))
    row.unit_rmse_m = unit_rmse(errors, d, k)
    row.rmse_ci95_m = rmse_ci(row.unit_rmse_m)  # over units: None below two, or a drive lost
    uq = unit_quantiles(gated, d, k, share)
    row.unit_p90_m = [float(v) for v in np.quantile(uq, [0.0, 0.5, 1.0], method="inverted_cdf")]
    row.unit_yield, row.unit_yield_ci95 = unit_yield(uq, target)
    row.error_model = getattr(res, "error_model", None)
    dr = getattr(res, "dead_reckoning", None)
    if dr is not None:  # the same drives, every measurement dropped: what the radio adds
        dr = np.asarray(dr, float)
        row.dead_reckoning_p90_m = share_quantile(dr[:, k], share)  # never lost: no NaN
        row.dead_reckoning_rmse_m = float(np.sqrt(np.mean(dr[:, k] ** 2)))
        row.dead_reckoning_unit_rmse_m = unit_rmse(dr, d, k)
    pred = _rms(row.predicted_m, k)
    row.rmse_over_predicted = row.rmse_m / pred if pred else None
    _drive_bounds(row, res, k, row.unit_rmse_m)
    row.status, row.reason = judge(
        target,
        units=units,
        yield_=row.unit_yield,
        ci=row.unit_yield_ci95,
        required=required,
        share=share,
        cap=cap,
    )


def _drive_bounds(row, res, k, unit_rmse) -> None:
    """The bounds over the drive (RMS over the counted epochs ``k``) and the tracker's RMSE
    over them: ``pcrlb`` every unit's (so each unit's RMSE ``unit_rmse`` is set beside it),
    ``hybrid`` the one pooled over units; and the prediction ``predicted`` over the drive."""
    pc, hy = _rms(getattr(res, "pcrlb", None), k), _rms(getattr(res, "hybrid", None), k)
    if pc:
        row.pcrlb_rms_m, row.rmse_over_pcrlb = pc, row.rmse_m / pc
        row.unit_rmse_over_pcrlb_min = float(np.min(unit_rmse)) / pc
    if hy:
        row.hybrid_bound_rms_m, row.rmse_over_hybrid_bound = hy, row.rmse_m / hy
    pred = _rms(getattr(res, "predicted", None), k)
    if pred is not None:
        row.predicted_drive_rms_m = pred
        row.rmse_over_predicted_drive = row.rmse_m / pred if pred > 0 else None


def run_units(setup, rows, todo, units, cap, seed, kw, warnings, scoring, judged) -> None:
    """The Monte-Carlo by units: ``units`` units of every array in ``todo``, then as many again
    (doubling) for the arrays still undecided, up to ``cap`` units; each batch's units follow
    the last (a unit's generators do not depend on the batch), each array scored on all its
    units after every batch (:func:`score_row`)."""
    by = {r.array: r for r in rows}
    done, batch, open_ = 0, units, list(todo)
    acc: dict = {}
    while open_ and batch > 0:
        d = kw["drives_per_unit"]
        results, failed = _run_montecarlo(setup, open_, batch * d, seed, dict(kw, first_unit=done))
        done += batch
        for label, why in failed.items():
            by[label].status, by[label].reason = "error", why
            warnings.append(f"{label}: {why}")
        for label, res in results.items():
            acc[label] = res if label not in acc else _joined(acc[label], res)
            score_row(by[label], acc[label], *scoring, **judged)
        open_ = [s for s in open_ if s.label in results and by[s.label].status == "undecided"]
        batch = min(done, cap - done)


def _joined(a, b):
    """Two Monte-Carlo results of one array, ``b``'s units after ``a``'s."""
    cat = {
        k: np.concatenate([getattr(a, k), getattr(b, k)])
        for k in ("errors", "rmse_runs", "dead_reckoning")
        if getattr(a, k) is not None
    }
    return replace(a, **cat)
