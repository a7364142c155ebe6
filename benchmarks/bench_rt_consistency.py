"""The geometry-consistency test of one snapshot's paths on both channels.

Per epoch of a drive and per draw (noise and clock bias drawn, LoS kept), the ML route's
estimates (``refine="ml"``, ``L`` known; on the ray-traced channel tested against noise + diffuse
power) go through :func:`tunnelkit.consistency.geometry_consistency` with the CRLB at the
estimate as the bound (world-frame azimuth, elevation, range; computed whatever the fit's own
verdict) and no model-error floor, at the false-alarm rate ``--pfa``:

* image channel (eq. 1 is the truth): the snapshot test's false-alarm rate, over every snapshot
  and over the snapshots whose fit passed its own residual test;
* ray-traced channel: per snapshot the largest error of a matched path against the truth in
  bound standard deviations (azimuth, elevation, range after the true clock bias), the share
  of snapshots beyond ``6`` of them, and the share of those the test flags;
* with the model-error floors ``--floor-angle-deg`` / ``--floor-range`` (the bound taken as zero,
  the pre-filter of ``bench_rt_track.py``): per channel the share of paths matched to a true
  first-order path and of spurious paths (matched to none) that the per-path test drops.

    python benchmarks/bench_rt_consistency.py --scenario italiano2026-straight --draws 1
    python benchmarks/bench_rt_consistency.py --false-alarm --draws 5 --seeds 0 1

``--false-alarm``: on the image channel only, the snapshot test's false-alarm rate with the
bound's joint covariance (correlations within and between paths) beside the per-component sigmas
alone, on the same snapshots, with exact (Clopper-Pearson) 95 % intervals.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.stats import chi2, kstest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.constants import C
from tunnelkit.path_consistency import bound_sigmas, epoch_consistency, rate_interval
from tunnelkit.signal_route import SignalRoute


def truth_errors(ep, sig) -> np.ndarray:
    """Per matched path the largest |error| in bound sd over (azimuth, elevation, range)."""
    m, ti = ep.measurements, np.asarray(ep.truth_index)
    out = []
    for j, i in enumerate(ti):
        if i < 0:
            continue
        p = ep.paths[i]
        e = np.array(
            [
                np.angle(np.exp(1j * (m.phi[j] - p.azimuth))),
                m.psi[j] - p.elevation,
                m.d[j] - p.length - C * ep.snapshot.clock_bias,
            ]
        )
        out.append(np.max(np.abs(e) / sig[j]))
    return np.array(out)


def study(route: SignalRoute, draws: int, pfa: float, floors, rng) -> dict:
    acc = {"flag": [], "fit_ok": [], "worst": [], "drop_true": [], "drop_spur": []}
    for k in range(len(route.trajectory)):
        for _ in range(draws):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ep = route.epoch(k, rng, refine="ml")
            m = ep.measurements
            if len(m) < 2:
                continue
            try:
                sig = bound_sigmas(ep.estimates, ep.array, route.config)
                res = epoch_consistency(ep, route, pfa=pfa)
            except (np.linalg.LinAlgError, ValueError):  # Fisher information singular there
                acc["skipped"] = acc.get("skipped", 0) + 1
                continue
            acc["flag"].append(not res["consistent"])
            acc["fit_ok"].append(bool(getattr(ep.estimates, "fit_ok", True)))
            te = truth_errors(ep, sig)
            acc["worst"].append(te.max() if te.size else np.nan)
            fl = epoch_consistency(
                ep, route, bound=False, pfa=pfa, floor_angle=floors[0], floor_range=floors[1]
            )
            ti = np.asarray(ep.truth_index)
            acc["drop_true"].extend((~fl["keep"][ti >= 0]).tolist())
            acc["drop_spur"].extend((~fl["keep"][ti < 0]).tolist())
    skipped = acc.pop("skipped", 0)
    return {**{k: np.array(v) for k, v in acc.items()}, "skipped": skipped}


def false_alarms(scenarios, seeds, draws: int, pfa: float) -> dict:
    """Image channel (eq. 1 is the truth): per scenario and seed, ``draws`` snapshots per epoch
    (noise and clock bias drawn, LoS kept, ML route), the snapshot test's verdict with the
    bound's joint covariance (:func:`epoch_consistency`, ``joint=True``) and with the
    per-component sigmas alone (``joint=False``) on the same snapshots."""
    out = {}
    for sc in scenarios:
        route = SignalRoute.from_scenario(sc)
        for seed in seeds:
            rng = np.random.default_rng(seed)
            acc = {"joint": [], "diag": [], "fit_ok": [], "skipped": 0}
            for k in range(len(route.trajectory)):
                for _ in range(draws):
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        ep = route.epoch(k, rng, refine="ml")
                    if len(ep.measurements) < 2:
                        continue
                    try:
                        rj = epoch_consistency(ep, route, pfa=pfa)
                        rd = epoch_consistency(ep, route, pfa=pfa, joint=False)
                    except (np.linalg.LinAlgError, ValueError):
                        acc["skipped"] += 1
                        continue
                    acc["joint"].append(not rj["consistent"])
                    acc["diag"].append(not rd["consistent"])
                    acc.setdefault("p_joint", []).append(chi2.sf(rj["statistic"], rj["dof"]))
                    acc.setdefault("p_diag", []).append(chi2.sf(rd["statistic"], rd["dof"]))
                    acc["fit_ok"].append(bool(getattr(ep.estimates, "fit_ok", True)))
            out[(sc, seed)] = {k: np.array(v) if isinstance(v, list) else v for k, v in acc.items()}
    return out


def report_false_alarms(res: dict, pfa: float) -> None:
    tot = {"joint": [0, 0], "diag": [0, 0]}
    for (sc, seed), r in res.items():
        line = f"{sc} seed {seed}: {r['joint'].size} snapshots ({r['skipped']} skipped)"
        for v in ("joint", "diag"):
            k, n = int(r[v].sum()), r[v].size
            tot[v][0] += k
            tot[v][1] += n
            lo, hi = rate_interval(k, n)
            line += f"; {v} {k}/{n} = {k / n:.4f} [95 % CI {lo:.4f}, {hi:.4f}]"
        print(line)
    for v, (k, n) in tot.items():
        lo, hi = rate_interval(k, n)
        pv = np.concatenate([r[f"p_{v}"] for r in res.values()])
        q = np.quantile(pv, [0.01, 0.05, 0.1, 0.5])
        print(
            f"  all, {v}: {k}/{n} = {k / n:.4f} [95 % CI {lo:.4f}, {hi:.4f}] against {pfa:g}; "
            f"p-values (uniform if the statistic is chi-square): quantiles 1/5/10/50 % "
            f"{np.round(q, 4).tolist()}, KS p {kstest(pv, 'uniform').pvalue:.3g}"
        )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--channels", nargs="+", default=["image", "sionna"])
    ap.add_argument("--draws", type=int, default=1)
    ap.add_argument("--pfa", type=float, default=0.01)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--floor-angle-deg", type=float, default=0.5)
    ap.add_argument("--floor-range", type=float, default=0.3)
    ap.add_argument("--false-alarm", action="store_true",
                    help="image channel only: the snapshot test's false-alarm rate, joint "
                    "covariance against per-component sigmas, on --scenarios x --seeds")  # fmt: skip
    ap.add_argument("--scenarios", nargs="+",
                    default=["italiano2026-straight", "italiano2026-slalom"])  # fmt: skip
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    a = ap.parse_args(argv)
    if a.false_alarm:
        t0 = time.perf_counter()
        res = false_alarms(a.scenarios, a.seeds, a.draws, a.pfa)
        print(f"false alarms, image channel, pfa {a.pfa:g}, {a.draws} draw(s) per epoch: "
              f"{time.perf_counter() - t0:.0f} s")  # fmt: skip
        report_false_alarms(res, a.pfa)
        return 0
    floors = (np.radians(a.floor_angle_deg), a.floor_range)
    for chan in a.channels:
        route = SignalRoute.from_scenario(a.scenario, channel=chan)
        if chan == "sionna":
            route = route.with_options(diffuse_floor=True)
        t0 = time.perf_counter()
        r = study(route, a.draws, a.pfa, floors, np.random.default_rng(a.seed))
        wall = time.perf_counter() - t0
        n = r["flag"].size
        ok = r["fit_ok"]
        beyond = r["worst"] > 6
        print(
            f"{a.scenario} channel={chan}: {n} snapshots in {wall:.0f} s, pfa {a.pfa:g} "
            f"({r['skipped']} skipped: the bound at the estimate undefined)"
        )
        print(
            f"  snapshot test flags {r['flag'].mean():.3f} of all, "
            f"{r['flag'][ok].mean() if ok.any() else np.nan:.3f} of the {ok.sum()} fits passing "
            f"their residual test"
        )
        print(
            f"  worst matched-path error: median {np.nanmedian(r['worst']):.3g} bound sd; "
            f"{beyond.sum()} of {n} snapshots beyond 6 sd, of which the test flags "
            f"{r['flag'][beyond].mean() if beyond.any() else np.nan:.3f}; of the others it flags "
            f"{r['flag'][~beyond].mean() if (~beyond).any() else np.nan:.3f}"
        )
        dt, ds = r["drop_true"], r["drop_spur"]
        print(
            f"  floors {a.floor_angle_deg:g} deg / {a.floor_range:g} m: drops {dt.mean():.3f} of "
            f"{dt.size} true-matched paths, "
            f"{ds.mean() if ds.size else np.nan:.3f} of {ds.size} spurious paths"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
