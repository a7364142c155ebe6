"""``tunnelkit reproduce TARGET --runs N`` serially against ``--workers 2`` (a Dask LocalCluster of
two processes): the whole command in a fresh process each time, Python start-up and the cluster's
start and stop included, and the JSON of both compared (they must be identical).

``make bench`` runs a small case (``javelin-table1 --runs 2``, 3 repeats each). The measurement of
record runs alone, serial and parallel alternating::

    python benchmarks/bench_dask.py --target javelin-table1 --runs 20 --repeat 3

and prints every timing, the medians, the speed-up (serial median / 2-worker median), whether the
JSON matched, and the load average before and after (the speed-up needs two idle cores).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from run import Case

ROOT = Path(__file__).resolve().parent.parent


def command(target: str, runs: int, seed: int, workers: int | None) -> list[str]:
    """The CLI call being timed: JSON output, no progress bar."""
    cmd = [sys.executable, "-m", "tunnelkit", "reproduce", target, "--runs", str(runs)]
    cmd += ["--seed", str(seed), "--format", "json"]
    return cmd + ([] if workers is None else ["--workers", str(workers)])


def timed(cmd: list[str]) -> tuple[float, str]:
    """Wall time of one run of ``cmd`` and its standard output (raises if it fails)."""
    t0 = time.perf_counter()
    out = subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True).stdout
    return time.perf_counter() - t0, out


def cases() -> list[Case]:
    target, runs, seed = "javelin-table1", 2, 0
    outputs: dict[str, str] = {}

    def run_mode(workers: int | None):
        _, out = timed(command(target, runs, seed, workers))
        key = "serial" if workers is None else "parallel"
        outputs[key] = out
        if len(set(outputs.values())) > 1:
            raise RuntimeError(f"{target}: JSON differs between serial and --workers 2")

    name = f"reproduce {target} --runs {runs}"
    return [
        Case(f"{name}, serial", lambda: run_mode(None), baseline=True, repeat=3, warmup=False),
        Case(f"{name}, --workers 2", lambda: run_mode(2), repeat=3, warmup=False),
    ]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--target", default="javelin-table1")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", default="build/bench_dask.json")
    args = ap.parse_args(argv)
    load_before = os.getloadavg()
    times: dict[str, list[float]] = {"serial": [], "parallel": []}
    outs: dict[str, set[str]] = {"serial": set(), "parallel": set()}
    for i in range(args.repeat):
        for mode, w in (("serial", None), ("parallel", args.workers)):
            dt, out = timed(command(args.target, args.runs, args.seed, w))
            times[mode].append(dt)
            outs[mode].add(out)
            print(
                f"repeat {i + 1}: {mode:8s} {dt:8.2f} s  load {os.getloadavg()[0]:.2f}", flush=True
            )
    med = {k: statistics.median(v) for k, v in times.items()}
    identical = len(outs["serial"] | outs["parallel"]) == 1
    result = {
        "command": " ".join(command(args.target, args.runs, args.seed, None)[1:]),
        "workers": args.workers,
        "repeat": args.repeat,
        "serial_s": times["serial"],
        "parallel_s": times["parallel"],
        "serial_median_s": med["serial"],
        "parallel_median_s": med["parallel"],
        "speedup": med["serial"] / med["parallel"],
        "identical_json": identical,
        "loadavg_before": load_before,
        "loadavg_after": os.getloadavg(),
        "cpu_count": os.cpu_count(),
    }
    print(json.dumps(result, indent=2))
    out = ROOT / args.json
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2))
    return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
