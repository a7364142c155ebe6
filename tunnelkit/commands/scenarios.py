"""``tunnelkit scenarios``: list the scenario presets."""

from __future__ import annotations

import argparse

NAME = "scenarios"
HELP = "list the scenario presets in data/scenarios/"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("name", nargs="?", help="show one preset's description")


def main(args: argparse.Namespace) -> int:
    from ..scenarios import list_scenarios, load_scenario

    names = [args.name] if args.name else list_scenarios()
    for n in names:
        sc = load_scenario(n)
        print(f"{sc.name:28s} [{sc.paper}] {sc.description}")
    return 0
