"""Generated contracts of the command line: every option of every sub-command that takes a value
is probed with values no run may accept (NaN, +-inf, 1e300, -1e300, and the physical probes of
:func:`contracts.physical_bads` for options named like a physical quantity or a count: a carrier
in GHz, an entry fix of 100 km, 10^10 units). Nothing here lists options: they come from the
parser (:func:`tunnelkit.cli.build_parser`), so a new option is probed the day it is added.

Each probe must end in a clear refusal: exit status 2 and the option named on stderr (``--opt``
or its parameter name), within a few seconds (the run is stopped there: a probe still running
was accepted)."""

from __future__ import annotations

import argparse
import re
import signal
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from contracts import physical_bads

from tunnelkit.cli import build_parser, main

#: the positional arguments each sub-command needs for a valid call
POSITIONALS = {
    "design": ["example-rectangular-28ghz"],
    "reproduce": ["jiang-crlb"],
    "mmax": [],
    "long-tunnel": ["example-rectangular-28ghz"],
    "scenarios": [],
}
#: seconds a probe may take to be refused (validation is at the boundary; the first probe of a
#: command also imports it)
PROBE_S = 20.0
#: values no numeric option accepts (text as typed on the command line)
ALWAYS_BAD = ("nan", "inf", "-inf", "1e300", "-1e300")
#: probes whose value is right for that option, each with its reason
DOCUMENTED = {
    ("design", "--spacing", "above-range"): "in wavelengths: 100 of them is 1.07 m at 28 GHz, "
    "within an element spacing's physical range",
}


def _numeric(a) -> bool:
    """An option whose value is a number (a file path or a name is not probed here)."""
    try:
        return isinstance(a.type("1"), int | float)
    except Exception:  # a parser that refuses "1" takes something else (a name, a path)
        return False


def _options():
    parser, _ = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for command, p in sorted(sub.choices.items()):
        for a in p._actions:
            if a.option_strings and a.type is not None and _numeric(a):
                yield command, a


def _probes():
    out = []
    for command, a in _options():
        flag = a.option_strings[-1]
        is_int = a.type is int or a.dest in {"seed", "workers", "n_epochs", "units", "max_units"}
        values = [(v, v) for v in ALWAYS_BAD]
        kind = "int" if is_int else "float"
        for bad in physical_bads(a.dest, kind, None):
            values.append((bad.label, repr(bad.value) if kind == "float" else str(bad.value)))
        for label, v in values:
            if (command, flag, label) in DOCUMENTED:
                continue
            out.append(pytest.param(command, flag, a.dest, v, id=f"{command}{flag}={label}"))
    return out


class _Accepted(BaseException):
    pass


def _stop(signum, frame):
    raise _Accepted


@pytest.mark.parametrize(("command", "flag", "dest", "value"), _probes())
def test_every_option_refuses_impossible_values_naming_itself(command, flag, dest, value, capsys):
    argv = [command, *POSITIONALS.get(command, []), f"{flag}={value}"]
    old = signal.signal(signal.SIGALRM, _stop)
    signal.setitimer(signal.ITIMER_REAL, PROBE_S)
    try:
        try:
            status = main(argv)
        except SystemExit as exc:  # argparse's own refusal
            status = exc.code
        except _Accepted:
            pytest.fail(f"tunnelkit {' '.join(argv)}: still running after {PROBE_S:g} s (accepted)")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
    err = capsys.readouterr().err
    assert status == 2, f"tunnelkit {' '.join(argv)}: exit {status}, not refused\n{err[-400:]}"
    names = {flag, dest, dest.replace("_", "-"), flag.lstrip("-")}
    assert any(re.search(rf"(?<![\w-]){re.escape(n)}(?![\w])", err) for n in names), (
        f"tunnelkit {' '.join(argv)}: refused without naming {flag}: {err[-400:]}"
    )


def test_the_probes_reach_every_option_and_the_physical_classes():
    probes = _probes()
    flags = {(p.values[0], p.values[1]) for p in probes}
    assert flags == {(c, a.option_strings[-1]) for c, a in _options()}
    ids = " ".join(p.id for p in probes)
    for label in ("GHz-for-Hz", "spread-too-wide", "beyond-budget"):
        assert label in ids, f"no {label} probe generated"
