"""First-order extraction error on the ray-traced channel against the misspecified bound.

Per epoch of a drive (``channel="sionna"``, cached traces, transmit power included):

1. the pseudo-true first-order paths ``phi_0`` of the noiseless traced tensor: the ML fit of eq. 1
   started at the true first-order paths (:func:`tunnelkit.studies.misspecified.pseudo_true`),
   the bias ``phi_0 - phi`` and the sandwich bound at ``phi_0``
   (:func:`~tunnelkit.studies.misspecified.misspecified_bound`) beside eq. 1's CRLB there;
   ``residual`` ``||H - mu(phi_0)||^2`` per sample over ``N0`` and as a share of the received
   power (the model-error share the residual test below is given);
2. ``--draws`` noisy snapshots (noise drawn on the cached tensor, no clock bias): the ML fit started
   at ``phi_0`` without re-seeding (the estimator whose noise-free limit is ``phi_0``): its error
   about ``phi_0`` in MCRB and CRLB standard deviations (delay ``d`` of each first-order path);
3. ``--full-draws`` snapshots through the route's default extraction (search and re-seeding), its
   estimates matched to the true paths (:func:`tunnelkit.evaluation.match_paths`): the delay error
   against ``bias +- MCRB sd`` and how many MCRB sd from ``phi_0`` it lies;
4. for every fit of 2. and 3. the residual test with a model-error floor: the periodogram peak of the
   fit's residual (:func:`~tunnelkit.extraction.ml.residual.residual_peak`: the energy of its
   strongest single-path component) and its energy, each allowed its noise-only threshold plus
   ``share`` times the received energy (``||Y||^2 - N N0``): the model error stated as a share
   of the received power, like the DMC share. Printed: the smallest share each fit needs to
   pass; ``--json`` keeps everything for the choice of the share on one drive and its check on
   another (``benchmarks/bench_rt_flags.py``).

    python benchmarks/bench_rt_mcrb.py --scenario italiano2026-straight --epochs 0 12 24 \\
        --draws 30 --full-draws 2 --json /tmp/mcrb-straight.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.constants import C
from tunnelkit.evaluation import match_paths
from tunnelkit.extraction import ml_truth
from tunnelkit.extraction.ml import Problem, fit_problem
from tunnelkit.signal_route import SignalRoute, measurements_from_estimates
from tunnelkit.signal_route.judging import model_error_test
from tunnelkit.studies.misspecified import misspecified_bound, pseudo_true


def needed_share(resid, n_paths, y2, pos, fc, n0) -> dict:
    """:func:`model_error_test` of a fit's residual (module docstring, item 4)."""
    return model_error_test(resid, n_paths, y2, pos, fc, n0, 0.0)


def study(route: SignalRoute, k: int, draws: int, full_draws: int, rng) -> dict:
    cfg = route.config
    n0 = cfg.noise_power
    arr, paths = route.paths(k)
    name, H0 = route.raytraced.tensor(k)
    if name != arr.name:
        raise RuntimeError(f"epoch {k}: traced for {name}, the route selects {arr.name}")
    H = np.sqrt(cfg.tx_power) * H0
    pos, fc = arr.local, cfg.fc
    truth = ml_truth(paths, arr, cfg)
    L = len(paths)
    dm = C / (2 * np.pi * cfg.tone_spacing)  # metres of delay per radian of mu_f
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pt = pseudo_true(H, pos, fc, truth, noise_power=n0)
    t_pt = time.perf_counter() - t0
    b = misspecified_bound(
        H, pos, fc, pt["theta"], pt["mu_f"], pt["mu_t"], pt["c"], n0, held=pt["held"]
    )
    p_rx = float(np.vdot(H, H).real / H.size)
    out = {
        "k": k,
        "array": arr.name,
        "L": L,
        "kinds": [p.kind for p in paths],
        "pseudo_true_s": t_pt,
        "converged": pt["converged"],
        "lm_iterations": pt["lm_iterations"],
        "newton_iterations": pt["newton_iterations"],
        "residual_N0": pt["residual_power"] / n0,
        "residual_share": pt["residual_power"] / p_rx,
        "held": pt["held"].tolist(),
        "separation": pt["separation"],
        "definite": b["definite"],
        "condition": b["condition"],
        "bias_d_m": (-(pt["mu_f"] - truth[1]) * dm).tolist(),
        "mcrb_sd_d_m": (b["mcrb_sd"][:, 5] * dm).tolist(),
        "crlb_sd_d_m": (b["crlb_sd"][:, 5] * dm).tolist(),
        "pseudo_true_test": needed_share(pt["residual"], L, float(np.vdot(H, H).real), pos, fc, n0),
    }
    start = (pt["theta"], pt["mu_f"], pt["mu_t"])
    local, full = [], []
    t0 = time.perf_counter()
    for _ in range(draws):
        snap = route.raytraced_snapshot(k, arr, paths, rng, clock_bias=0.0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f = fit_problem(Problem(snap.H, pos, fc), start, noise_power=n0, n_reseed=0)
        mf = pt["mu_f"] + np.angle(np.exp(1j * (f.mu_f - pt["mu_f"])))
        z = (mf - pt["mu_f"]) / np.where(b["mcrb_sd"][:, 5] > 0, b["mcrb_sd"][:, 5], np.nan)
        zc = (mf - pt["mu_f"]) / b["crlb_sd"][:, 5]
        r = snap.H - Problem(snap.H, pos, fc).model(f.theta, mf, f.mu_t, f.alpha)
        y2 = float(np.vdot(snap.H, snap.H).real)
        local.append(
            {
                "err_d_m": (-(mf - truth[1]) * dm).tolist(),
                "z_mcrb": z.tolist(),
                "z_crlb": zc.tolist(),
                "test": needed_share(r, L, y2, pos, fc, n0),
            }
        )
    out["local_s"] = (time.perf_counter() - t0) / max(draws, 1)
    t0 = time.perf_counter()
    for _ in range(full_draws):
        snap = route.raytraced_snapshot(k, arr, paths, rng, clock_bias=0.0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            est = route.extract(snap.H, arr, L)
        meas = measurements_from_estimates(est, arr)  # world frame, as the paths
        idx = match_paths(meas.d, meas.direction, paths)
        err = np.full(L, np.nan)
        z = np.full(L, np.nan)
        for i, j in enumerate(idx):
            if j >= 0:
                err[j] = meas.d[i] - paths[j].length
                z[j] = (err[j] - out["bias_d_m"][j]) / max(out["mcrb_sd_d_m"][j], 1e-300)
        model = np.einsum("ml,sl,kl,l->msk", *est.factors, est.alpha)
        r = snap.H - model
        y2 = float(np.vdot(snap.H, snap.H).real)
        full.append(
            {
                "err_d_m": err.tolist(),
                "z_mcrb": z.tolist(),
                "fit_ok": bool(est.fit_ok),
                "reason": est.fit.reason,
                "test": needed_share(r, L, y2, pos, fc, n0),
            }
        )
    out["full_s"] = (time.perf_counter() - t0) / max(full_draws, 1)
    out["local"], out["full"] = local, full
    return out


def _summary(s: dict) -> None:
    print(
        f"epoch {s['k']} ({s['array']}, L = {s['L']}): pseudo-true fit {s['pseudo_true_s']:.1f} s, "
        f"(LM {s.get('lm_iterations')} + Newton {s.get('newton_iterations')} iterations, "
        f"minimum reached {s.get('converged')}), "
        f"residual {s['residual_N0']:.3g} N0/sample = {s['residual_share']:.3g} of P_rx, "
        f"held w {sum(s['held'])}, separation {s['separation']:.3g} sd, A definite {s['definite']}, "
        f"cond B {s['condition']:.2g}"
    )
    for j, kind in enumerate(s["kinds"]):
        zl = np.array([d["z_mcrb"][j] for d in s["local"]])
        zc = np.array([d["z_crlb"][j] for d in s["local"]])
        el = np.array([d["err_d_m"][j] for d in s["local"]])
        line = (
            f"  path {j} {kind:10s} bias {s['bias_d_m'][j]:+.4f} m  MCRB sd "
            f"{s['mcrb_sd_d_m'][j]:.3g} m  CRLB sd {s['crlb_sd_d_m'][j]:.3g} m"
        )
        if zl.size:
            line += (
                f" | local fit: error {np.mean(el):+.4f} m, sd/MCRB "
                f"{np.nanstd(zl):.2f}, sd/CRLB {np.std(zc):.2f}, |z|>6: {np.mean(np.abs(zl) > 6):.2f}"
            )
        ef = [d["err_d_m"][j] for d in s["full"]]
        zf = [d["z_mcrb"][j] for d in s["full"]]
        if ef:
            line += " | full: " + ", ".join(
                f"{e:+.4f} m ({z:+.3g} sd)" for e, z in zip(ef, zf, strict=True)
            )
        print(line)
    sh = [d["test"]["needed"] for d in s["local"]]
    print(
        f"  share needed to pass: pseudo-true {s['pseudo_true_test']['needed']:.3g}; local fits "
        + (f"median {np.median(sh):.3g}, max {np.max(sh):.3g}" if sh else "-")
        + "; full: "
        + ", ".join(f"{d['test']['needed']:.3g} ({d['reason'] or 'ok'})" for d in s["full"])
    )
    print(f"  cost: local fit {s['local_s']:.2f} s/draw, full extraction {s['full_s']:.1f} s/draw")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--epochs", type=int, nargs="+", default=[0, 12, 24])
    ap.add_argument("--draws", type=int, default=30)
    ap.add_argument("--full-draws", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args(argv)
    route = SignalRoute.from_scenario(a.scenario, channel="sionna")
    rng = np.random.default_rng(a.seed)
    res = []
    for k in a.epochs:
        s = study(route, k, a.draws, a.full_draws, rng)
        _summary(s)
        res.append(s)
        sys.stdout.flush()
        if a.json:
            a.json.write_text(json.dumps({"scenario": a.scenario, "epochs": res}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
