"""What Tables 1-2's goal on the ray-traced channel needs of the line of sight's angles.

The goal: JAVELIN-L at most half of dead reckoning's 2-D RMSE. The told model of the tables'
line-of-sight column (the line of sight's azimuth and elevation as independent Gaussian errors
whose sigmas follow the measured elevation, :func:`tunnelkit.design.tracedlos.los_table` of the
array design's survey) gives a posterior CRLB over the drive
(:func:`tunnelkit.design.drivebound.drive_pcrlb`); beside dead reckoning's (the same recursion,
no radio) their ratio is the gain an efficient tracker fed such angles shows on average. Scaling
every sigma of the table by ``k`` asks what the goal needs: the ``k`` at which the ratio reaches 2.
It is a figure of that model, not a bound on the traced channel (whose errors repeat and have
gross outliers). Drives nothing; a few seconds.

    python benchmarks/bench_tables_need.py
    python benchmarks/bench_tables_need.py --scenario italiano2026-slalom --start-sigma 0.01 0.1
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.design import DesignSetup
from tunnelkit.design.drivebound import drive_pcrlb
from tunnelkit.design.los import los_angle_information
from tunnelkit.geometry import spherical
from tunnelkit.odometry import MODELS
from tunnelkit.reproduce.javelin_traced import los_survey
from tunnelkit.signal_route import SignalRoute

SCALES = (1.0, 0.5, 0.25, 0.1, 0.07, 0.05)


def figures(scenario: str, table, start_sigma: float, odometry, scales=SCALES) -> dict:
    """RMS over every epoch (the tables' metric) of dead reckoning's posterior CRLB over
    ``scenario``'s drive and, per scale
    ``k``, the told model's with every sigma of ``table`` times ``k`` (the line of sight from the
    scenario's first array, at the true elevation), from a start of ``start_sigma`` [m] with
    ``odometry``'s messages: ``{"dead reckoning": m, k: m, ...}``."""
    setup = DesignSetup.from_scenario(scenario)
    ue = setup.trajectory.position
    bs = SignalRoute.from_scenario(scenario).arrays[0].origin
    saz, sel = table.at(spherical(ue - bs)[:, 1])

    def rms(info):
        b = drive_pcrlb(setup, info, sigma_p0=start_sigma, odometry=odometry)
        return float(np.sqrt(np.mean(b**2)))

    out = {"dead reckoning": rms(np.zeros((len(ue), 2, 2)))}
    for k in scales:
        out[k] = rms(los_angle_information(ue, bs, k * saz, k * sel))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--scenario", nargs="+", default=["italiano2026-straight", "italiano2026-slalom"]
    )
    ap.add_argument("--survey", default="italiano2026-straight",
                    help="the scene whose array-design survey gives the table")  # fmt: skip
    ap.add_argument("--start-sigma", type=float, nargs="+", default=[0.01, 0.1],
                    help="the start's sigma [m] (the tables start at the truth: 0.01 stands for "
                    "it; 0.1: the line-of-sight column's told start)")  # fmt: skip
    ap.add_argument(
        "--odometry", nargs="+", default=["white", "automotive"], choices=sorted(MODELS)
    )
    a = ap.parse_args()
    table, summary = los_survey(a.survey)
    print(f"table: {summary['path']} ({summary['bins']} bins): {summary['table_deg']}")
    head = " | ".join(f"k = {k:g}" for k in SCALES)
    print(f"\n| scene | messages | start [m] | dead reckoning [m] | {head} |")
    print("| --- " * (4 + len(SCALES)) + "|")
    for sc in a.scenario:
        for odo in a.odometry:
            for s in a.start_sigma:
                f = figures(sc, table, s, MODELS[odo])
                dr = f["dead reckoning"]
                cells = " | ".join(f"{f[k]:.3f} ({dr / f[k]:.2f}x)" for k in SCALES)
                print(f"| {sc} | {odo} | {s:g} | {dr:.3f} | {cells} |", flush=True)


if __name__ == "__main__":
    main()
