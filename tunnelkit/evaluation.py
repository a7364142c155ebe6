"""Estimates against the truth (notebook 03, benchmarks): matching, tables, RMSE studies with bounds."""

from __future__ import annotations

import numpy as np

from .arrays import ArrayGeometry
from .constants import C

__all__ = ["comparison_rows", "match_paths", "path_rows", "rmse_study"]


def match_paths(
    d_est,
    dir_est,
    paths,
    *,
    clock_bias: float = 0.0,
    direction_scale: float = 0.1,
    range_scale: float = 1.0,
) -> np.ndarray:
    """Assign estimates to true paths (Hungarian on range and direction); -1 where unmatched.

    Cost: ``|d_est - (length + c b)| / range_scale + ||u_est - u_true|| / direction_scale``;
    assignments costing more than 10 are refused.
    """
    from scipy.optimize import linear_sum_assignment

    d_est = np.atleast_1d(np.asarray(d_est, float))
    out = -np.ones(d_est.shape[0], dtype=int)
    if not len(paths) or not d_est.size:
        return out
    d_true = np.array([p.length for p in paths]) + C * clock_bias
    u_true = np.stack([p.direction for p in paths])
    cost = (
        np.abs(d_est[:, None] - d_true[None, :]) / range_scale
        + np.linalg.norm(np.asarray(dir_est)[:, None, :] - u_true[None], axis=-1) / direction_scale
    )
    r, c = linear_sum_assignment(cost)
    ok = cost[r, c] < 10.0
    out[r[ok]] = c[ok]
    return out


def path_rows(paths) -> list[dict]:
    """One table row per true path: family, surface, length, angles [deg], Doppler, gain, kappa."""
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
    refine: str = "joint",
    progress: bool = False,
) -> list[dict]:
    """RMSE of ``d``, ``v``, direction and ``kappa`` per true path over seeded snapshots, with CRLBs.

    Each snapshot draws noise and a clock bias; estimates are matched to true paths (Hungarian);
    ``d`` errors are taken against ``length + c b`` (the bias is part of the truth), ``kappa``
    against the VUE distance (exact physics). Unmatched paths count in ``missed``.
    """
    from .channel import synthesize
    from .extraction import extract_paths, path_crlb
    from .montecarlo import spawn_rngs

    arr, paths = route.paths(k)
    cfg = route.config
    err = {i: [] for i in range(len(paths))}
    missed = np.zeros(len(paths), int)
    it = spawn_rngs(seed, n_snapshots)
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(it, desc="snapshots", leave=False)
    for r in it:
        snap = synthesize(paths, cfg, r, model=route.model, snr_offset_db=route.snr_offset_db)
        est = extract_paths(
            snap.H,
            len(paths),
            arr.local,
            cfg.fc,
            cfg.tone_spacing,
            cfg.symbol_period,
            refine=refine,
        )
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
    bound = path_crlb(paths, arr, cfg)
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
