"""``tunnelkit scenarios [NAME|PATH ...]``, ``scenarios show NAME``, ``scenarios new NAME --from PRESET``.

Without an action every named scenario (default: every preset in ``data/scenarios/``) is loaded
and validated against its family's schema; one line per scenario, and exit status 1 with the
message if any is malformed. ``show`` prints one scenario's validated sections (defaults filled);
``doc`` prints the schema as Markdown tables (``data/scenarios/README.md``); ``new`` writes ``NAME.toml``, a commented template holding the preset's values, into the current
directory (or ``--out DIR``) and refuses to overwrite an existing file.
"""

from __future__ import annotations

import argparse
import json
import sys
import tomllib
from pathlib import Path

NAME = "scenarios"
HELP = "validate and list scenarios; `scenarios new NAME --from PRESET` writes your own"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "words",
        nargs="*",
        metavar="ARG",
        help="scenario names or .toml paths to validate (default: every preset); "
        "or `show NAME`; or `new NAME --from PRESET [--out DIR]`; or `doc` (the schema)",
    )
    p.add_argument(
        "--from",
        dest="preset",
        default="example-rectangular-28ghz",
        help="preset (or .toml path) the new scenario copies (default example-rectangular-28ghz)",
    )
    p.add_argument(
        "--out", default=".", help="directory the new scenario is written to (default .)"
    )


def main(args: argparse.Namespace) -> int:
    from ..scenarios import load_scenario, scenario_from_dict, template
    from ..scenarios.checkall import check_all

    words = list(args.words)
    if words and words[0] == "new":
        if len(words) != 2:
            raise ValueError(
                "new: expected exactly one NAME, e.g. `scenarios new my-tunnel --from PRESET`"
            )
        name = words[1]
        text = template(name, args.preset)
        out = Path(args.out)
        if not out.is_dir():
            raise ValueError(f"--out: {str(out)!r} is not a directory")
        path = out / f"{name}.toml"
        if path.exists():
            raise ValueError(f"NAME: {str(path)!r} already exists; choose another name or --out")
        scenario_from_dict(tomllib.loads(text), path)  # the template validates before it is written
        path.write_text(text)
        print(f"wrote {path} (from {args.preset}); edit it, then: tunnelkit scenarios {path}")
        return 0
    if words == ["doc"]:
        from ..schemadoc import to_markdown

        print(to_markdown())
        return 0
    if words and words[0] == "show":
        if len(words) != 2:
            raise ValueError("show: expected exactly one NAME")
        sc = load_scenario(words[1])
        print(f"{sc.name} [{sc.family}] {sc.path}")
        print(json.dumps(sc.sections, indent=2))
        return 0
    bad = 0
    for name, err in check_all(words or None):
        if err is None:
            sc = load_scenario(name)
            print(f"{sc.name:28s} [{sc.paper or 'user'}] {sc.description}")
        else:
            bad += 1
            print(f"tunnelkit scenarios: error: {err}", file=sys.stderr)
    return 1 if bad else 0
