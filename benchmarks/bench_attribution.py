"""Attribution: what eq. 1 misses on the ray-traced channel, mechanism by mechanism.

Switches each mechanism off in the ray tracer in turn (diffuse scattering, second-order bounces,
per-element tracing, the reflection coefficient's angle dependence; the TR 38.901 pattern
switched on) and prints, per configuration and array, the pseudo-true bias of each kind of
first-order path, the ML extraction's errors at the operating SNR and the one-epoch fix's
position error (:mod:`tunnelkit.studies.attribution`). Traces are cached per configuration
(``<cache>/attribution/<configuration>``); a second run reads them.

    python benchmarks/bench_attribution.py --arrays 8x8 4x4 --epochs 0 5 10 15 20 25 --draws 2
    python benchmarks/bench_attribution.py --configs scenario all-off --arrays 4x4 --draws 0
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import shlex
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.studies.attribution import CONFIGURATIONS, attribution


def _shape(text: str) -> tuple[int, int]:
    try:
        a, b = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected ROWSxCOLS such as 8x8, got {text!r}") from None
    return a, b


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--arrays", nargs="+", type=_shape, default=[(8, 8)])
    ap.add_argument("--configs", nargs="+", choices=list(CONFIGURATIONS), default=None)
    ap.add_argument("--no-references", action="store_true", help="leave out the eq. 1 rows")
    ap.add_argument("--epochs", nargs="+", type=int, default=[0, 5, 10, 15, 20, 25])
    ap.add_argument("--draws", type=int, default=2, help="noisy snapshots per epoch")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--samples", type=int, default=None, help="rays (default: the scenario's)")
    ap.add_argument("--cache-dir", default=None, help="trace cache root (default: the rt cache)")
    ap.add_argument("--json", default=None, help="also write the records here")
    args = ap.parse_args(argv)
    res = attribution(
        args.scenario,
        arrays=args.arrays,
        configs=args.configs,
        references=not args.no_references,
        epochs=args.epochs,
        draws=args.draws,
        seed=args.seed,
        cache_dir=args.cache_dir,
        samples_per_src=args.samples,
        progress=True,
    )
    cmd = "python benchmarks/bench_attribution.py " + shlex.join(
        sys.argv[1:] if argv is None else argv
    )
    print(f"\n`{cmd.strip()}` ({res.wall_s:.0f} s; scenario {res.scenario}, epochs "
          f"{list(res.epochs)}, {res.draws} draws per epoch, seed {res.seed})\n")  # fmt: skip
    print(res.markdown())
    if args.json:
        Path(args.json).write_text(
            json.dumps(
                {
                    "command": cmd,
                    **{k: v for k, v in vars(res).items() if k not in ("rows", "summary")},
                    "rows": [dataclasses.asdict(r) for r in res.rows],
                    "summary": [dataclasses.asdict(s) for s in res.summary],
                },
                indent=1,
                default=str,
            )
            + "\n"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
