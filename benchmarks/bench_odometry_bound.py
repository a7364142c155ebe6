"""The posterior CRLB of a drive with the radio and the odometry's repeating errors.

Two drives: the tables' straight drive (``italiano2026-straight``, its 10 x 10 arrays, the design's
error model of the ML route: what it draws, the clock bias eliminated) from a start known
to a millimetre (the tables start JAVELIN at the truth); and a row of sites along a long tunnel
(:func:`tunnelkit.design.sites.row_pcrlb`). Per drive the bound on the white and the
automotive messages, the automotive one without its yaw-rate bias (does the state matter?),
and dead reckoning's bound (no radio). Prints the RMS over the drive (or over its settled
epochs on the row) and the value at the end, in metres::

    python benchmarks/bench_odometry_bound.py
    python benchmarks/bench_odometry_bound.py --scenario mont-blanc-28ghz --speed-kmh 70 \\
        --length 3000 --arrays 8x8 --spacings 200 400
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from tunnelkit.design import DesignSetup, drive_pcrlb, position_information, route_geometry
from tunnelkit.design.achievable import path_error_model
from tunnelkit.design.sites import SiteRow, row_pcrlb, site_route
from tunnelkit.metrics import settled
from tunnelkit.odometry import AUTOMOTIVE, WHITE
from tunnelkit.reckoning import dead_reckoning_bound

MODELS = {
    "white": WHITE,
    "automotive": AUTOMOTIVE,
    "automotive, no yaw-rate bias": replace(AUTOMOTIVE, yaw_rate_bias=0.0),
}


def _motion(traj, T):
    v = np.linalg.norm(traj.velocity[:T, :2], axis=1)
    return traj.t[:T], v, np.arctan2(traj.velocity[:T, 1], traj.velocity[:T, 0])


def tables_drive(spec: str = "10x10") -> list[tuple]:
    setup = DesignSetup.from_scenario("italiano2026-straight")
    g = route_geometry(setup, spec)
    info = position_information(path_error_model(setup, spec, geometry=g), g, drawn=True)
    t, v, th = _motion(setup.trajectory, info.shape[0])
    out = []
    for name, odo in MODELS.items():
        b = drive_pcrlb(setup, info, sigma_p0=1e-3, odometry=odo)
        dr = dead_reckoning_bound(t, v, th, odo)
        out.append((name, np.sqrt(np.mean(b**2)), b[-1], np.sqrt(np.mean(dr**2)), dr[-1]))
    return out


def row_drive(scenario, speed, length, spec, spacing) -> list[tuple]:
    row = SiteRow.along(DesignSetup.from_scenario(scenario), spacing, length, speed=speed)
    route = site_route(row, spec)
    t, v, th = _motion(row.setup.trajectory, len(row.setup.trajectory))
    idx = settled(t)
    out = []
    for name, odo in MODELS.items():
        b = row_pcrlb(row, route, odo, 1.0)
        dr = dead_reckoning_bound(t, v, th, odo, sigma_start=1.0)
        out.append(
            (name, np.sqrt(np.mean(b[idx] ** 2)), b[-1], np.sqrt(np.mean(dr[idx] ** 2)), dr[-1])
        )
    return out


def _print(title, rows):
    print(f"\n{title}\n")
    print("| messages | bound, RMS [m] | bound, end [m] | DR bound, RMS [m] | DR bound, end [m] |")
    print("| --- | --- | --- | --- | --- |")
    for name, a, b, c, d in rows:
        print(f"| {name} | {a:.4g} | {b:.4g} | {c:.4g} | {d:.4g} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="mont-blanc-28ghz")
    ap.add_argument("--speed-kmh", type=float, default=70.0)
    ap.add_argument("--length", type=float, default=3000.0)
    ap.add_argument("--arrays", nargs="+", default=["8x8"])
    ap.add_argument("--spacings", nargs="+", type=float, default=[200.0, 400.0])
    a = ap.parse_args()
    t0 = time.perf_counter()
    _print(
        "The tables' straight drive (10 x 10, ML route's error model, start known)", tables_drive()
    )
    for spec in a.arrays:
        for s in a.spacings:
            rows = row_drive(a.scenario, a.speed_kmh / 3.6, a.length, spec, s)
            _print(f"{a.scenario}, {a.length:g} m at {a.speed_kmh:g} km/h, {spec} every {s:g} m "
                   "(RMS over the settled epochs)", rows)  # fmt: skip
    print(f"\nwall {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
