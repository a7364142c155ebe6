"""The design sweep of the paper tunnel on both channel sources: a table per array.

``tunnelkit design SCENARIO --arrays ... --mode channel --channel image|sionna --runs N --seed S
--format json`` on both channels (the ray-traced one with the traced treatment of
:mod:`tunnelkit.design.traced`: geometry pre-filter, the array's own errors measured on the first
drives of seed 0 and cached in ``data/rt/design/``), then per array and channel: median and p90
of the settled error with its bootstrap 95 % interval, the verdict, the PEB and achievable bound
beside it (p90, eq.-1 model), on the traced route the bound of the sigmas its tracker is told
(settled RMS, :func:`tunnelkit.design.tracedbounds.traced_bounds`), with ``--dead-reckoning`` the
same drives' error p90 with every measurement dropped ("DR p90"), the traced route's measurement
noise, and the ray tracer's cost (trace time per epoch, median and max, and the cache size of the
array's drive). ``--start-sigma`` sets the entry fix (the CLI's ``--start-sigma``).

    python benchmarks/bench_rt_design.py --runs 5 --seed 20261202 --workers 2
    python benchmarks/bench_rt_design.py --runs 10 --channels sionna --start-sigma 0.1
    python benchmarks/bench_rt_design.py --from-json build/sweep-image.json build/sweep-sionna-*.json

Choose on seed 0 (the traced errors are measured there), report on a seed never looked at
(:data:`tunnelkit.simulation.HELD_OUT_SEED` by default).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit import design
from tunnelkit.simulation import HELD_OUT_SEED


def run_sweep(
    scenario,
    arrays,
    channel,
    runs,
    seed,
    workers,
    out: Path,
    start_sigma=None,
    dead_reckoning=False,
    traced_tracker="paths",
) -> dict:
    """The CLI's sweep on ``channel``; its JSON (written to ``out``) with the wall time."""
    cmd = [sys.executable, "-m", "tunnelkit", "design", scenario, "--arrays", *arrays,
           "--mode", "channel", "--channel", channel, "--runs", str(runs), "--seed", str(seed),
           "--no-progress", "--format", "json"]  # fmt: skip
    if workers:
        cmd += ["--workers", str(workers)]
    if start_sigma is not None:
        cmd += ["--start-sigma", str(start_sigma)]
    if dead_reckoning:
        cmd += ["--dead-reckoning"]
    if channel == "sionna":  # the tracker this benchmark's tables measured (docs/results/)
        cmd += ["--traced-tracker", traced_tracker]
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if res.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(cmd)} failed ({res.returncode}):\n{res.stderr[-2000:]}")
    rep = json.loads(res.stdout)
    rep["wall_s"] = time.perf_counter() - t0
    out.write_text(json.dumps(rep, indent=1) + "\n")
    return rep


def trace_cost(scenario: str, label: str) -> dict:
    """Trace time per epoch and cache size of ``label``'s design drive on the ray-traced channel
    (traced now if the cache lacks epochs)."""
    setup = design.DesignSetup.from_scenario(scenario, channel="sionna")
    route = setup.signal_route(label)
    r = route.raytraced.prepare(route.tunnel)
    t = np.asarray(r["trace_s"])
    return {"median_s": float(np.median(t)), "max_s": float(t.max()), "epochs": int(t.size),
            "bytes": int(r["bytes"])}  # fmt: skip


def _m(v) -> str:
    if v is None:
        return "-"
    return f"{v * 1e3:.3g} mm" if abs(v) < 0.1 else f"{v:.3g} m"


def table(reps: dict, costs: dict) -> str:
    lines = [
        "pred p90: the design's prediction (eq. 1, not a bound); told RMS: on the traced route the "
        "posterior CRLB of the sigmas its tracker is told as independent Gaussian errors (settled "
        "RMS; a prediction, not a bound on the traced channel); DR: the same drives with every "
        "measurement dropped (--dead-reckoning), gain = DR RMSE / RMSE",
        f"{'channel':12s} {'array':6s} {'runs':>4s} {'median':>9s} {'p90':>9s} {'95% CI of p90':>22s} "
        f"{'RMSE':>9s} {'PEB p90':>9s} {'pred p90':>9s} {'told RMS':>9s} {'DR p90':>9s} "
        f"{'DR RMSE':>9s} {'gain':>5s} {'verdict':10s} noise model / trace cost",
    ]
    for ch, rep in reps.items():
        for a in rep["arrays"]:
            ci = a.get("error_p90_ci95_m")
            cis = f"[{_m(ci[0])}, {_m(ci[1])}]" if ci else "-"
            em = a.get("error_model")
            if em:
                s = em["sigmas"]
                note = (f"traced (seed {em['seed']}, {em['runs']} drives): {s['phi_deg']:.3g}/"
                        f"{s['psi_deg']:.3g} deg, {s['kappa_m']:.3g} m, {s['delta_d_m']:.3g} m")  # fmt: skip
            else:
                note = "reported CRLB"
            c = costs.get(a["array"])
            if ch.startswith("sionna") and c:
                note += (f"; trace {c['median_s']:.2f} s/epoch (max {c['max_s']:.2f}), cache "
                         f"{c['bytes'] / 1e6:.0f} MB")  # fmt: skip
            dr = a.get("dead_reckoning_rmse_m")
            gain = f"{dr / a['rmse_m']:.2f}" if dr and a.get("rmse_m") else "-"
            lines.append(
                f"{ch:12s} {a['array']:6s} {a['runs']:4d} {_m(a['error_median_m']):>9s} "
                f"{_m(a['error_p90_m']):>9s} {cis:>22s} {_m(a.get('rmse_m')):>9s} "
                f"{_m(a['peb_p90_m']):>9s} {_m(a['predicted_p90_m']):>9s} "
                f"{_m(a.get('predicted_drive_rms_m')):>9s} "
                f"{_m(a.get('dead_reckoning_p90_m')):>9s} {_m(dr):>9s} {gain:>5s} "
                f"{a['status']:10s} {note}"
            )
        lines.append(
            f"{ch}: recommendation {rep['recommendation'].get('array')}, seed "
            f"{rep['inputs']['seed']}, entry fix {rep['inputs'].get('start_sigma_m', 1.0):g} m, "
            f"wall {rep.get('wall_s', float('nan')):.0f} s"
        )
        lines += [f"  warning: {w}" for w in rep["warnings"]]
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--arrays", nargs="+", default=["4x4", "8x8", "10x10"])
    ap.add_argument("--channels", nargs="+", default=["image", "sionna"])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--seed", type=int, default=HELD_OUT_SEED)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--start-sigma", type=float, default=None, help="entry fix [m] per axis")
    ap.add_argument("--dead-reckoning", action="store_true", help="also each drive without radio")
    ap.add_argument("--traced-tracker", default="paths", choices=["paths", "los", "auto"],
                    help="the ray-traced channel's tracker (default paths, the tables' own)")  # fmt: skip
    ap.add_argument("--out", default=str(ROOT / "build"))
    ap.add_argument("--from-json", nargs="+", default=None, help="tabulate CLI outputs instead")
    args = ap.parse_args()
    if args.from_json:  # one file per channel, or per channel and array (merged in order)
        reps = {}
        for f in args.from_json:
            rep = json.loads(Path(f).read_text())
            ch = rep["inputs"].get("channel", "image")
            if "start_sigma_m" in rep["inputs"]:
                ch += f"@{rep['inputs']['start_sigma_m']:g}m"
            if ch in reps:
                reps[ch]["arrays"] += rep["arrays"]
                reps[ch]["warnings"] += rep["warnings"]
                reps[ch]["recommendation"] = {"array": "(per-array files: see each)"}
                reps[ch]["wall_s"] = reps[ch].get("wall_s", 0.0) + rep.get("wall_s", 0.0)
            else:
                reps[ch] = rep
    else:
        Path(args.out).mkdir(parents=True, exist_ok=True)
        reps = {
            ch: run_sweep(
                args.scenario,
                args.arrays,
                ch,
                args.runs,
                args.seed,
                args.workers,
                Path(args.out) / f"design-{ch}-{args.seed}.json",
                args.start_sigma,
                args.dead_reckoning,
                args.traced_tracker,
            )
            for ch in args.channels
        }
    labels = [a["array"] for rep in reps.values() for a in rep["arrays"]]
    costs = (
        {lb: trace_cost(args.scenario, lb) for lb in dict.fromkeys(labels)}
        if any(ch.startswith("sionna") for ch in reps)
        else {}
    )
    print(table(reps, costs))


if __name__ == "__main__":
    main()
