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

from ._checks import attributes
from ._validate import boolean, finite_array, integer, sequence, text
from .constants import C, db2lin
from .evaluation import bound_errors, match_paths
from .extraction import path_crlb
from .montecarlo import spawn_rngs

__all__ = ["drive_efficiency", "efficiency_rows", "mie_threshold_db", "threshold_study"]


def _epoch_errors(route, k, rngs, refines):

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

    attributes("route", route, ("paths", "config"), "a signal_route.SignalRoute")
    progress = boolean("progress", progress)
    epochs = [integer("epochs", k, minimum=0) for k in np.atleast_1d(epochs).tolist()]
    if not epochs:
        raise ValueError("epochs: need at least one epoch")
    n = integer("n_snapshots", n_snapshots, minimum=1)
    refines = tuple(sequence("refines", refines, empty=True))
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
    rows = sequence("rows", rows)
    path = text("path", path)
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


def threshold_study(
    route, epochs, snr_offsets_db, n_snapshots: int, seed: int, *, progress: bool = False
) -> list[dict]:
    """The ML route against its bound as the SNR falls and the range grows: where it leaves the
    bound (the threshold region) and whether its own test (``PathEstimates.fit_ok``) says so.

    For every epoch of ``epochs`` and offset of ``snr_offsets_db`` (the route's SNR lowered or
    raised, :class:`~tunnelkit.signal_route.SignalRoute` ``snr_offset_db``), ``n_snapshots``
    seeded snapshots, extracted by the route's default (ML) extraction; errors over the CRLB at
    that SNR (:func:`tunnelkit.evaluation.bound_errors`). One row per (epoch, offset, true path):
    ``epoch``, ``range [m]``, ``SNR offset [dB]``, ``path``, ``integrated SNR [dB]`` (``eta =
    P_t |gain|^2 M Nf Nt / N0``), ``RMS/CRLB d``, ``... v``, ``... direction``, ``... w`` (over
    the snapshots in which the path was found), ``beyond 6 sigma`` (share of snapshots with this
    path beyond 6 sigma or missed) and ``flagged`` (share of snapshots the extraction flagged).
    """
    from dataclasses import replace

    attributes("route", route, ("paths", "config"), "a signal_route.SignalRoute")
    progress = boolean("progress", progress)
    epochs = [integer("epochs", k, minimum=0) for k in np.atleast_1d(epochs).tolist()]
    offsets = np.atleast_1d(finite_array("snr_offsets_db", snr_offsets_db))
    if offsets.ndim != 1:
        raise ValueError(f"snr_offsets_db: expected a list of offsets, got shape {offsets.shape}")
    offsets = offsets.tolist()
    if not epochs or not offsets:
        raise ValueError("epochs, snr_offsets_db: need at least one of each")
    if not np.all(np.isfinite(offsets)):
        raise ValueError(f"snr_offsets_db: expected finite values, got {offsets}")
    n = integer("n_snapshots", n_snapshots, minimum=1)
    grid = [(k, o) for k in epochs for o in offsets]
    it = list(zip(grid, spawn_rngs(seed, len(grid))))
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(it, desc="threshold study", leave=False)
    rows = []
    for (k, off), rng in it:
        r_off = replace(route, snr_offset_db=off)
        arr, paths = r_off.paths(k)
        bound = path_crlb(paths, arr, r_off.config, snr_offset_db=off)
        src = np.stack([arr.to_local(p.source) for p in paths])
        errs, flags = [], []
        for r in rng.spawn(n):
            snap = r_off.snapshot(paths, arr, r)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                est = r_off.extract(snap.H, arr, len(paths))
            d_true = np.array([p.length for p in paths]) + C * snap.clock_bias
            v_true = np.array([p.velocity for p in paths])
            errs.append(bound_errors(est, d_true, v_true, src, bound))
            flags.append(est.fit_ok is False)
        e = np.stack(errs)  # (n, L, 4)
        eta = (
            np.abs([p.gain for p in paths]) ** 2
            * r_off.config.tx_power
            * snap.H.size
            / (r_off.config.noise_power / float(db2lin(off)))
        )
        rng_ue = float(np.linalg.norm(route.trajectory.position[k] - arr.origin))
        for j, p in enumerate(paths):
            ej = e[:, j]
            found = np.all(np.isfinite(ej), axis=1)
            rms = np.sqrt(np.mean(ej[found] ** 2, axis=0)) if found.any() else np.full(4, np.nan)
            rows.append(
                {
                    "epoch": k,
                    "range [m]": rng_ue,
                    "SNR offset [dB]": off,
                    "path": p.surface_kind,
                    "integrated SNR [dB]": float(10 * np.log10(eta[j])),
                    **{
                        f"RMS/CRLB {q}": float(x) for q, x in zip(("d", "v", "direction", "w"), rms)
                    },
                    "beyond 6 sigma": float(np.mean(np.any(~(np.abs(ej) <= 6.0), axis=1))),
                    "flagged": float(np.mean(flags)),
                }
            )
    return rows


def mie_threshold_db(n_cells: int) -> float:
    """Integrated SNR ``eta`` [dB] below which a maximum-likelihood search over ``n_cells``
    independent cells (beams x delays x Dopplers, ``M Nf Nt``) starts to pick a noise cell over
    the path: the probability of such an outlier is about ``n_cells e^{-eta}`` (each noise cell
    of the normalised periodogram is exponential with mean 1, the path's cell is ``eta`` above
    it), 1/2 at ``eta = ln(2 n_cells)``. This is where the method of interval errors and the
    Ziv-Zakai bound leave the CRLB: above it they coincide with it, below it the mean square
    error is set by the outliers (the width of the search space), not by the local curvature."""
    K = integer("n_cells", n_cells, minimum=1)
    return float(10 * np.log10(np.log(2.0 * K)))
