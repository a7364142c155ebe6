"""Extraction routes against the Cramér-Rao bound along a drive, with or without impairments.

:func:`drive_efficiency` runs seeded snapshots of a :class:`~tunnelkit.signal_route.SignalRoute`
at chosen epochs: each snapshot's tensor (with the route's impairments, if any:
:class:`tunnelkit.channel.Impairments`) is synthesised once and extracted by every route asked
for (``extract_paths(refine=...)``); estimates are matched to the true paths
(:func:`tunnelkit.evaluation.match_paths`) and their direction and curvature errors compared with
the structured CRLB of eq. 1 (:func:`tunnelkit.extraction.path_crlb`). The bound always assumes
eq. 1 as printed: with an impairment on, the distance between estimator and bound is what the
impairment costs. Notebook 03 plots the result with :func:`tunnelkit.plots.efficiency_figure`.
"""

from __future__ import annotations

import warnings

import numpy as np

from ._validate import integer

__all__ = ["drive_efficiency", "efficiency_rows"]


def _epoch_errors(route, k, rngs, refines):
    from .evaluation import match_paths

    arr, paths = route.paths(k)
    err = {r: {j: [] for j in range(len(paths))} for r in refines}
    for rng in rngs:
        snap = route.snapshot(paths, arr, rng)
        for refine in refines:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                est = route.extract(snap.H, arr, len(paths), refine=refine)
            u = arr.dir_to_world(est.direction)
            match = match_paths(est.d, u, paths, clock_bias=snap.clock_bias)
            for i, j in enumerate(match):
                if j >= 0:
                    ang = np.arccos(np.clip(u[i] @ paths[j].direction, -1.0, 1.0))
                    err[refine][j].append((ang, est.kappa[i] - paths[j].length))
    return arr, paths, err


def drive_efficiency(
    route,
    epochs,
    n_snapshots: int,
    seed: int,
    *,
    refines: tuple[str, ...] = ("joint", "coherent", "ml"),
    progress: bool = False,
) -> list[dict]:
    """RMSE of direction and curvature per route, true path and epoch, beside the CRLB.

    ``epochs``: indices into the route's trajectory; ``n_snapshots`` seeded snapshots each (noise
    and clock bias drawn, the epoch's paths fixed); ``refines``: routes of
    :func:`tunnelkit.extraction.extract_paths`. One row per (epoch, true path, route): ``epoch``,
    ``range [m]`` (UE to reference antenna), ``route``, ``path`` (surface kind), ``matched``,
    ``RMSE dir [deg]``, ``CRLB dir [deg]``, ``RMSE kappa [m]`` (against the distance of the wave
    source, NaN estimates left out and counted in ``no kappa``), ``CRLB kappa [m]``.
    """
    from .extraction import path_crlb
    from .montecarlo import spawn_rngs

    epochs = [integer("epochs", k, minimum=0) for k in np.atleast_1d(epochs).tolist()]
    if not epochs:
        raise ValueError("epochs: need at least one epoch")
    n = integer("n_snapshots", n_snapshots, minimum=1)
    refines = tuple(refines)
    if not refines:
        raise ValueError("refines: need at least one route")
    it = list(zip(epochs, spawn_rngs(seed, len(epochs))))
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(it, desc="epochs", leave=False)
    rows = []
    for k, rng in it:
        arr, paths, err = _epoch_errors(route, k, rng.spawn(n), refines)
        bound = path_crlb(paths, arr, route.config, snr_offset_db=route.snr_offset_db)
        rng_ue = float(np.linalg.norm(route.trajectory.position[k] - arr.origin))
        for refine in refines:
            for j, p in enumerate(paths):
                e = np.array(err[refine][j]).reshape(-1, 2)
                kap = e[np.isfinite(e[:, 1]), 1]
                rows.append(
                    {
                        "epoch": k,
                        "range [m]": rng_ue,
                        "route": refine,
                        "path": p.surface_kind,
                        "matched": int(e.shape[0]),
                        "RMSE dir [deg]": float(np.degrees(np.sqrt(np.mean(e[:, 0] ** 2))))
                        if e.size
                        else np.nan,
                        "CRLB dir [deg]": float(np.degrees(bound["direction"][j])),
                        "RMSE kappa [m]": float(np.sqrt(np.mean(kap**2))) if kap.size else np.nan,
                        "CRLB kappa [m]": float(bound["kappa"][j]),
                        "no kappa": int(e.shape[0] - kap.size),
                    }
                )
    return rows


def efficiency_rows(rows: list[dict], path: str = "los") -> dict[str, dict[str, np.ndarray]]:
    """:func:`drive_efficiency` rows of one path kind regrouped per route for plotting:
    ``{route: {"range", "dir", "kappa", "crlb_dir", "crlb_kappa"}}`` sorted by range (the first
    path of that kind in each epoch)."""
    out: dict[str, dict[str, list]] = {}
    seen = set()
    for r in rows:
        key = (r["route"], r["epoch"])
        if r["path"] != path or key in seen:
            continue
        seen.add(key)
        o = out.setdefault(
            r["route"], {q: [] for q in ("range", "dir", "kappa", "crlb_dir", "crlb_kappa")}
        )
        o["range"].append(r["range [m]"])
        o["dir"].append(r["RMSE dir [deg]"])
        o["kappa"].append(r["RMSE kappa [m]"])
        o["crlb_dir"].append(r["CRLB dir [deg]"])
        o["crlb_kappa"].append(r["CRLB kappa [m]"])
    if not out:
        raise ValueError(f"path: no row of kind {path!r}")
    res = {}
    for route, o in out.items():
        order = np.argsort(o["range"])
        res[route] = {q: np.asarray(v, float)[order] for q, v in o.items()}
    return res
