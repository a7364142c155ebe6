"""The ``tunnelkit`` command line (also ``python -m tunnelkit``).

Sub-commands live in :mod:`tunnelkit.commands`, one module each; a new one needs no edit here.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from collections.abc import Sequence

from . import __version__, commands


def build_parser() -> tuple[argparse.ArgumentParser, dict]:
    parser = argparse.ArgumentParser(
        prog="tunnelkit", description="Single-base-station tunnel positioning workbook."
    )
    parser.add_argument("--version", action="version", version=f"tunnelkit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    handlers = {}
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        mod = importlib.import_module(f"{commands.__name__}.{info.name}")
        p = sub.add_parser(mod.NAME, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(p)
        handlers[mod.NAME] = mod.main
    return parser, handlers


def main(argv: Sequence[str] | None = None) -> int:
    parser, handlers = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(handlers[args.command](args) or 0)
    except (ValueError, TypeError) as exc:
        print(f"tunnelkit {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except TimeoutError as exc:  # a Monte-Carlo run stopped by its time limit (runner.TrialTimeout)
        print(f"tunnelkit {args.command}: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
