"""``tunnelkit design SCENARIO --arrays 4x4 8x8 16x16 [--fc 28GHz] [--bandwidth 400MHz]
[--target 0.2] [--share 0.9] [--runs N] [--workers N | --scheduler ADDRESS] [--format table|json]``.

Sizes an array for a scenario's tunnel and route (:mod:`tunnelkit.design`): per candidate array
the share of the route where the SR-NF model holds for every reflected path, the position error
bound (median and 90th percentile), optionally a JAVELIN Monte-Carlo RMSE with a 95 % interval
(``--runs``), and the smallest array meeting ``--target`` on ``--share`` of the route.
"""

from __future__ import annotations

import argparse
import json
import re
import sys

NAME = "design"
HELP = "size an antenna array for a tunnel: SR-NF validity, position error bound, recommendation"

_UNITS = {"": 1.0, "hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9}


def _frequency(param: str):
    """argparse type reading ``28GHz``, ``400 MHz``, ``5.9e9``; errors name ``param``."""

    def parse(text: str) -> float:
        m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*([a-zA-Z]*)\s*", text)
        try:
            if not m or m.group(2).lower() not in _UNITS:
                raise ValueError
            value = float(m.group(1)) * _UNITS[m.group(2).lower()]
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{param}: cannot read {text!r} (e.g. 28GHz, 400MHz, 5.9e9)"
            ) from None
        if not value > 0:
            raise argparse.ArgumentTypeError(f"{param}: must be > 0, got {text!r}")
        return value

    return parse


def _positive(param: str):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{param}: expected a number, got {text!r}") from None
        if not value > 0:
            raise argparse.ArgumentTypeError(f"{param}: must be > 0, got {text!r}")
        return value

    return parse


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", help="preset name (tunnelkit scenarios) or a .toml path")
    p.add_argument(
        "--arrays",
        nargs="+",
        default=["4x4", "8x8", "16x16"],
        help="candidate arrays: N (a ULA) or NxM (a URA), e.g. 4x4 8x8 16x16",
    )
    p.add_argument("--spacing", type=_positive("spacing"), default=0.5, help="[wavelengths] (0.5)")
    p.add_argument("--fc", type=_frequency("fc"), default=None, help="carrier, e.g. 28GHz")
    p.add_argument("--bandwidth", type=_frequency("bandwidth"), default=None, help="e.g. 400MHz")
    p.add_argument("--tilt", type=float, default=None, help="down-tilt of every array [deg]")
    p.add_argument(
        "--mount-height", type=float, default=None, help="height of the arrays' centre [m]"
    )
    p.add_argument("--target", type=_positive("target"), default=0.2, help="PEB target [m] (0.2)")
    p.add_argument(
        "--share",
        type=float,
        default=0.9,
        help="share of the route that must meet the target with SR-NF valid (0.9)",
    )
    p.add_argument("--eps", type=_positive("eps"), default=0.15, help="eps_phi [rad] (0.15)")
    p.add_argument(
        "--runs", type=int, default=0, help="JAVELIN Monte-Carlo drives per array (0: bounds only)"
    )
    p.add_argument("--seed", type=int, default=0, help="Monte-Carlo seed (0)")
    from .reproduce import add_parallel_arguments

    add_parallel_arguments(p)
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.add_argument("--format", choices=["table", "json"], default="table")


def main(args: argparse.Namespace) -> int:
    from .. import design
    from ..montecarlo import TrialLost
    from .reproduce import parallel_kwargs

    specs = [design.parse_array(a, args.spacing) for a in args.arrays]
    setup = design.DesignSetup.from_scenario(
        args.scenario,
        fc=args.fc,
        bandwidth=args.bandwidth,
        tilt_deg=args.tilt,
        mount_height=args.mount_height,
    )
    try:
        rep = design.design_sweep(
            setup,
            specs,
            target=args.target,
            share=args.share,
            eps_phi=args.eps,
            runs=args.runs,
            seed=args.seed,
            **parallel_kwargs(args),
            progress=args.runs > 0 and args.format == "table" and not args.no_progress,
        )
    except TrialLost as exc:
        print(f"tunnelkit design: error: {exc}", file=sys.stderr)
        return 1
    if args.format == "json":
        print(json.dumps(rep.to_json(), indent=2))
    else:
        print(rep.to_table())
    return 0
