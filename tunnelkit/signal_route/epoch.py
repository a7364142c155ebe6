"""One SRS slot through the signal route, what ``SignalRoute.epoch`` runs (:func:`run_epoch`):
the drawn slot extracted, a flagged fit re-judged (:func:`rejudge_fit`), Algorithm 1 and the
route's options on the measurements, the :class:`~tunnelkit.signal_route.measurements.Epoch`."""

from __future__ import annotations

import numpy as np

from .._validate import instance, integer
from ..arrays import ArrayGeometry
from ..channel import ChannelSnapshot
from .measurements import Epoch, measure_epoch

__all__: list[str] = []


def run_epoch(
    route, k: int, rng: np.random.Generator, n_paths, tunnel, clock_bias, extract_kw: dict
) -> Epoch:
    """Simulate SRS slot ``k`` on ``route``: trace, synthesise (noise, clock bias), extract,
    Algorithm 1 (what ``SignalRoute.epoch`` runs, with its arguments; ``extract_kw`` the
    extraction options, a dict of its own)."""
    arr, paths, snap = route.draw(k, rng, tunnel=tunnel, clock_bias=clock_bias)
    L = len(paths) if n_paths is None else integer("n_paths", n_paths, minimum=1)
    if route.options.wideband_model:
        extract_kw.setdefault("wideband", True)
    if route.options.diffuse_floor and extract_kw.get("refine", "ml") == "ml":
        extract_kw.setdefault("noise_power", route.ml_noise_power(k, snap, tunnel))
    est = route.extract(snap.H, arr, L, **extract_kw)
    cfg = route.config if route.options.report_covariance else None
    rejudged = rejudge_fit(route, est, snap, arr, extract_kw)
    judged = rejudged is None or not rejudged["passed"]
    meas, truth = measure_epoch(est, arr, paths, snap, cfg, route.min_d, judged)
    if route.options.bias_budget is not None:
        from .judging import apply_budget

        meas = apply_budget(meas, route.options.bias_budget, k)
    if route.options.centroid_unresolved:
        from .farfield import centroid_far_field  # loaded when the option is on

        meas = centroid_far_field(meas, est, arr)
    return Epoch(
        k,
        float(route.trajectory.t[k]),
        route.trajectory.position[k].copy(),
        route.trajectory.velocity[k].copy(),
        arr,
        paths,
        snap,
        est,
        meas,
        truth,
        rejudged,
    )


def rejudge_fit(route, est, snap: ChannelSnapshot, arr: ArrayGeometry, extract_kw: dict):
    """The model-error test of a flagged ML fit on ``route`` (``model_error_floor``; None when
    there is nothing to re-judge: the floor off or zero, the fit passed or is not an ML fit, the
    extraction modelled the wideband term)."""
    from ..extraction.estimates import PathEstimates

    instance("est", est, PathEstimates)
    instance("snap", snap, ChannelSnapshot)
    instance("arr", arr, ArrayGeometry)
    instance("extract_kw", extract_kw, dict)
    if not route.options.model_error_floor or getattr(est, "fit_ok", None) is not False:
        return None
    if getattr(est, "fit", None) is None or extract_kw.get("wideband", False):
        return None
    from .judging import impairment_share, rejudge

    imp = route.impairments
    if impairment_share(imp) <= 0:
        return None
    # the diffuse share as it is, the calibration at the draw's false-alarm floor
    dmc = 0.0 if imp.dmc is None else float(imp.dmc.share)
    cal = None if imp.calibrated else (imp.phase_sigma_deg, imp.gain_sigma_db)
    return rejudge(est, snap.H, arr.local, route.config.fc, dmc, calibration=cal)
