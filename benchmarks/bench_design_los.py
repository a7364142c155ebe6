"""The design's trackers on the ray-traced channel, on the same drives: every path, the line of sight, the choice.

``tunnelkit design SCENARIO --mode channel --channel sionna`` with ``--traced-tracker paths``
(every path the geometry pre-filter keeps, told the array's long-run RMS errors),
``--traced-tracker los`` (the path taken for the line of sight, told its angle sigmas by its
measured elevation from a survey of the first 3 drives of seed 0: :mod:`tunnelkit.design.los`)
and ``--traced-tracker auto`` (the default: per array the one whose told model predicts the
smaller error), run in one process so that the later sweeps track on the first one's drives
(the extraction, which costs seconds per epoch, runs once;
:func:`tunnelkit.design.traced.design_drive`, which keeps at most
:data:`~tunnelkit.design.traced.DRIVES_KEPT` drives). Per array and tracker: the tracker's error
p90 and RMSE over the settled route, dead reckoning's on the same drives, entry fixes and V2X
messages, the radio's gain (dead reckoning's RMSE over the tracker's) and the told model's
posterior CRLB (a prediction on this channel, not a bound). ``--drives-cache FILE`` stores the
drives (:func:`~tunnelkit.design.traced.kept_drives`) and, when the file exists, tracks on them
without extracting.

    python benchmarks/bench_design_los.py example-rectangular-28ghz --arrays 4x4 8x8 --units 6
    python benchmarks/bench_design_los.py italiano2026-straight --arrays 4x4 8x8 10x10 --units 6

The survey is seed 0's (the choice of the table's bins was made on the studies' seed-0 drives);
report on a seed never looked at (:data:`tunnelkit.simulation.HELD_OUT_SEED`, the default).
"""

from __future__ import annotations

import argparse
import json
import pickle
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit import design
from tunnelkit.design import traced
from tunnelkit.design.tracedtracker import TRACED_TRACKERS
from tunnelkit.simulation import HELD_OUT_SEED


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("--arrays", nargs="+", default=["4x4", "8x8"])
    ap.add_argument("--units", type=int, default=6, help="units of --drives-per-unit drives")
    ap.add_argument("--drives-per-unit", type=int, default=2)
    ap.add_argument("--seed", type=int, default=HELD_OUT_SEED)
    ap.add_argument("--start-sigma", type=float, default=design.START_SIGMA_M)
    ap.add_argument("--json", default=None, help="write the rows here")
    ap.add_argument(
        "--drives-cache", default=None,
        help="a pickle of the sweep's drives: read when it exists (tracking only), written after",
    )  # fmt: skip
    a = ap.parse_args()
    setup = design.DesignSetup.from_scenario(a.scenario, channel="sionna")
    cache = Path(a.drives_cache) if a.drives_cache else None
    if cache is not None and cache.exists():
        traced.keep_drives(setup, pickle.loads(cache.read_bytes()))
    rows = []
    for tracker in TRACED_TRACKERS:  # "paths" first: it drives, the others track on its drives
        t0 = time.perf_counter()
        rep = design.design_sweep(
            setup, a.arrays, units=a.units, max_units=a.units, drives_per_unit=a.drives_per_unit,
            mode="channel", seed=a.seed, dead_reckoning=True, start_sigma=a.start_sigma,
            traced_tracker=tracker,
        )  # fmt: skip
        wall = time.perf_counter() - t0
        for r in rep.rows:
            rows.append({"tracker": tracker, "wall_s": round(wall, 1), **r.to_json()})
        print(rep.to_table(), flush=True)
        print(f"{tracker}: {wall:.0f} s", flush=True)
        if cache is not None and tracker == TRACED_TRACKERS[0]:
            cache.parent.mkdir(parents=True, exist_ok=True)
            cache.write_bytes(pickle.dumps(traced.kept_drives(setup)))
    print(f"\n{a.scenario}, traced channel, seed {a.seed}, {a.units} units x "
          f"{a.drives_per_unit} drives, entry fix {a.start_sigma:g} m\n")  # fmt: skip
    print(
        "| array | tracker | p90 / RMSE [m] | dead reckoning p90 / RMSE [m] | gain (RMSE) | "
        "told model's posterior CRLB (a prediction) [m] |\n| --- | --- | --- | --- | --- | --- |"
    )
    for r in rows:
        gain = r["dead_reckoning_rmse_m"] / r["rmse_m"]
        pred = r.get("predicted_drive_rms_m")
        print(f"| {r['array']} | {r['tracker']} | {r['error_p90_m']:.3f} / {r['rmse_m']:.3f} | "
              f"{r['dead_reckoning_p90_m']:.3f} / {r['dead_reckoning_rmse_m']:.3f} | "
              f"{gain:.2f}x | {'-' if pred is None else f'{pred:.3f}'} |")  # fmt: skip
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
