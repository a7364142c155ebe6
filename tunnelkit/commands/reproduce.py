"""``tunnelkit reproduce TARGET [--runs N] [--seed S] [--channel image|sionna]
[--second-order N] [--diffuse-floor] [--length METRES] [--odometry white|automotive]
[--told-odometry] [--motion-step held|midpoint] [--workers N | --scheduler ADDRESS]
[--format table|json]``."""

from __future__ import annotations

import argparse
import sys

NAME = "reproduce"
HELP = "reproduce a paper's result (Monte-Carlo), paper beside ours"


def add_arguments(p: argparse.ArgumentParser) -> None:
    from ..reproduce import targets

    names = list(targets())
    p.add_argument("target", choices=names, metavar="TARGET", help="one of: " + ", ".join(names))
    p.add_argument(
        "--runs", type=int, default=None, help="Monte-Carlo runs (default: the target's)"
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the random generator (default 0)")
    p.add_argument("--format", choices=["table", "json"], default="table")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.add_argument(
        "--channel",
        choices=["image", "sionna"],
        default="image",
        help="channel source: the image method's eq. 1 (default) or the ray-traced channel "
        "(Sionna RT, every path per element, traced once and cached; javelin-table1|2 only; "
        "adds the traced design's column: sigmas measured on that channel, geometry pre-filter; "
        "its sigmas belong to the route with --diffuse-floor; the line of sight told by "
        "elevation; and, condition L, the direct fit under JAVELIN on its own drives)",
    )
    p.add_argument(
        "--second-order",
        type=int,
        default=0,
        metavar="N",
        help="the route's model also fits the N strongest second-order specular paths the image "
        "method predicts, left out of the tracker's measurements (javelin-table1|2 only; 0)",
    )
    p.add_argument(
        "--diffuse-floor",
        action="store_true",
        help="with --channel sionna: the ML fit tested against noise + the epoch's diffuse power",
    )
    p.add_argument(
        "--length",
        type=float,
        default=None,
        metavar="METRES",
        help="drive over this many metres, ending where the preset's drive ends (e.g. 120: UE "
        "ranges 5-125 m in a lengthened tunnel; javelin-table1 only, image channel)",
    )
    p.add_argument(
        "--odometry",
        choices=["white", "automotive"],
        default="white",
        help="the V2X speed and heading messages' model: the paper's white noise (default) or "
        "automotive odometry (a wheel-speed scale error, a drifting gyro heading bias, 10 Hz, "
        "10 %% lost; tunnelkit.odometry); javelin-table1|2 only",
    )
    p.add_argument(
        "--told-odometry",
        action="store_true",
        help="JAVELIN is told the --odometry model (the scale factor and heading biases as "
        "states of its filter); javelin-table1|2 with --odometry automotive only",
    )
    p.add_argument(
        "--motion-step",
        choices=["held", "midpoint"],
        default=None,
        help="how every JAVELIN steps on the messages: the previous epoch's held over the step "
        "(eq. 62) or the mean of the two epochs' (midpoint: the chord of a steady turn); by "
        "default each design its own (the paper's eq. 62, ours the midpoint); "
        "javelin-table1|2 only",
    )
    add_parallel_arguments(p)


def _seconds(param: str):
    """argparse type: a time in seconds, > 0 and at most a day; errors name ``param``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{param}: expected seconds, got {text!r}") from None
        if not 0 < value <= 86400:
            raise argparse.ArgumentTypeError(f"{param}: must be in (0, 86400] s, got {text!r}")
        return value

    return parse


def add_parallel_arguments(p: argparse.ArgumentParser) -> None:
    """``--workers N | --scheduler ADDRESS`` and ``--connect-timeout`` (any command whose trials
    go through :func:`tunnelkit.runner.run_trials`; pass them on with :func:`parallel_kwargs`)."""
    from ..runner import CONNECT_TIMEOUT_S

    par = p.add_mutually_exclusive_group()
    par.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="run the trials on a local Dask cluster of N processes (default: serial)",
    )
    par.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="run the trials on a running Dask cluster, e.g. tcp://HOST:8786",
    )
    p.add_argument(
        "--connect-timeout",
        type=_seconds("connect_timeout"),
        default=CONNECT_TIMEOUT_S,
        metavar="SECONDS",
        help=f"give up on --scheduler after this long (default {CONNECT_TIMEOUT_S:g})",
    )


def add_trial_timeout(p: argparse.ArgumentParser, trial: str, note: str = "") -> None:
    """``--trial-timeout SECONDS|none`` (``args.trial_timeout``): how long a run waits for a
    ``trial`` to finish before it stops (:data:`tunnelkit.runner.TRIAL_TIMEOUT_S`)."""
    from .._parallel import TRIAL_TIMEOUT_S

    seconds = _seconds("trial_timeout")
    p.add_argument(
        "--trial-timeout",
        type=lambda text: None if text.strip().lower() == "none" else seconds(text),
        default=TRIAL_TIMEOUT_S,
        metavar="SECONDS|none",
        help=f"stop when no {trial} has finished for this long (default {TRIAL_TIMEOUT_S:g} s; "
        f"none: no limit){'. ' + note if note else ''}",
    )


def parallel_kwargs(args: argparse.Namespace) -> dict:
    """``workers``, ``scheduler`` and ``timeout`` for ``run_trials`` from the parsed arguments."""
    return {"workers": args.workers, "scheduler": args.scheduler, "timeout": args.connect_timeout}


def main(args: argparse.Namespace) -> int:
    from ..reproduce import run, targets
    from ..rt import RTUnavailableError
    from ..runner import TrialLost

    chans = targets()[args.target].channels
    if args.channel not in chans:
        print(
            f"tunnelkit reproduce: error: --channel {args.channel}: {args.target} runs on "
            f"{', '.join(chans)} only",
            file=sys.stderr,
        )
        return 2
    nuisance = {}
    if args.second_order:
        nuisance["second_order"] = args.second_order
    if args.diffuse_floor:
        if args.channel != "sionna":
            print(
                "tunnelkit reproduce: error: --diffuse-floor needs --channel sionna",
                file=sys.stderr,
            )
            return 2
        nuisance["diffuse_floor"] = True
    if nuisance and len(chans) == 1:
        print(
            f"tunnelkit reproduce: error: --second-order/--diffuse-floor: {args.target} has no "
            "route model to extend (javelin-table1|2 only)",
            file=sys.stderr,
        )
        return 2
    if args.length is not None and not targets()[args.target].lengths:
        print(
            f"tunnelkit reproduce: error: --length: {args.target} drives its preset only "
            "(javelin-table1 only)",
            file=sys.stderr,
        )
        return 2
    if args.told_odometry and args.odometry == "white":
        print(
            "tunnelkit reproduce: error: --told-odometry: needs --odometry automotive (JAVELIN is "
            "told the white model by default)",
            file=sys.stderr,
        )
        return 2
    asked = [f for f, on in (("--odometry", args.odometry != "white"),
                             ("--motion-step", args.motion_step is not None)) if on]  # fmt: skip
    if asked and not targets()[args.target].odometries:
        print(
            f"tunnelkit reproduce: error: {asked[0]}: {args.target} has no V2X messages to model "
            "or track on (javelin-table1|2 only)",
            file=sys.stderr,
        )
        return 2
    try:
        rep = run(
            args.target,
            runs=args.runs,
            seed=args.seed,
            progress=(args.format == "table" and not args.no_progress),
            channel=args.channel,
            nuisance=nuisance or None,
            length=args.length,
            odometry=args.odometry,
            told_odometry=args.told_odometry,
            motion_step=args.motion_step,
            **parallel_kwargs(args),
        )
    except (TrialLost, RTUnavailableError) as exc:
        print(f"tunnelkit reproduce: error: {exc}", file=sys.stderr)
        return 1
    print(rep.to_json() if args.format == "json" else rep.to_table())
    return 0
