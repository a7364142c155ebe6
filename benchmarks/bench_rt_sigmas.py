"""The traced design's measurement noise: measure it (and store it with ``--write``).

:func:`tunnelkit.studies.traced.measure_traced_errors`: the ML route's RMS extraction error on
the ray-traced channel, condition-L drives of the straight preset, seed 0 (``--runs``, default
:data:`~tunnelkit.studies.traced.SIGMA_RUNS`), every epoch's measurements whatever the fit's own
verdict. ``--write`` stores the record in ``data/rt/traced_errors.json``, which
:func:`~tunnelkit.studies.traced.traced_design` (the ``--channel sionna`` tables' traced column)
reads. Deterministic: the same cache and seed give the same numbers.

    python benchmarks/bench_rt_sigmas.py --write
"""

from __future__ import annotations

import argparse
import datetime
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.studies.traced import SIGMA_RUNS, measure_traced_errors, write_traced_errors


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=SIGMA_RUNS)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--n-epochs", type=int, default=None)
    ap.add_argument("--write", action="store_true", help="store in data/rt/traced_errors.json")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    rec = measure_traced_errors(a.runs, a.seed, progress=True, n_epochs=a.n_epochs)
    wall = time.perf_counter() - t0
    rec["measured_utc"] = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d")
    print(f"{a.runs} traced drive(s), seed {a.seed}: {wall:.0f} s")
    print("  " + ", ".join(rec["columns"]))
    for r in rec["rows"]:
        print("  " + ", ".join(f"{x:.4g}" if isinstance(x, float) else str(x) for x in r))
    if a.write:
        print(f"written: {write_traced_errors(rec)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
