"""Dead reckoning's drift against distance driven beside its bound, for the paper's white
odometry and the automotive model (:mod:`tunnelkit.studies.odometry`): a 3 km straight drive at
22 m/s, 10 Hz epochs, ``--drives`` Monte-Carlo drives per model, on seed 0 and the held-out
seed. Prints one Markdown table per seed (``docs/results/odometry.md``); ``--speed`` and
``--distances`` drive another speed (the paper's drives: 13.89 m/s over 40 m).

    python benchmarks/bench_odometry.py --drives 2000
    python benchmarks/bench_odometry.py --drives 2000 --speed 13.89 --distances 40 100
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.simulation import HELD_OUT_SEED
from tunnelkit.studies.odometry import DISTANCES_M, MODELS, drift_rows, drift_table


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--drives", type=int, default=2000, help="Monte-Carlo drives per model")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, HELD_OUT_SEED])
    ap.add_argument("--speed", type=float, default=22.0, help="the drive's speed [m/s]")
    ap.add_argument("--distances", type=float, nargs="+", default=list(DISTANCES_M))
    args = ap.parse_args(argv)
    for seed in args.seeds:
        t0 = time.perf_counter()
        rows = drift_rows(args.drives, seed, args.distances, speed=args.speed)
        took = time.perf_counter() - t0
        print(
            f"\nseed {seed}, {args.drives} drives per model at {args.speed:g} m/s ({took:.1f} s)\n"
        )
        print(drift_table(rows))
        far = rows[-1]
        print(
            f"\nmean error along the track at {far['distance']:g} m: "
            + ", ".join(f"{m} {far[f'{m}_along']:.3g} m" for m in MODELS)
        )


if __name__ == "__main__":
    main()
