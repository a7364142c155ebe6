"""Estimates against the truth in tables: errors in units of the CRLB, rows per path, RMSE
studies with their bounds (notebook 03, benchmarks).
"""

from __future__ import annotations

import numpy as np

from .._checks import attributes
from .._validate import boolean, finite_array, instance, integer, real, sequence
from ..arrays import ArrayGeometry
from ..constants import C
from ..extraction import MIN_SIGNIFICANCE, path_crlb
from ..extraction.estimates import PathEstimates
from ..montecarlo import spawn_rngs
from .matching import match_paths, match_points

__all__ = ["bound_errors", "comparison_rows", "normalized_errors", "path_rows", "rmse_study"]


def _truth_and_bound(est, d_true, v_true, sources, bound):
    """The checked inputs of :func:`normalized_errors` / :func:`bound_errors`: ``sources``
    (L, 3) finite, ``d_true`` and ``v_true`` (L,) finite, ``bound`` a dict of (L,) arrays."""

    instance("est", est, PathEstimates)
    src = np.atleast_2d(finite_array("sources", sources))
    if src.ndim != 2 or src.shape[1] != 3:
        raise ValueError(f"sources: expected wave origins (L, 3), got shape {src.shape}")
    n = src.shape[0]
    d_true = finite_array("d_true", d_true, ndim=1)
    v_true = finite_array("v_true", v_true, ndim=1)
    for name, x in (("d_true", d_true), ("v_true", v_true)):
        if x.shape != (n,):
            raise ValueError(f"{name}: expected one value per source ({n}), got shape {x.shape}")
    instance("bound", bound, dict, "a dict of standard deviations")
    return src, d_true, v_true


def normalized_errors(est, d_true, v_true, sources, bound) -> np.ndarray:
    """Errors over the CRLB standard deviation, (L_true, 4) for ``d, v, direction, kappa``.

    ``est`` a :class:`~tunnelkit.extraction.PathEstimates`, ``d_true`` (with the clock bias),
    ``v_true``, ``sources`` (L, 3) the true wave origins in the array's local frame, ``bound`` a
    dict of standard deviations (``path_crlb`` / ``source_crlb`` units: m, m/s, rad, m). A true
    path no estimate is matched to gets ``inf`` in every column (every estimate of the route is
    matched, not only Algorithm 1's ``d >= 0``; on the ML route those above the noise); a far-field estimate (kappa NaN)
    of a near-field path gets ``inf`` in the kappa column. The direction error is the angle
    between the unit vectors (non-negative).
    """
    src, d_true, v_true = _truth_and_bound(est, d_true, v_true, sources, bound)
    rng_ = np.linalg.norm(src, axis=1)
    u = src / rng_[:, None]
    out = np.full((src.shape[0], 4), np.inf)
    if est.significance is None:  # every estimate of the route (not Algorithm 1's d >= 0)
        keep = np.arange(len(est))
    else:  # the ML route: the paths that stand above the noise
        keep = np.flatnonzero(est.significance >= MIN_SIGNIFICANCE)
    match = match_points(est.d[keep], est.direction[keep], d_true, u)
    for i, j in zip(keep, match):
        if j < 0:
            continue
        kap = est.kappa[i] if np.isfinite(est.kappa[i]) else np.inf
        out[j] = (
            (est.d[i] - d_true[j]) / bound["d"][j],
            (est.v[i] - v_true[j]) / bound["v"][j],
            np.arccos(np.clip(est.direction[i] @ u[j], -1.0, 1.0)) / bound["direction"][j],
            (kap - rng_[j]) / bound["kappa"][j],
        )
    return out


def bound_errors(est, d_true, v_true, sources, bound) -> np.ndarray:
    """Errors over the CRLB, (L_true, 4) for ``d, v, direction, w = 1 / kappa``, with estimates
    assigned to true paths in units of the bound; ``inf`` for a missed true path.

    As :func:`normalized_errors`, except: the curvature column is ``w = 1 / kappa`` (what the ML
    fit estimates, ``kappa_nf``; finite for a far-field estimate) over its bound
    ``sigma_kappa / kappa^2``; the estimates (on the ML route those above the noise) are assigned
    by the Hungarian method on the sum of squared normalised errors, so clustered paths a
    centimetre and a degree apart are told apart by the bound rather than by metres and
    radians; an assignment beyond 1,000 sigma counts as missed.
    """
    from scipy.optimize import linear_sum_assignment

    src, d_true, v_true = _truth_and_bound(est, d_true, v_true, sources, bound)
    rng_ = np.linalg.norm(src, axis=1)
    u = src / rng_[:, None]
    out = np.full((src.shape[0], 4), np.inf)
    if est.significance is None:
        keep = np.arange(len(est))
    else:
        keep = np.flatnonzero(est.significance >= MIN_SIGNIFICANCE)
    if not keep.size:
        return out
    with np.errstate(divide="ignore"):
        w_est = 1.0 / np.asarray(est.kappa_nf, float)[keep]  # 1/inf = 0: an exact plane wave
    w_est = np.nan_to_num(w_est, nan=0.0)
    cosang = np.clip(est.direction[keep] @ u.T, -1.0, 1.0)
    e = np.stack(
        [
            (est.d[keep][:, None] - np.asarray(d_true)[None]) / bound["d"][None],
            (est.v[keep][:, None] - np.asarray(v_true)[None]) / bound["v"][None],
            np.arccos(cosang) / bound["direction"][None],
            (w_est[:, None] - 1.0 / rng_[None]) / (bound["kappa"] / rng_**2)[None],
        ],
        axis=-1,
    )
    cost = np.sum(np.minimum(np.nan_to_num(e, nan=1e6) ** 2, 1e12), axis=-1)
    r, c = linear_sum_assignment(cost)
    for i, j in zip(r, c):
        if cost[i, j] < 1e6:
            out[j] = e[i, j]
    return out


def path_rows(paths) -> list[dict]:
    """One table row per true path: family, surface, length, angles [deg], Doppler, gain, kappa."""
    paths = sequence("paths", paths, empty=True)  # no path: an empty table
    return [
        {
            "kind": p.surface_kind,
            "surface": p.surface or "-",
            "length [m]": p.length,
            "azimuth [deg]": float(np.degrees(p.azimuth)),
            "elevation [deg]": float(np.degrees(p.elevation)),
            "v [m/s]": p.velocity,
            "Doppler [Hz]": p.doppler,
            "|gain| [dB]": float(20 * np.log10(abs(p.gain))),
            "kappa SR-NF [m]": p.kappa_srnf,
        }
        for p in paths
    ]


def comparison_rows(est, paths, array: ArrayGeometry, clock_bias: float) -> list[dict]:
    """Extracted vs true parameters, one row per estimate matched to a true path."""

    instance("est", est, PathEstimates)
    paths = sequence("paths", paths, empty=True)  # no true path: every estimate unmatched
    instance("array", array, ArrayGeometry)
    clock_bias = real("clock_bias", clock_bias)  # a clock offset [s]: either sign
    match = match_paths(est.d, array.dir_to_world(est.direction), paths, clock_bias=clock_bias)
    rows = []
    for i, j in enumerate(match):
        p = paths[j] if j >= 0 else None
        u = array.dir_to_world(est.direction[i])
        rows.append(
            {
                "est #": i,
                "true path": p.surface_kind if p else "none",
                "d est [m]": est.d[i],
                "d true [m]": (p.length + C * clock_bias) if p else np.nan,
                "v est": est.v[i],
                "v true": p.velocity if p else np.nan,
                "angle err [deg]": float(np.degrees(np.arccos(np.clip(u @ p.direction, -1, 1))))
                if p
                else np.nan,
                "kappa est [m]": est.kappa[i],
                "|VUE| [m]": p.length if p else np.nan,
                "kappa SR-NF [m]": p.kappa_srnf if p else np.nan,
            }
        )
    return rows


def rmse_study(
    route,
    k: int,
    n_snapshots: int,
    seed: int,
    *,
    refine: str = "ml",
    progress: bool = False,
    spatial: str | None = None,
) -> list[dict]:
    """RMSE of ``d``, ``v``, direction and ``kappa`` per true path over seeded snapshots, with CRLBs.

    Each snapshot draws noise and a clock bias; estimates are matched to true paths (Hungarian);
    ``d`` errors are taken against ``length + c b`` (the bias is part of the truth), ``kappa``
    against the VUE distance (exact physics). Unmatched paths count in ``missed``.
    ``refine`` is the extraction route (``extract_paths``); ``spatial`` the model of the ``d``/``v``
    bound (:func:`~tunnelkit.extraction.path_crlb`): by default "free" for the paper's routes
    ("joint", "column", "none": what a CPD can reach) and "structured" for "ml" and "coherent".
    """
    attributes("route", route, ("paths", "config"), "a signal_route.SignalRoute")
    n_snapshots = integer("n_snapshots", n_snapshots, minimum=1)
    progress = boolean("progress", progress)
    if spatial is None:
        spatial = "free" if refine in ("joint", "column", "none") else "structured"

    arr, paths = route.paths(k)
    cfg = route.config
    err = {i: [] for i in range(len(paths))}
    missed = np.zeros(len(paths), int)
    it = spawn_rngs(seed, n_snapshots)
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(it, desc="snapshots", leave=False)
    for r in it:
        snap = route.snapshot(paths, arr, r)
        est = route.extract(snap.H, arr, len(paths), refine=refine)
        match = match_paths(
            est.d, arr.dir_to_world(est.direction), paths, clock_bias=snap.clock_bias
        )
        for i, j in enumerate(match):
            if j < 0:
                continue
            p = paths[j]
            u = arr.dir_to_world(est.direction[i])
            err[j].append(
                (
                    est.d[i] - p.length - C * snap.clock_bias,
                    est.v[i] - p.velocity,
                    np.arccos(np.clip(u @ p.direction, -1, 1)),
                    est.kappa[i] - p.length,
                )
            )
        missed += np.isin(np.arange(len(paths)), match, invert=True)
    bound = path_crlb(paths, arr, cfg, spatial=spatial, snr_offset_db=route.snr_offset_db)
    rows = []
    for j, p in enumerate(paths):
        e = np.array(err[j]).reshape(-1, 4)
        with np.errstate(invalid="ignore"):
            rm = np.sqrt(np.nanmean(e**2, axis=0)) if e.size else np.full(4, np.nan)
        rows.append(
            {
                "path": p.surface_kind,
                "surface": p.surface or "-",
                "matched": len(err[j]),
                "missed": int(missed[j]),
                "RMSE d [m]": rm[0],
                "CRLB d [m]": bound["d"][j],
                "RMSE v [m/s]": rm[1],
                "CRLB v [m/s]": bound["v"][j],
                "RMSE dir [deg]": float(np.degrees(rm[2])),
                "CRLB dir [deg]": float(np.degrees(bound["direction"][j])),
                "RMSE kappa [m]": rm[3],
                "CRLB kappa [m]": bound["kappa"][j],
                "far-field share": float(np.mean(np.isnan(e[:, 3]))) if e.size else np.nan,
            }
        )
    return rows
