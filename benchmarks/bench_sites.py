"""A long tunnel served by a row of sites (:mod:`tunnelkit.design.sites`): the study's table and
wall time, and the cost per epoch of a multi-site drive against a single-site one.

Part ``study``: :func:`tunnelkit.design.longtunnel.long_tunnel_study` on the 28 GHz example
tunnel, 4x4 / 8x8 / 16x16 x 100 / 200 / 400 / 800 m x ``--runs`` drives of ``--length`` m,
``--workers`` processes, ``--impairments ideal`` (default) or ``calibrated`` (the design's
default impairment set, :func:`tunnelkit.design.impairments.preset_impairments`); prints the Markdown table, the configurations meeting the target and
the wall time. Part ``cost``: per epoch, the median over ``--repeats`` of (a) the drawn drive
and (b) JAVELIN on it, for the preset's single-site bound drive (:func:`bound_drive`, its own
route) and for a drive along a 200 m row (:func:`site_drive`), plus the one-off cost of each
array's model (:func:`bound_route` on the preset route, :func:`site_route` on the row).

    PYTHONPATH=$PWD python benchmarks/bench_sites.py --part cost [--repeats 5]
    PYTHONPATH=$PWD python benchmarks/bench_sites.py --part study --runs 20 --workers 2 --seed 0
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tunnelkit.design import DesignSetup
from tunnelkit.design.achievable import path_error_model
from tunnelkit.design.arrayjob import design_planes, javelin_config, median_sigmas
from tunnelkit.design.fastroute import bound_drive, bound_route
from tunnelkit.design.longtunnel import long_tunnel_study
from tunnelkit.design.sites import SiteRow, site_drive, site_route
from tunnelkit.simulation import evaluate

SCENARIO = "example-rectangular-28ghz"


def _timed(f, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return float(np.median(times)), out


def cost(repeats: int, spec: str = "8x8", spacing: float = 200.0, length: float = 1000.0):
    setup = DesignSetup.from_scenario(SCENARIO)
    row = SiteRow.along(setup, spacing, length)
    t_single_model, route1 = _timed(
        lambda: bound_route(path_error_model(setup, spec), setup, spec), repeats
    )
    t_row_model, route2 = _timed(lambda: site_route(row, spec), repeats)
    print(f"| {spec} | drive | epochs | model [s] | drive [ms/epoch] | JAVELIN [ms/epoch] |")
    print("|---|---|---|---|---|---|")
    cases = (
        ("single site (preset route)", setup, route1, t_single_model,
         lambda rng: bound_drive(route1, setup, spec, rng)),
        (f"row of {row.count} sites, {spacing:g} m", row.setup, route2.route, t_row_model,
         lambda rng: site_drive(row, route2, rng)),
    )  # fmt: skip
    for name, s, r, t_model, draw in cases:
        design = javelin_config(median_sigmas(r.model), r.min_d, design_planes(s))
        T = len(s.trajectory)
        t_drive, drive = _timed(lambda draw=draw: draw(np.random.default_rng(0)), repeats)
        t_trk, _ = _timed(lambda d=drive, g=design: evaluate(d, g), repeats)
        print(
            f"| | {name} | {T} | {t_model:.3f} | {1e3 * t_drive / T:.3f} | {1e3 * t_trk / T:.3f} |"
        )


def study(runs: int, workers: int | None, seed: int, length: float, target: float, imp: str):
    from tunnelkit.design.impairments import preset_impairments

    setup = DesignSetup.from_scenario(SCENARIO)
    arrays = ("4x4", "8x8", "16x16")
    res = long_tunnel_study(
        setup,
        arrays,
        length=length,
        runs=runs,
        seed=seed,
        workers=workers,
        target=target,
        impairments=preset_impairments(imp, setup, arrays),
    )
    print(
        f"{SCENARIO}, {imp}, {length:g} m at 80 km/h, {runs} runs, seed {seed}, workers {workers}\n"
    )
    print(res.table())
    print(f"\nmeeting p90 <= {target:g} m: {res.meeting()}")
    print(f"wall time: {res.wall_s:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=("cost", "study"), default="cost")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--length", type=float, default=2000.0)
    ap.add_argument("--target", type=float, default=1.0)
    ap.add_argument("--impairments", choices=("ideal", "calibrated"), default="ideal")
    a = ap.parse_args()
    if a.part == "cost":
        cost(a.repeats)
    else:
        study(a.runs, a.workers, a.seed, a.length, a.target, a.impairments)


if __name__ == "__main__":
    main()
