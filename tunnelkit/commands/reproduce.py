"""``tunnelkit reproduce TARGET [--runs N] [--seed S] [--format table|json]``."""

from __future__ import annotations

import argparse

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


def main(args: argparse.Namespace) -> int:
    from ..reproduce import run

    rep = run(
        args.target,
        runs=args.runs,
        seed=args.seed,
        progress=(args.format == "table" and not args.no_progress),
    )
    print(rep.to_json() if args.format == "json" else rep.to_table())
    return 0
