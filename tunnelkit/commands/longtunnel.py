"""``tunnelkit long-tunnel SCENARIO [--arrays 4x4 8x8 16x16] [--spacings 100 200 400 800]
[--length 2000] [--speed-kmh 80] [--runs 20] [--seed 0] [--target 1] [--ideal]
[--odometry white|automotive] [--told-odometry] [--workers N | --scheduler A] [--format table|json]``.

Which array and how far apart the sites, for a long tunnel: the scenario's site repeated every
spacing along a drive of ``--length`` metres (:mod:`tunnelkit.design.sites`), JAVELIN and dead
reckoning on ``--runs`` drives per array and spacing on the design's bound route
(:func:`tunnelkit.design.longtunnel.long_tunnel_study`); per array and spacing the 2-D error's
p90 and RMSE, the p90 at the worst point between sites, dead reckoning's, the radio's gain and
whether the p90 meets ``--target``. The arrays are calibrated as ``tunnelkit design``'s default
(``--ideal``: no impairment, the optimistic case); the V2X messages are white (the optimistic
case for dead reckoning) or, with ``--odometry automotive``, a car's odometry; by default the
scenario's ``[odometry]`` section says which (white where it has none).
"""

from __future__ import annotations

import argparse
import json

from .._physical import MAX_RANGE_M, MAX_SPEED
from .design import count_arg, positive_arg

NAME = "long-tunnel"
HELP = "a long tunnel served by a row of sites: which array and how far apart the sites"

#: the longest drive the command runs [m]
MAX_LENGTH_M = 20_000.0


def add_arguments(p: argparse.ArgumentParser) -> None:
    from .reproduce import add_parallel_arguments

    p.add_argument("scenario", help="preset name (tunnelkit scenarios) or a .toml path")
    p.add_argument(
        "--arrays", nargs="+", default=["4x4", "8x8", "16x16"], help="candidate arrays, e.g. 8x8"
    )
    p.add_argument(
        "--spacings",
        nargs="+",
        type=positive_arg("spacings", MAX_LENGTH_M),
        default=[100.0, 200.0, 400.0, 800.0],
        help="distances between sites [m] (100 200 400 800)",
    )
    p.add_argument(
        "--length",
        type=positive_arg("length", MAX_LENGTH_M),
        default=2000.0,
        help="the drive [m] (2000)",
    )
    p.add_argument(
        "--speed-kmh",
        type=positive_arg("speed_kmh", 3.6 * MAX_SPEED),
        default=80.0,
        help="the drive's constant speed [km/h] (80)",
    )
    p.add_argument("--runs", type=count_arg("runs", 1), default=20, help="drives per row (20)")
    p.add_argument("--seed", type=count_arg("seed", 0), default=0, help="random seed (0)")
    p.add_argument(
        "--target",
        type=positive_arg("target", MAX_RANGE_M),
        default=1.0,
        help="the p90 of the 2-D error to meet [m] (1)",
    )
    p.add_argument(
        "--ideal",
        action="store_true",
        help="ideal arrays (no impairment: the optimistic case) instead of calibrated ones",
    )
    p.add_argument(
        "--odometry",
        choices=["white", "automotive"],
        default=None,
        help="the V2X speed and heading messages: the paper's white noise or a car's odometry (a "
        "wheel-speed scale error, a drifting gyro heading bias, 10 Hz, 10 %% lost); default: the "
        "scenario's [odometry] section (the paper's white noise where it has none)",
    )
    p.add_argument(
        "--told-odometry",
        action="store_true",
        help="JAVELIN is told the --odometry model (its scale factor and heading biases as states)",
    )
    p.add_argument("--format", choices=["table", "json"], default="table")
    add_parallel_arguments(p)


def main(args: argparse.Namespace) -> int:
    from ..design import DesignSetup, parse_array
    from ..design.impairments import preset_impairments
    from ..design.longtunnel import long_tunnel_study
    from .reproduce import parallel_kwargs

    specs = [parse_array(a) for a in args.arrays]
    setup = DesignSetup.from_scenario(args.scenario)
    preset = "ideal" if args.ideal else "calibrated"
    res = long_tunnel_study(
        setup,
        specs,
        args.spacings,
        length=args.length,
        speed=args.speed_kmh / 3.6,
        runs=args.runs,
        seed=args.seed,
        target=args.target,
        impairments=preset_impairments(preset, setup, specs),
        odometry=args.odometry,
        told_odometry=args.told_odometry,
        **parallel_kwargs(args),
    )
    if args.format == "json":
        print(json.dumps({"impairments": preset, **res.to_json()}, indent=2))
        return 0
    print(
        f"{setup.name}, {preset} arrays, {res.odometry.label} odometry"
        f"{' (JAVELIN told it)' if res.told_odometry else ''}, a {res.length:g} m drive at "
        f"{args.speed_kmh:g} km/h, "
        f"{res.runs} runs, seed {res.seed} (wall {res.wall_s:.0f} s)\n"
    )
    print(res.table())
    meet = res.meeting()
    print(
        f"\np90 <= {res.target:g} m: "
        + (", ".join(f"{a} every {s:g} m" for a, s in meet) if meet else "none")
    )
    return 0
