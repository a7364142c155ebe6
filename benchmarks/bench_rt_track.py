"""Where the track error on the ray-traced channel comes from (JAVELIN-L, our design, ML route).

One or more traced drives (``channel="sionna"``, diffuse power as the fit's noise floor, every
epoch's measurements passed on as ``bench_rt_tables.py --model-error-share 0.1858`` does: all
flagged epochs pass there) are measured once; the same measurements are then scored by JAVELIN
(``designs.ours_ml``) in variants that each remove one suspect, from outside the tracker:

* ``measured``: what the tables score;
* ``no spurious``: the measurements matched to no true first-order path dropped (the match of
  :func:`tunnelkit.evaluation.match_paths`: an oracle, to size the suspect);
* ``LoS only``: only the measurement matched to the LoS kept (oracle);
* ``true LoS first``: the measurement matched to the LoS moved to row 0 (what Algorithm 1's
  earliest-arrival order and the tracker's first fix take for the LoS);
* ``geometry test``: the paths the per-snapshot geometry-consistency test rejects dropped
  (:func:`tunnelkit.path_consistency.epoch_consistency` with model-error floors, no oracle);
* ``no curvature``: every path's curvature removed (far-field: angles and delay only);
* ``all-path sigmas`` / ``kept-path sigmas``: the design's measurement noise set to the RMS
  extraction error on these traced drives (:func:`tunnelkit.simulation.analysis.extraction_errors`,
  :func:`~tunnelkit.tracking.javelin.measured.design_from_errors`) of every matched path, or of
  the paths the geometry test keeps; in-sample unless ``--sigmas`` / ``--sigmas-kept`` give them
  (measured on another drive or seed), alone and with the geometry test;
* ``sigmas x S``: the design's measurement sigmas scaled by ``S`` (``--scale``).

Per epoch of the ``measured`` variant (``--epochs``) it prints the 2-D error, the number of
measurements, how many were spurious, whether row 0 is the LoS, the delay error of the earliest
measurement, and which measurement the UE took as its LoS (by association or eq. 61's test).
``--store FILE`` keeps the simulated drives (tensors dropped) for a re-scoring without tracing.

    python benchmarks/bench_rt_track.py --scenario italiano2026-straight --runs 3 --seed 0 \
        --scale 10 --store /tmp/straight-0.pkl
    python benchmarks/bench_rt_track.py --scenario italiano2026-slalom --runs 3 --seed 0 \
        --sigmas 9.328 8.583 33.71 1.078 --sigmas-kept 5.216 6.896 36.27 0.6224 --scale 10
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.constants import C
from tunnelkit.path_consistency import epoch_consistency
from tunnelkit.runner import run_trials
from tunnelkit.simulation import drives, evaluate
from tunnelkit.simulation.analysis import extraction_errors
from tunnelkit.simulation.collect import simulate_condition
from tunnelkit.tracking.javelin import designs
from tunnelkit.tracking.javelin.measured import design_from_errors

SIGMAS = ("sigma_phi", "sigma_psi", "sigma_kappa", "sigma_delta_d")

NUISANCE = {"diffuse_floor": True}


def traced_drive(scenario: str, seed: int, runs: int) -> list[tuple]:
    """``runs`` drives of ``scenario`` on the traced channel (drive ``i`` from the ``i``-th child
    of ``seed``, as the tables draw them): ``[(DriveData, [Epoch, ...]), ...]`` with every
    flagged epoch's measurements passed on."""
    original = drives.path_measurements
    out = []

    def trial(cond, rng):
        eps = []

        def adapter(ep, route):
            eps.append(ep)
            pm, reason = original(ep, route)
            if reason == drives.FLAGGED:
                m = ep.measurements
                pm = drives.PathMeasurements.from_arrays(
                    m.phi, m.psi, m.kappa, m.d, m.v, warn=False, min_d=route.min_d
                )
                reason = None
            return pm, reason

        def light(ep):  # the tensor dropped (kept: truth, estimates, measurements, clock bias)
            snap = replace(ep.snapshot, H=ep.snapshot.H[:, :1, :1].copy())
            return replace(ep, snapshot=snap)

        drives.path_measurements = adapter
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                d = simulate_condition(
                    scenario, None, ("ml",), cond, rng, channel="sionna", nuisance=NUISANCE
                )["ml"]
        finally:
            drives.path_measurements = original
        return d, [light(ep) for ep in eps]

    res = run_trials(trial, runs, seed, inputs=["L"] * runs)
    out.extend(res)
    return out


def subset_drive(drive, eps, keep) -> object:
    """``drive`` with epoch ``k``'s measurements reduced to the rows of ``ep.measurements`` that
    ``keep(ep, pm)`` returns (in the order given; rows Algorithm 1's adapter dropped stay out)."""
    epochs, tidx = [], []
    for ep, pm, ti in zip(eps, drive.epochs, drive.truth_index, strict=True):
        if pm is None:
            epochs.append(None)
            tidx.append(ti)
            continue
        want = np.asarray(keep(ep, pm), int)  # rows of ep.measurements, in the order wanted
        src = np.asarray(pm.source, int)
        rows = np.array([np.flatnonzero(src == r)[0] for r in want if np.any(src == r)], int)
        epochs.append(pm.subset(rows) if rows.size else None)
        tidx.append(np.asarray(ti)[rows] if rows.size else np.zeros(0, int))
    return replace(drive, epochs=epochs, truth_index=tidx)


def los_row(ep) -> int | None:
    los = [i for i, p in enumerate(ep.paths) if p.kind == "los"]
    hit = np.flatnonzero(np.asarray(ep.truth_index) == los[0]) if los else []
    return int(hit[0]) if len(hit) else None


def geometry_keep(ep, route, floors) -> np.ndarray:
    """Rows the geometry-consistency test keeps (the bound's sigmas taken as zero: the model-error
    floors ``floors = (angle [rad], range [m])`` alone, :func:`epoch_consistency`)."""
    m = ep.measurements
    if len(m) < 2:
        return np.arange(len(m))
    res = epoch_consistency(ep, route, bound=False, floor_angle=floors[0], floor_range=floors[1])
    return np.flatnonzero(res["keep"])


def variants(drive, eps, route, floors) -> dict:
    all_rows = lambda ep, pm: np.arange(len(pm.phi))  # noqa: E731
    out = {"measured": drive}
    out["no spurious"] = subset_drive(
        drive, eps, lambda ep, pm: np.flatnonzero(np.asarray(ep.truth_index) >= 0)
    )
    out["LoS only"] = subset_drive(
        drive, eps, lambda ep, pm: [] if los_row(ep) is None else [los_row(ep)]
    )

    def los_first(ep, pm):
        j = los_row(ep)
        rows = all_rows(ep, pm)
        return rows if j is None else np.r_[j, np.delete(rows, j)]

    out["true LoS first"] = subset_drive(drive, eps, los_first)
    out["no curvature"] = no_curvature(drive)
    out["geometry test"] = subset_drive(
        drive,
        eps,
        lambda ep, pm: geometry_keep(ep, route, floors),
    )
    return out


def no_curvature(drive):
    """``drive`` with every path's curvature removed (far-field: the tracker uses its angles and
    delay only)."""
    eps = [
        None if pm is None else replace(pm, kappa=np.full_like(pm.kappa, np.nan))
        for pm in drive.epochs
    ]
    return replace(drive, epochs=eps)


def epoch_table(drive, eps, ev) -> list[str]:
    lines = []
    err = np.linalg.norm(ev.estimates[:, :2] - drive.truth[:, :2], axis=1)
    for k, ep in enumerate(eps):
        ti = np.asarray(ep.truth_index)
        j = los_row(ep)
        d0_err = np.nan
        if len(ep.measurements) and ti.size and ti[0] >= 0:
            p = ep.paths[ti[0]]
            d0_err = ep.measurements.d[0] - p.length - C * ep.snapshot.clock_bias
        rep = ev.run.reports[k]
        lp = None if rep.manage is None else rep.manage.los_path
        src = np.asarray(rep.paths.source, int)
        lp = None if lp is None or lp < 0 else int(src[lp])  # a row of ep.measurements
        ue_ok = "-" if lp is None else ("LoS" if lp == j else f"row{lp}")
        kinds = ",".join(ep.paths[i].surface_kind[:2] if i >= 0 else "??" for i in ti)
        lines.append(
            f"  k={k:2d} err {err[k]:6.3f} m  n={len(ti):2d} spurious={int(np.sum(ti < 0))} "
            f"row0={'LoS' if j == 0 else 'not LoS'} d0_err={100 * d0_err:7.1f} cm "
            f"UE<-{ue_ok:5s} tracks={len(rep.ids)} [{kinds}]"
        )
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--scale", type=float, nargs="*", default=[3.0, 10.0])
    ap.add_argument("--epochs", action="store_true", help="print the per-epoch table")
    ap.add_argument(
        "--sigmas", type=float, nargs=4, default=None,
        help="phi_deg psi_deg kappa_m delta_d_m: a design with these sigmas (else the rows "
        "measured on these drives, in-sample)",
    )  # fmt: skip
    ap.add_argument("--sigmas-kept", type=float, nargs=4, default=None,
                    help="as --sigmas, for the design fed the geometry-kept paths")  # fmt: skip
    ap.add_argument(
        "--store", default=None, help="a pickle of the drives: read if present, else written"
    )
    ap.add_argument("--floor-angle-deg", type=float, default=0.5)
    ap.add_argument("--floor-range", type=float, default=0.3)
    a = ap.parse_args(argv)
    route = drives.scenario_route(a.scenario, "exact", "sionna", NUISANCE)
    floors = (np.radians(a.floor_angle_deg), a.floor_range)
    t0 = time.perf_counter()
    store = Path(a.store) if a.store else None
    if store is not None and store.is_file():
        with store.open("rb") as f:
            data = pickle.load(f)
        print(f"drives read from {store}")
    else:
        data = traced_drive(a.scenario, a.seed, a.runs)
        if store is not None:
            with store.open("wb") as f:
                pickle.dump(data, f)
    print(
        f"{a.scenario} seed {a.seed}: {a.runs} traced drive(s) in {time.perf_counter() - t0:.0f} s"
    )
    base = designs.ours_ml()
    cfg = base.config
    scores: dict[str, list] = {}
    geo = [variants(d, e, route, floors)["geometry test"] for d, e in data]

    def sigma_design(rows, given, what):
        for row in rows:
            print(f"  extraction error, {what}: " + ", ".join(
                f"{x:.4g}" if isinstance(x, float) else str(x) for x in row))  # fmt: skip
        if given is None:
            return design_from_errors(rows, base=base), "in-sample"
        return design_from_errors([["all", 0, *given]], base=base), "given"

    all_d, how_all = sigma_design(extraction_errors([d for d, _ in data])[1], a.sigmas, "all paths")
    kept_d, how_kept = sigma_design(extraction_errors(geo)[1], a.sigmas_kept, "kept paths")
    for lab, d in (
        (f"all-path sigmas ({how_all})", all_d),
        (f"kept-path sigmas ({how_kept})", kept_d),
    ):
        print(f"  {lab}: " + ", ".join(f"{k} {getattr(d.config, k):.4g}" for k in SIGMAS))
    for r, (drive, eps) in enumerate(data):
        for name, dv in variants(drive, eps, route, floors).items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ev = evaluate(dv, base, keep_reports=True)
            scores.setdefault(name, []).append(ev.metrics)
            if name == "measured" and a.epochs:
                print(f"run {r}, measured, per epoch:")
                print("\n".join(epoch_table(drive, eps, ev)))
        for name, dv, des in (
            ("no curvature + geometry test", no_curvature(geo[r]), base),
            ("all-path sigmas", drive, all_d),
            ("all-path sigmas + geometry test", geo[r], all_d),
            ("kept-path sigmas + geometry test", geo[r], kept_d),
            ("kept-path sigmas, no curvature + geometry test", no_curvature(geo[r]), kept_d),
        ):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                scores.setdefault(name, []).append(evaluate(dv, des).metrics)
        for s in a.scale:
            d = base.with_(
                sigma_phi=s * cfg.sigma_phi,
                sigma_psi=s * cfg.sigma_psi,
                sigma_kappa=s * cfg.sigma_kappa,
                sigma_delta_d=s * cfg.sigma_delta_d,
            )
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                scores.setdefault(f"sigmas x {s:g}", []).append(evaluate(drive, d).metrics)
        kept = sum(0 if pm is None else len(pm.phi) for pm in geo[r].epochs)
        print(f"run {r}: the geometry test keeps {kept} measurements")
        n_meas = sum(len(np.asarray(ep.truth_index)) for ep in eps)
        n_spur = sum(int(np.sum(np.asarray(ep.truth_index) < 0)) for ep in eps)
        n_row0 = sum(los_row(ep) == 0 for ep in eps)
        print(
            f"run {r}: {len(eps)} epochs, {n_meas} measurements, {n_spur} spurious, "
            f"row 0 is the LoS in {n_row0} epochs"
        )
    for name, v in scores.items():
        rm = [m["rmse_2d_m"] for m in v]
        ma = np.mean([m["mae_2d_m"] for m in v])
        print(
            f"  {name:46s} 2-D RMSE {np.mean(rm):.3f} m, MAE {ma:.3f} m  runs {np.round(rm, 3).tolist()}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
