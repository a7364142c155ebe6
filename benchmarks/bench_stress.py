"""The default extraction stressed over its whole operating range, and its failure test.

Cases (``CASES``): both drives (``italiano2026-straight`` and ``-slalom``) on a 300 m variant of
the tunnel whose trajectory runs from x = 122 m to x = 0.5 m (``long_route``: the ranges the
presets' 100 m tunnel cannot reach), UE ranges 4-8 m (near the base station, where the ceiling
and road images of the tilted arrays approach end-fire; 4.1 m is the closest a UE in the lane
gets), 15-45 m (the presets' own drive) and 80-120 m (clustered images a few degrees and
centimetres from the LoS), at the presets' SNR and 10 and 20 dB below it; and free-space scenes
in front of the paper's 10 x 10 URA: ``L = 10`` sources 2-8 m away, and a close pair (two sources
a third of a beamwidth and a third of the delay resolution apart, among four).

Per case, ``n`` snapshots (noise, clock bias and the epoch within the range band drawn from the
seed): RMS(error / CRLB) per parameter over the matched paths, ``d`` (with the clock bias),
``v``, ``direction`` (angle), ``w = 1 / kappa`` (the curvature the fit estimates, normalised by
its bound ``sigma_kappa / kappa^2``; it stays finite for a far-field estimate), the share of
paths beyond 6 sigma in any parameter (a missed path counts as beyond), and for the failure test
(``PathEstimates.fit_ok``) the share of bad snapshots (a path beyond 6 sigma) flagged and of good
ones flagged. The CRLB takes the SNR the tensor was made with (``snr_offset_db``).

Each bad snapshot is also told apart as a *search* failure or an *identifiability* limit: the
fit is restarted at the truth (no re-seeding) and the cost it reaches compared with the
estimate's; when the truth's basin is significantly more likely (the likelihood-ratio
``2 Delta cost / sigma^2`` above the 99 % quantile of chi-square with ``5 L`` degrees of
freedom) the search missed the maximum of the likelihood, otherwise the data cannot tell the
estimate from the truth (two paths closer than they can be resolved, or a path at the noise),
and the CRLB of the model with every path resolved is not a bound the estimate can reach:
such snapshots are judged by the flag (the resolution test, ``MLFit.reason``), not by the bound.
:func:`attainability` lists every bad snapshot above the threshold with that verdict and its
Fisher-information reason (the separation at the truth's fit and at the estimate against
``RESOLVE_Z``) and states the goal per case with and without the snapshots not attainable.
The estimate's own resolution verdict (``PathEstimates.unresolved``: a pair that one path
explains, the pair test's GLRT, or closer than ``RESOLVE_Z`` at the fit) moves a snapshot's
paths above the threshold into their own column of :func:`threshold_table` ("unresolved":
counted, with how many lie beyond 6 sigma of the resolved model's bound, never dropped): the
goal is stated on the others. :func:`attainability` gives each not-attainable snapshot's
smallest pair ``llr`` and whether it was reported.
:func:`merged_table` judges each pair the estimate reports unresolved against the bound it can
reach instead: the CRLB of ONE path at the true pair's power-weighted centroid, jointly with the
other paths (:func:`tunnelkit.extraction.bounds.merged_crlb`), the estimate's two paths taken
at their own power-weighted centroid (:func:`merged_errors`): share beyond 6 sigma, RMS(error /
bound) per parameter. The table also gives the share of unflagged snapshots with a path beyond 6 sigma (what a
tracker that skips flagged epochs still sees), and the threshold SNR: the lowest SNR offset
at which every drive case meets the goal (<= 2 % beyond 6 sigma, RMS <= 1.5) on all its
snapshots, the paths the estimate itself reports unresolved judged apart (:func:`merged_table`):
a statement that needs no truth, beside the per-snapshot one below.

The threshold region is also stated per snapshot, from the bound at the truth
(:func:`above_threshold`, :func:`tunnelkit.extraction.ml.below_threshold`): a snapshot is below the
threshold when a true path's post-integration SNR (its log-likelihood ratio against noise at the
true parameters) is below the threshold SNR of the method of interval errors (the SNR at which
the search puts the path in a wrong one of the tensor's ``M Nf Nt`` cells with probability 1 %,
:func:`tunnelkit.extraction.ml.snr_threshold`: 28.5, 14.5 dB, for the presets' tensor), or a true
path lies fewer than ``RESOLVE_Z`` = 5 standard deviations of the difference from another (the
statistical resolution limit of the 5-parameter test; Smith 2005, Liu & Nehorai 2007).
:func:`threshold_table` gives per case the snapshots above (beyond 6 sigma, RMS: goal <= 2 %,
<= 1.5) and below (bad flagged >= 95 %, good flagged <= 5 %), and how often the estimate's own
verdict (``PathEstimates.below_threshold`` at the fit) agrees with the truth's.

``python benchmarks/bench_stress.py --seed S --snapshots 30`` prints the table; the
settings were chosen on seed 23 (the design seed); ``HELD_OUT_SEED`` is a seed the settings
were never tried on before the final run (the seed 2026 of the session before was seen while
choosing these; the split of an unresolved pair, ``ml.split.PAIR_GAIN``, was chosen on seed 23
alone and then run once on 8191 and on 4242, a seed never run before; the resolution verdict,
``PathEstimates.unresolved`` with ``ml.PAIR_LLR`` from its Monte-Carlo null, was decided on seed
23 and then run once on 8191, 4242 and 30011, a seed never run before; the split of the closest
pair while the residual test fails, ``ml.fitting._split_weak(flagged=)``, was found on a 30011
search miss, tested on a synthetic cluster and run once on 61417, a seed never run before).
``make bench``
runs ``report()`` (both seeds, ``TUNNELKIT_BENCH_STRESS`` snapshots per case, default 30).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.stats import chi2
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run import Case

from tunnelkit import evaluation, extraction, scenarios, signal_route
from tunnelkit.constants import C
from tunnelkit.extraction import ml
from tunnelkit.montecarlo import spawn_rngs

PARAMS = ("d", "v", "direction", "w")
DESIGN_SEED, HELD_OUT_SEED = 23, 8191
DRIVES = ("italiano2026-straight", "italiano2026-slalom")
BANDS = {"near": (4.0, 8.0), "mid": (15.0, 45.0), "far": (80.0, 120.0)}
#: (name, drive or scene kind, band, SNR offset [dB])
CASES = [
    *[
        (f"{d.split('-')[1]} {b} {off:+.0f} dB", d, b, off)
        for d in DRIVES
        for b, off in (
            ("near", 0.0),
            ("mid", 0.0),
            ("far", 0.0),
            ("mid", -10.0),
            ("far", -10.0),
            ("near", -20.0),
            ("mid", -20.0),
            ("far", -20.0),
        )
    ],
    ("scene L=10", "scene10", None, 0.0),
    ("scene close pair", "pair", None, 0.0),
]

_ROUTES: dict = {}


def long_route(drive: str, snr_offset_db: float = 0.0) -> signal_route.SignalRoute:
    """``drive`` in a 300 m tunnel, the trajectory from x = 122 m to x = 0.5 m (same lane, speed
    and epoch period), at ``snr_offset_db``."""
    key = (drive, snr_offset_db)
    if key not in _ROUTES:
        sc = scenarios.with_values(
            scenarios.load_scenario(drive),
            {"tunnel.length": 300.0, "trajectory.x_start": 122.0, "trajectory.x_end": 0.5},
        )
        _ROUTES[key] = signal_route.SignalRoute.from_scenario(sc, snr_offset_db=snr_offset_db)
    return _ROUTES[key]


def _errors(est, d_true, v_true, src, bound) -> np.ndarray:
    """(L_true, 4) errors over the bound, ``d, v, direction, w``; ``inf`` for a missed path
    (:func:`tunnelkit.evaluation.bound_errors`)."""
    return evaluation.bound_errors(est, d_true, v_true, src, bound)


def _in_unresolved_pair(est, d_true, v_true, src, bound) -> np.ndarray:
    """Per true path (L_true,): the snapshot's estimate reports an unresolved pair
    (``PathEstimates.unresolved >= 0``, the CRLB of its paths all resolved is not a bound it
    claims to reach). Every path of such a snapshot is marked, not only the two the assignment
    gives the pair: two paths closer than the data resolve swap identities with their neighbours
    (on the design seed the path beyond 6 sigma of a not-attainable snapshot was assigned to
    another estimate than the pair's)."""
    n = len(d_true)
    if est.unresolved is None or not np.any(est.unresolved >= 0):
        return np.zeros(n, bool)
    return np.ones(n, bool)


def merged_errors(est, alpha, src, d_true, v_true, pos, cfg, noise_power, bound) -> np.ndarray:
    """(P, 4) errors of each pair the estimate reports unresolved (``PathEstimates.unresolved``)
    against the bound it can reach: its two estimates' power-weighted centroid against the true
    pair's (:func:`tunnelkit.extraction.bounds.merged_path`), over the CRLB of one path there
    jointly with the other true paths (:func:`~tunnelkit.extraction.bounds.merged_crlb`),
    ``d, v, direction, w``. The true pair: the two true paths the estimates are assigned to (the
    Hungarian method on the errors over the resolved model's ``bound``, as
    :func:`tunnelkit.evaluation.bound_errors`); ``inf`` when both go to one true path or none."""
    from scipy.optimize import linear_sum_assignment

    from tunnelkit.extraction.bounds import merged_crlb

    un = est.unresolved
    if un is None or not np.any(un >= 0):
        return np.zeros((0, 4))
    pairs = sorted({tuple(sorted((a, int(b)))) for a, b in enumerate(un) if b >= 0})
    r = np.linalg.norm(src, axis=1)
    u = src / r[:, None]
    w_est = np.nan_to_num(1.0 / np.asarray(est.kappa_nf, float), nan=0.0)
    e = np.stack(
        [
            (est.d[:, None] - d_true[None]) / bound["d"][None],
            (est.v[:, None] - v_true[None]) / bound["v"][None],
            np.arccos(np.clip(est.direction @ u.T, -1, 1)) / bound["direction"][None],
            (w_est[:, None] - 1 / r[None]) / (bound["kappa"] / r**2)[None],
        ],
        axis=-1,
    )
    rows_, cols = linear_sum_assignment(
        np.sum(np.minimum(np.nan_to_num(e, nan=1e6) ** 2, 1e12), -1)
    )
    to_true = dict(zip(rows_.tolist(), cols.tolist()))
    mf = -2 * np.pi * cfg.tone_spacing * np.asarray(d_true) / C
    mt = 2 * np.pi * cfg.fc * cfg.symbol_period * np.asarray(v_true) / C
    out = []
    for a, b in pairs:
        i, j = to_true.get(a), to_true.get(b)
        if i is None or j is None or i == j:
            out.append(np.full(4, np.inf))
            continue
        m = merged_crlb(
            alpha, src, pos, mf, mt, cfg.fc, cfg.n_tones, cfg.n_symbols, noise_power, (i, j)
        )
        p = np.abs(est.alpha[[a, b]]) ** 2
        p = p / p.sum()
        ue = p @ est.direction[[a, b]]
        ue = ue / np.linalg.norm(ue)
        d_c = C / (2 * np.pi * cfg.tone_spacing)
        v_c = C / (2 * np.pi * cfg.fc * cfg.symbol_period)
        out.append(
            [
                (p @ est.d[[a, b]] - (-d_c * m["mu_f"])) / (d_c * m["sd_mu_f"]),
                (p @ est.v[[a, b]] - v_c * m["mu_t"]) / (v_c * m["sd_mu_t"]),
                np.arccos(np.clip(ue @ m["direction"], -1, 1)) / m["sd_direction"],
                (p @ w_est[[a, b]] - m["w"]) / (m["sd_kappa"] * m["w"] ** 2),
            ]
        )
    return np.array(out, float).reshape(-1, 4)


def _drive_snapshot(drive, band, off, rng, search):
    route = long_route(drive, off)
    pos = route.trajectory.position
    dist = np.linalg.norm(pos - route.arrays[0].origin, axis=1)
    lo, hi = BANDS[band]
    k = int(rng.choice(np.flatnonzero((dist >= lo) & (dist <= hi))))
    arr, paths = route.paths(k)
    snap = route.snapshot(paths, arr, rng)
    t = time.process_time()
    est = route.extract(snap.H, arr, len(paths), search=search)
    dt = time.process_time() - t
    src = np.stack([arr.to_local(p.source) for p in paths])
    d_true = np.array([p.length for p in paths]) + C * snap.clock_bias
    v_true = np.array([p.velocity for p in paths])
    bound = extraction.path_crlb(paths, arr, route.config, snr_offset_db=off)
    e = _errors(est, d_true, v_true, src, bound)
    pair = _in_unresolved_pair(est, d_true, v_true, src, bound)
    alpha = np.sqrt(route.config.tx_power) * np.array([p.gain for p in paths])
    noise = route.config.noise_power / 10 ** (off / 10)
    mg = merged_errors(est, alpha, src, d_true, v_true, arr.local, route.config, noise, bound)
    return e, est, dt, (snap.H, arr.local, route.config, src, d_true, v_true), (pair, mg)


def close_pair(rng) -> evaluation.Scene:
    """Four sources 2-8 m from the URA, the second a third of a beamwidth (0.067 in direction
    cosine) and a third of the delay resolution ``c / (Nf Delta f)`` from the first."""
    sc = evaluation.random_scene(rng, 4, snr_db=(0.0, 10.0))
    src, d = sc.sources.copy(), sc.d.copy()
    r0 = np.linalg.norm(src[0])
    u0 = src[0] / r0
    ang = rng.uniform(0, 2 * np.pi)
    u1 = u0[:2] + (0.2 / 3) * np.array([np.cos(ang), np.sin(ang)])
    u1 = u1 * min(1.0, 0.8 / np.linalg.norm(u1))
    src[1] = r0 * 1.02 * np.append(u1, np.sqrt(1 - u1 @ u1))
    cfg = sc.config
    d[1] = d[0] + C / (cfg.n_tones * cfg.tone_spacing) / 3
    return replace(sc, sources=src, d=d)


def _scene_snapshot(kind, rng, search):
    sc = evaluation.random_scene(rng, 10) if kind == "scene10" else close_pair(rng)
    H = sc.tensor(rng)
    t = time.process_time()
    est = extraction.extract_paths(H, len(sc.d), sc.element_positions, sc.config, search=search)
    dt = time.process_time() - t
    bound = sc.crlb()
    e = _errors(est, sc.d, sc.v, sc.sources, bound)
    pair = _in_unresolved_pair(est, sc.d, sc.v, sc.sources, bound)
    truth = (H, sc.element_positions, sc.config, sc.sources, sc.d, sc.v)
    pos, cfg = sc.element_positions, sc.config
    mg = merged_errors(est, sc.alpha, sc.sources, sc.d, sc.v, pos, cfg, cfg.noise_power, bound)
    return e, est, dt, truth, (pair, mg)


def search_failed(est, truth) -> bool:
    """Whether the truth's basin of the likelihood is significantly more likely than the
    estimate (module text): the fit restarted at the truth, ``2 (cost_est - cost_truth) /
    sigma^2`` against the 99 % quantile of chi-square with ``5 L`` degrees of freedom."""
    lr, _ = likelihood_ratio(est, truth)
    return bool(lr > chi2.ppf(0.99, 5 * len(truth[4])))


def likelihood_ratio(est, truth) -> tuple[float, float]:
    """``2 (cost_est - cost_truth) / sigma^2`` (the fit restarted at the truth, no re-seeding)
    and the separation of the truth's fit (its smallest, standard deviations of the difference
    of two paths, Fisher information at that fit)."""
    H, pos, cfg, src, d, v = truth
    r = np.linalg.norm(src, axis=1)
    th = np.column_stack([src[:, :2] / r[:, None], 1 / r])
    mf = -2 * np.pi * cfg.tone_spacing * d / C
    mt = 2 * np.pi * cfg.fc * cfg.symbol_period * v / C
    sigma2 = est.fit.noise_power
    at_truth = ml.fit_problem(
        ml.Problem(H, pos, cfg.fc), (th, mf, mt), noise_power=sigma2, n_reseed=0, search="basic"
    )
    return 2.0 * (est.fit.cost - at_truth.cost) / sigma2, float(at_truth.separation)


def above_threshold(est, truth) -> tuple[bool, float, float]:
    """Whether the snapshot lies outside the estimator's threshold region, by the stated
    criterion computed from the bound at the truth (:func:`tunnelkit.extraction.ml.below_threshold`:
    every true path's post-integration SNR, its log-likelihood ratio against noise at the true
    parameters, at least the threshold SNR of the method of interval errors,
    :func:`~tunnelkit.extraction.ml.snr_threshold` of the tensor's ``M Nf Nt`` cells at a 1 %
    outlier rate, and every true path at least ``RESOLVE_Z`` = 5 standard deviations of the
    difference from every other, Fisher information of the concentrated model at the true
    parameters), the smallest separation and the smallest SNR at the truth."""
    H, pos, cfg, src, d, v = truth
    r = np.linalg.norm(src, axis=1)
    th = np.column_stack([src[:, :2] / r[:, None], 1 / r])
    mf = -2 * np.pi * cfg.tone_spacing * d / C
    mt = 2 * np.pi * cfg.fc * cfg.symbol_period * v / C
    prob = ml.Problem(H, pos, cfg.fc)
    sigma2 = est.fit.noise_power
    ev = prob.evaluate(th, mf, mt)
    sig = np.abs(ev["c"]) ** 2 / np.maximum(np.real(np.diag(np.linalg.pinv(ev["G"]))), 1e-300)
    sig = sig / sigma2
    z = ml.separations(prob, th, mf, mt, sigma2)
    below = ml.below_threshold(sig, z, H.size)
    return bool(not below.any()), float(z.min()) if z.size else float("inf"), float(sig.min())


def study(n: int = 30, seed: int = HELD_OUT_SEED, cases=None, search: str = "residual") -> list:
    """Per case: the rows of errors, the flags and the CPU seconds of ``n`` snapshots."""
    out = []
    for case in cases or CASES:
        name, kind, band, off = case
        ci = CASES.index(case)  # the seed of a case does not depend on the selection
        errs, flags, bad, secs, srch, reasons, above, zmin = [], [], [], [], [], [], [], []
        snr_min, est_below, lrs, pairs, llr_min, merged, merged_up = [], [], [], [], [], [], []
        for rng in spawn_rngs(seed * 1000 + ci, n):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                if band is None:
                    e, est, dt, truth, (pair, mg) = _scene_snapshot(kind, rng, search)
                else:
                    e, est, dt, truth, (pair, mg) = _drive_snapshot(kind, band, off, rng, search)
                b = bool(np.any(~(np.abs(e) <= 6.0)))
                lr, z_fit = likelihood_ratio(est, truth) if b else (np.nan, np.nan)
                srch.append(b and bool(lr > chi2.ppf(0.99, 5 * len(truth[4]))))
                lrs.append((lr, z_fit, est.fit.separation))
                a, z, g = above_threshold(est, truth)
            above.append(a)
            pairs.append(pair)
            merged.append(mg)
            merged_up.append(np.full(len(mg), a))
            tests = est.fit.pairs
            llr_min.append(float(tests[:, 3].min()) if tests is not None and len(tests) else np.inf)
            snr_min.append(g)
            est_below.append(bool(np.any(est.below_threshold)))
            zmin.append(z)
            errs.append(e)
            flags.append(not est.fit_ok)
            bad.append(b)
            secs.append(dt)
            reasons.append(est.fit.reason)
        out.append(
            {
                "case": name,
                "offset": off,
                "drive": band is not None,
                "errors": np.concatenate(errs),
                "flagged": np.array(flags),
                "bad": np.array(bad),
                "search": np.array(srch),
                "seconds": np.array(secs),
                "reasons": reasons,
                "above": np.array(above),
                "zmin": np.array(zmin),
                "snr_min": np.array(snr_min),
                "est_below": np.array(est_below),
                "n_paths": np.array([len(e) for e in errs]),
                "lr": np.array(lrs),
                "pair": np.concatenate(pairs),
                "llr_min": np.array(llr_min),
                "merged": np.concatenate(merged),
                "merged_above": np.concatenate(merged_up).astype(bool),
            }
        )
    return out


def _meets_goal(e: np.ndarray) -> bool:
    """The goal on rows of ``error / CRLB`` (n, 4): at most 2 % of the paths beyond 6 sigma in
    any parameter (a missed path, NaN, counts as beyond) and RMS <= 1.5 per parameter over the
    finite rows; no rows meets it."""
    if not len(e):
        return True
    beyond = np.mean(np.any(~(np.abs(e) <= 6.0), axis=1)) * 100
    fin = np.all(np.isfinite(e), axis=1)
    rms = np.sqrt(np.mean(e[fin] ** 2, axis=0)) if fin.any() else np.zeros(e.shape[1])
    return bool(beyond <= 2.0 and np.all(rms <= 1.5))


def table(rows: list) -> str:
    head = (
        f"{'case':26s} {'paths':>5s} "
        + " ".join(f"{'RMS ' + p:>11s}" for p in PARAMS)
        + f" {'>6sig':>6s} {'bad':>4s} {'search':>6s} {'bad flagged':>11s}"
        + f" {'good flagged':>12s} {'unflagged>6sig':>14s} {'median s':>8s}"
    )
    lines = [head]
    missed: dict = {}  # per SNR offset, the drive cases missing the goal
    for r in rows:
        e = r["errors"]
        fin = np.all(np.isfinite(e), axis=1)
        with np.errstate(invalid="ignore"):
            rms = np.sqrt(np.mean(e[fin] ** 2, axis=0)) if fin.any() else np.full(4, np.nan)
        beyond = np.mean(np.any(~(np.abs(e) <= 6.0), axis=1)) * 100
        bad, fl = r["bad"], r["flagged"]
        bf = f"{fl[bad].sum()}/{bad.sum()}"
        gf = f"{fl[~bad].sum()}/{(~bad).sum()}"
        uf = f"{(bad & ~fl).sum()}/{(~fl).sum()}"
        lines.append(
            f"{r['case']:26s} {len(e):5d} "
            + " ".join(f"{x:11.2f}" for x in rms)
            + f" {beyond:5.1f}% {bad.sum():4d} {r['search'].sum():6d} {bf:>11s} {gf:>12s}"
            + f" {uf:>14s} {np.median(r['seconds']):8.3f}"
        )
        if r.get("drive"):
            # the estimate's own verdict only (no truth): the paths it reports unresolved are
            # judged in merged_table, every other path of every snapshot here
            keep = ~r.get("pair", np.zeros(len(e), bool))
            missed.setdefault(r["offset"], [])
            if not _meets_goal(e[keep]):
                missed[r["offset"]].append(r["case"])
    allbad = np.concatenate([r["bad"] for r in rows])
    allfl = np.concatenate([r["flagged"] for r in rows])
    lines.append(
        f"all: {allbad.size} snapshots, {allbad.sum()} with a path beyond 6 sigma, "
        f"{allfl[allbad].sum()} of them flagged; {allfl[~allbad].sum()} of "
        f"{(~allbad).sum()} good snapshots flagged"
    )
    allsearch = np.concatenate([r["search"] for r in rows])
    lines.append(
        f"bad snapshots: {allsearch.sum()} search failures (the truth's basin significantly more "
        f"likely), {allbad.sum() - allsearch.sum()} identifiability limits"
    )
    reasons: dict = {}
    for r in rows:
        for why, f in zip(r["reasons"], r["flagged"]):
            for k in why.split(", ") if f else ():
                reasons[k] = reasons.get(k, 0) + 1
    lines.append("flag reasons: " + (", ".join(f"{k} {v}" for k, v in reasons.items()) or "none"))
    if missed:
        meets = {o: not c for o, c in missed.items()}
        passing = [o for o in sorted(meets) if all(meets[p] for p in meets if p >= o)]
        lines.append(
            "threshold SNR: every drive case meets the goal (<= 2 % beyond 6 sigma, RMS <= 1.5) "
            "on every path but those the estimate reports unresolved (no truth used) "
            + (f"at offsets >= {passing[0]:+.0f} dB" if passing else "at no offset tried")
            + " ("
            + "; ".join(
                f"{o:+.0f} dB " + ("met" if meets[o] else "not met: " + ", ".join(missed[o]))
                for o in sorted(meets)
            )
            + ")"
        )
        # drive and range band (the case name without its offset) missing at every offset
        always = sorted(
            set.intersection(*({c.rsplit(" ", 2)[0] for c in v} for v in missed.values()))
        )
        if always:
            lines.append(
                f"  ({', '.join(always)}: the goal missed at every offset tried, a range threshold "
                "rather than an SNR one: the per-snapshot threshold table below is the statement "
                "to use)"
            )
    return "\n".join(lines)


def threshold_table(rows: list) -> str:
    """Per case, the snapshots above and below the threshold (:func:`above_threshold`): above,
    the share of paths beyond 6 sigma and RMS(error / CRLB) per parameter (goal <= 2 %, <= 1.5);
    the good ones flagged (false flags, goal <= 5 %, pooled); below, the bad snapshots flagged
    (goal >= 95 %, pooled) and the good ones flagged."""
    head = (
        f"{'case':26s} {'above':>5s} {'below':>5s} {'>6sig above':>11s} "
        + " ".join(f"{'RMS ' + p:>9s}" for p in PARAMS)
        + f" {'bad above':>13s} {'good above fl':>13s} {'below: bad fl':>13s} {'good fl':>7s}"
        + f" {'unresolved >6sig':>16s}"
    )
    lines = [head]
    tot = {"bb": 0, "bbf": 0, "bg": 0, "bgf": 0, "ab": 0, "abf": 0, "ag": 0, "agf": 0}
    fails = []
    for r in rows:
        up, bad, fl = r["above"], r["bad"], r["flagged"]
        # above the threshold, the paths the pair test reports unresolved go to their own
        # column (judged there against the resolved model's bound, counted, never dropped)
        pair = r.get("pair", np.zeros(len(r["errors"]), bool))
        per = np.repeat(up, r["n_paths"])
        e = r["errors"][per & ~pair]
        fin = np.all(np.isfinite(e), axis=1)
        with np.errstate(invalid="ignore"):
            rms = np.sqrt(np.mean(e[fin] ** 2, axis=0)) if fin.any() else np.full(4, np.nan)
        beyond = np.mean(np.any(~(np.abs(e) <= 6.0), axis=1)) * 100 if len(e) else np.nan
        eu = r["errors"][per & pair]
        tot["up"] = tot.get("up", 0) + len(eu)
        tot["upb"] = tot.get("upb", 0) + int(np.sum(np.any(~(np.abs(eu) <= 6.0), axis=1)))
        unres = f"{int(np.sum(np.any(~(np.abs(eu) <= 6.0), axis=1)))}/{len(eu)}"
        lo = ~up
        tot["bb"] += (lo & bad).sum()
        tot["bbf"] += (lo & bad & fl).sum()
        tot["bg"] += (lo & ~bad).sum()
        tot["bgf"] += (lo & ~bad & fl).sum()
        tot["ab"] += (up & bad).sum()
        tot["abf"] += (up & bad & fl).sum()
        tot["ag"] += (up & ~bad).sum()
        tot["agf"] += (up & ~bad & fl).sum()
        if up.any() and not _meets_goal(e):
            fails.append(r["case"])
        lines.append(
            f"{r['case']:26s} {up.sum():5d} {lo.sum():5d} {beyond:10.1f}% "
            + " ".join(f"{x:9.2f}" for x in rms)
            + f" {f'{(up & bad).sum()} ({(up & bad & fl).sum()} fl)':>13s}"
            + f" {f'{(up & ~bad & fl).sum()}/{(up & ~bad).sum()}':>13s}"
            + f" {f'{(lo & bad & fl).sum()}/{(lo & bad).sum()}':>13s}"
            + f" {f'{(lo & ~bad & fl).sum()}/{(lo & ~bad).sum()}':>7s}"
            + f" {unres:>16s}"
        )
    eb = [(r["above"], r["bad"], r["flagged"], r["est_below"]) for r in rows if "est_below" in r]
    if eb:
        up, bad, fl, said = (np.concatenate(x) for x in zip(*eb))
        lines.append(
            "the estimate's own verdict (PathEstimates.below_threshold, a path below the threshold "
            f"at the fit): below at the truth {said[~up].sum()}/{(~up).sum()}, above at the truth "
            f"{said[up].sum()}/{up.sum()}; bad snapshots told by fit_ok = False or a path below "
            f"the threshold at the fit {(bad & (fl | said)).sum()}/{bad.sum()}, good ones "
            f"{(~bad & (fl | said)).sum()}/{(~bad).sum()}"
        )
    lines.extend(attainability(rows))
    pb = tot["bbf"] / max(tot["bb"], 1) * 100
    pg = tot["bgf"] / max(tot["bg"], 1) * 100
    lines.append(
        f"above the threshold: {sum(r['above'].sum() for r in rows)} snapshots, "
        f"{tot['ab']} with a path beyond 6 sigma ({tot['abf']} of them flagged), good ones "
        f"flagged {tot['agf']}/{tot['ag']} ({tot['agf'] / max(tot['ag'], 1) * 100:.1f} %); cases missing "
        f"the goal (<= 2 % beyond 6 sigma, RMS <= 1.5; the paths the pair test reports unresolved "
        f"in their own column): {', '.join(fails) or 'none'}; paths reported unresolved above the "
        f"threshold: {tot.get('up', 0)}, {tot.get('upb', 0)} of them beyond 6 sigma of the "
        "resolved model's bound"
    )
    lines.append(
        f"below the threshold: {sum((~r['above']).sum() for r in rows)} snapshots; bad flagged "
        f"{tot['bbf']}/{tot['bb']} ({pb:.1f} %, goal >= 95 %), good flagged {tot['bgf']}/"
        f"{tot['bg']} ({pg:.1f} %: a snapshot in the threshold region flagged is the test "
        "doing its job; the false flags of the goal (<= 5 %) are the good ones above)"
    )
    return "\n".join(lines)


def merged_table(rows: list) -> str:
    """Per case, the pairs reported unresolved (above the threshold and in all), judged as one
    merged path against the bound it can reach (:func:`merged_errors`): the share beyond 6 sigma
    in any parameter (a pair whose two estimates went to one true path counts as beyond) and
    RMS(error / bound) per parameter over the others."""
    head = (
        f"{'case':26s} {'pairs above':>11s} {'>6sig':>6s} "
        + " ".join(f"{'RMS ' + p:>9s}" for p in PARAMS)
        + f" {'pairs all':>9s} {'>6sig':>6s}"
    )
    lines = [
        "Unresolved pairs as one merged path (CRLB of one path at the pair's "
        "power-weighted centroid)",
        head,
    ]
    tot = np.zeros((0, 4))
    for r in rows:
        if "merged" not in r or not len(r["merged"]):
            continue
        e, up = r["merged"], r["merged_above"]
        eu = e[up]
        tot = np.vstack([tot, eu])
        fin = np.all(np.isfinite(eu), axis=1)
        rms = np.sqrt(np.mean(eu[fin] ** 2, axis=0)) if fin.any() else np.full(4, np.nan)
        b_up = np.mean(np.any(~(np.abs(eu) <= 6.0), axis=1)) * 100 if len(eu) else np.nan
        b_all = np.mean(np.any(~(np.abs(e) <= 6.0), axis=1)) * 100
        lines.append(
            f"{r['case']:26s} {len(eu):11d} {b_up:5.1f}% "
            + " ".join(f"{x:9.2f}" for x in rms)
            + f" {len(e):9d} {b_all:5.1f}%"
        )
    fin = np.all(np.isfinite(tot), axis=1)
    rms = np.sqrt(np.mean(tot[fin] ** 2, axis=0)) if fin.any() else np.full(4, np.nan)
    nb = int(np.sum(np.any(~(np.abs(tot) <= 6.0), axis=1)))
    lines.append(
        f"above the threshold, pooled: {len(tot)} pairs, {nb} beyond 6 sigma of the merged bound; "
        "RMS " + " ".join(f"{p} {x:.2f}" for p, x in zip(PARAMS, rms))
    )
    return "\n".join(lines)


def _pair_rows(r) -> list:
    """Per snapshot of a row, its true paths reported unresolved by the pair test (bool)."""
    pair = r.get("pair", np.zeros(len(r["errors"]), bool))
    return np.split(pair, np.cumsum(r["n_paths"])[:-1])


def attainability(rows: list) -> list[str]:
    """Per case, the bad snapshots above the threshold told apart (module text): a *search miss*
    (the truth's basin significantly more likely: the likelihood ratio ``2 Delta cost /
    sigma^2`` above the 99 % quantile of chi-square with ``5 L`` degrees of freedom) or *not
    attainable* (the estimate as likely as the truth's basin: the maximum of the likelihood
    itself is that far off, and the bound of the resolved model is not what the estimate can
    reach), each with the Fisher-information reason: the smallest separation (standard
    deviations of the difference of two paths) at the truth's fit and at the estimate, against
    ``RESOLVE_Z``; and the goal above the threshold (<= 2 % beyond 6 sigma, RMS <= 1.5) without
    the snapshots not attainable (what the bound can promise; both verdicts are listed)."""
    out, fails = [], []
    for r in rows:
        if "lr" not in r:
            continue
        up, bad = r["above"], r["bad"]
        limit = np.zeros(bad.size, bool)
        for i in np.flatnonzero(up & bad):
            lr, z_fit, z_est = r["lr"][i]
            miss = bool(r["search"][i])
            limit[i] = not miss
            why = (
                "search miss (the truth's basin more likely)"
                if miss
                else "not attainable (the estimate as likely as the truth's basin)"
            )
            res = "unresolved" if z_est < ml.RESOLVE_Z else "resolved"
            out.append(
                f"  {r['case']}, snapshot {i}: {why}, 2 dcost/sigma^2 = {lr:.1f}; separation at "
                f"the truth's fit {z_fit:.1f}, at the estimate {z_est:.1f} sd ({res} at the "
                f"estimate, RESOLVE_Z = {ml.RESOLVE_Z:g}); flagged {bool(r['flagged'][i])} "
                f"({r['reasons'][i] or 'no reason'}); pair test: smallest llr "
                f"{r['llr_min'][i] if 'llr_min' in r else np.nan:.1f} (PAIR_LLR "
                f"{ml.PAIR_LLR:g}), {int(_pair_rows(r)[i].sum())} true paths reported unresolved"
            )
        per = np.repeat(up & ~limit, r["n_paths"])
        e = r["errors"][per]
        fin = np.all(np.isfinite(e), axis=1)
        beyond = np.mean(np.any(~(np.abs(e) <= 6.0), axis=1)) * 100 if len(e) else 0.0
        rms = np.sqrt(np.mean(e[fin] ** 2, axis=0)) if fin.any() else np.zeros(4)
        if limit.any():
            out.append(
                f"  {r['case']} without the {limit.sum()} not attainable: {beyond:.1f} % beyond "
                "6 sigma, RMS " + " ".join(f"{p} {x:.2f}" for p, x in zip(PARAMS, rms))
            )
        if beyond > 2.0 or np.any(rms > 1.5):
            fails.append(r["case"])
    head = "bad snapshots above the threshold, told apart:" if out else "no bad snapshot above"
    return [
        head,
        *out,
        "cases missing the goal above the threshold (<= 2 % beyond 6 sigma, RMS <= 1.5) without "
        f"the snapshots not attainable: {', '.join(fails) or 'none'}",
    ]


def _long_tensor(drive="italiano2026-straight", x=110.0, seed=0):
    route = long_route(drive)
    k = int(np.argmin(np.abs(route.trajectory.position[:, 0] - x)))
    arr, paths = route.paths(k)
    snap = route.snapshot(paths, arr, np.random.default_rng(seed))
    return snap.H, arr, route.config, len(paths)


def cases() -> list[Case]:
    """The default extraction at long range (UE ~110 m and ~85 m on the straight drive), and the
    basic search (the route before the pair search and the residual test) on the same tensors as the baseline."""
    out = []
    for x in (110.0, 85.0):
        H, arr, cfg, L = _long_tensor(x=x)

        def run(search, H=H, arr=arr, cfg=cfg, L=L):
            with threadpool_limits(1), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return extraction.extract_paths(H, L, arr, cfg, search=search)

        g = f"stress x={x:.0f}m"
        out.append(
            Case(
                f"extract_paths L={L} UE x={x:.0f} m, basic",
                lambda run=run: run("basic"),
                group=g,
                baseline=True,
                repeat=5,
            )
        )
        out.append(
            Case(
                f"extract_paths L={L} UE x={x:.0f} m, default",
                lambda run=run: run("residual"),
                group=g,
                repeat=5,
                goal_s=0.4,
            )
        )
    return out


def _unscreened(fn):
    """``fn()`` with the early screen of the search off (``SCREEN_ITER`` beyond ``max_iter``: the
    first fit runs to ``max_iter`` before the residual test, the default route before it)."""
    old = ml.fitting.SCREEN_ITER
    try:
        ml.fitting.SCREEN_ITER = 10**6
        return fn()
    finally:
        ml.fitting.SCREEN_ITER = old


def cpu_times(repeat: int = 9, far: bool = True) -> str:
    """Median process (CPU) time, one BLAS thread, interleaved, of the default extraction, of
    the same without the early screen (the default before it) and of the basic search (the route
    before the pair search: re-seeding on the residual energy only) on bench_ml's L = 6 tensor and on
    long-range tensors (UE at x = 110 m and 85 m; with ``far`` also 120, 100 and 95 m), and of
    the default with the fits calling the checked numerics (``bench_ml.checked_numerics``: the
    route before the unchecked twins, same results)."""
    from bench_ml import _tensor, checked_numerics

    tensors = {"L=6 (bench_ml)": _tensor()}
    for x in (120.0, 110.0, 100.0, 95.0, 85.0) if far else (110.0, 85.0):
        H, arr, cfg, L = _long_tensor(x=x)
        tensors[f"L={L} x={x:.0f} m"] = (H, arr, cfg, L)
    lines = [
        f"CPU time per extraction, median of {repeat} (one BLAS thread); ratios to the default "
        "without the screen (the route before it) and to the basic search, same run"
    ]
    runs = {
        "default": lambda H, arr, cfg, L: extraction.extract_paths(H, L, arr, cfg),
        "unscreened": lambda H, arr, cfg, L: _unscreened(
            lambda: extraction.extract_paths(H, L, arr, cfg)
        ),
        "basic": lambda H, arr, cfg, L: extraction.extract_paths(H, L, arr, cfg, search="basic"),
        "checked": lambda H, arr, cfg, L: checked_numerics(
            lambda: extraction.extract_paths(H, L, arr, cfg)
        ),
    }
    long_med = {k: [] for k in runs}
    with threadpool_limits(1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, args in tensors.items():
            t = {k: [] for k in runs}
            ok = {}
            runs["default"](*args)  # warm-up (and the residual test's calibration)
            for _ in range(repeat):
                for k, fn in runs.items():
                    t0 = time.process_time()
                    est = fn(*args)
                    t[k].append(time.process_time() - t0)
                    ok[k] = (est.fit_ok, round(est.fit.cost / est.fit.noise_power))
            med = {k: float(np.median(v)) for k, v in t.items()}
            if name.startswith("L=") and " x=" in name:
                for k in runs:
                    long_med[k].append(med[k])
            lines.append(
                f"  {name:18s} default {med['default'] * 1e3:5.0f} ms, unscreened "
                f"{med['unscreened'] * 1e3:5.0f} ms (ratio {med['default'] / med['unscreened']:.2f}), "
                f"basic {med['basic'] * 1e3:5.0f} ms (ratio {med['default'] / med['basic']:.2f}), "
                f"checked numerics {med['checked'] * 1e3:5.0f} ms (ratio "
                f"{med['default'] / med['checked']:.3f}); "
                f"(fit_ok, cost/sigma^2): " + ", ".join(f"{k} {ok[k]}" for k in runs)
            )
    m = {k: float(np.median(v)) for k, v in long_med.items()}
    lines.append(
        f"  long range, median over the tensors: default {m['default'] * 1e3:.0f} ms, unscreened "
        f"{m['unscreened'] * 1e3:.0f} ms (ratio {m['default'] / m['unscreened']:.2f}), basic "
        f"{m['basic'] * 1e3:.0f} ms, checked numerics {m['checked'] * 1e3:.0f} ms (ratio "
        f"{m['default'] / m['checked']:.3f})"
    )
    return "\n".join(lines)


def report(n: int | None = None) -> str:
    n = n or int(os.environ.get("TUNNELKIT_BENCH_STRESS", 30))
    parts = [cpu_times()]
    for seed, tag in ((DESIGN_SEED, "design seed"), (HELD_OUT_SEED, "held-out seed")):
        t0 = time.perf_counter()
        with threadpool_limits(1):
            rows = study(n, seed)
        parts.append(
            f"Stress matrix, {tag} {seed}, {n} snapshots per case "
            f"({time.perf_counter() - t0:.0f} s, load {os.getloadavg()[0]:.1f})\n"
            + table(rows)
            + "\n\nThreshold region (per snapshot, from the bound at the truth)\n"
            + threshold_table(rows)
            + "\n\n"
            + merged_table(rows)
        )
    return "\n\n".join(parts)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--snapshots", type=int, default=30)
    ap.add_argument("--seed", type=int, default=HELD_OUT_SEED)
    ap.add_argument("--search", default="residual", choices=("residual", "basic"))
    ap.add_argument("-k", dest="pattern", default=None, help="only cases containing this")
    ap.add_argument("--cpu", action="store_true", help="only the CPU times of the extraction")
    ap.add_argument("--repeat", type=int, default=9, help="with --cpu: runs per route")
    ap.add_argument("--near", action="store_true", help="with --cpu: two long-range tensors only")
    ap.add_argument("--save", default=None, help="directory: run case by case, save each")
    ap.add_argument("--report-only", action="store_true", help="with --save: print what is saved")
    a = ap.parse_args()
    if a.cpu:
        from bench_ml import check_share

        print(check_share(_long_tensor(x=110.0), "UE x = 110 m"))
        print(cpu_times(a.repeat, far=not a.near))
        sys.exit(0)
    sel = [c for c in CASES if a.pattern is None or a.pattern in c[0]]
    t0 = time.perf_counter()
    if a.save:  # case by case, each saved as it finishes (resumes; prints the cases saved)
        import pickle

        d = Path(a.save) / f"seed{a.seed}-n{a.snapshots}-{a.search}"
        d.mkdir(parents=True, exist_ok=True)
        res = []
        for c in sel:
            f = d / f"case{CASES.index(c):02d}.pkl"
            if not f.exists() and not a.report_only:
                with threadpool_limits(1):
                    row = study(a.snapshots, a.seed, [c], a.search)[0]
                f.write_bytes(pickle.dumps(row))
                print(f"{c[0]} done ({time.perf_counter() - t0:.0f} s)", flush=True)
            if f.exists():
                res.append(pickle.loads(f.read_bytes()))
    else:
        with threadpool_limits(1):
            res = study(a.snapshots, a.seed, sel, a.search)
    print(
        f"seed {a.seed}, {a.snapshots} snapshots per case, search {a.search}, "
        f"{time.perf_counter() - t0:.0f} s, load {os.getloadavg()[0]:.1f}"
    )
    print(table(res))
    print("\nThreshold region (per snapshot, from the bound at the truth)")
    print(threshold_table(res))
    print()
    print(merged_table(res))
