"""Notebook 05: how many particles the unscented particle filter needs on the Jiang straight run.

``python benchmarks/upf_particles.py [--runs N] [--particles 150 300 500 1000] [--seed S]`` runs
the UPF (default proposal, default gate) with each particle count on the same ``--runs``
simulated runs of the straight NLOS preset at (2 deg, 2 m), and the UKF on the same runs as the
reference. One row per filter: the mean Euclidean position error over all runs and epochs, its
RMSE, and the number of runs whose error exceeds ``LOST`` metres at some epoch (a run that locked
onto a wrong velocity and drifted). Prints a Markdown table (the one in
``docs/results/upf-particles.md``).

Only public interfaces are used, so the script measures any version of the package on the path.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tunnelkit.tracking import virtual_station as vs

#: an error above this at some epoch marks a lost run [m] (the filters' RMSE there is about 0.8 m)
LOST = 3.0


def rows(runs: int, particles: list[int], seed: int) -> list[dict]:
    """One dict per filter (UKF, then the UPF at each particle count) on the same runs."""
    exp = vs.experiment("jiang2023-straight", level=2)
    Z, x0 = exp.simulate(runs, np.random.default_rng(seed))
    out = []
    for n in [None, *particles]:
        name, opts = ("UKF", {}) if n is None else ("UPF", {"n_particles": n})
        t0 = time.perf_counter()
        est = vs.run_estimator(
            name, exp.model, Z, x0, exp.P0, rng=np.random.default_rng(seed + 1), **opts
        )
        err = np.linalg.norm(est[..., :2] - exp.truth[:, :2], axis=-1)  # (runs, T)
        out.append(
            {
                "filter": name if n is None else f"UPF, {n} particles",
                "mean_m": float(err.mean()),
                "rmse_m": float(np.sqrt(np.mean(err**2))),
                "lost_runs": int(np.sum(err.max(axis=1) > LOST)),
                "seconds": time.perf_counter() - t0,
            }
        )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=100, help="simulated runs (the paper: 100)")
    ap.add_argument("--particles", type=int, nargs="+", default=[150, 300, 500, 1000])
    ap.add_argument("--seed", type=int, default=0, help="seed of the simulated runs")
    args = ap.parse_args(argv)
    table = rows(args.runs, args.particles, args.seed)
    print(
        f"straight NLOS, 2 deg / 2 m, {args.runs} runs (seed {args.seed}); "
        f"lost = error above {LOST:g} m at some epoch\n"
    )
    print("| filter | mean error | RMSE | lost runs | wall time |")
    print("|---|---|---|---|---|")
    for r in table:
        print(
            f"| {r['filter']} | {r['mean_m']:.3f} m | {r['rmse_m']:.3f} m | "
            f"{r['lost_runs']} of {args.runs} | {r['seconds']:.0f} s |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
