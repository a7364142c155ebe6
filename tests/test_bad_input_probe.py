"""Probe: a few hundred bad inputs over the public callables and the command line.

Each case (``tests/bad_input_cases.py``) runs in a forked child with an address-space limit and a
timeout and is classified as

* ``clear``   -- ValueError/TypeError whose message names the bad parameter;
* ``unclear`` -- ValueError/TypeError that does not name it;
* ``silent``  -- returned a value (a wrong number, NaN or an empty result) without an error;
* ``crash``   -- any other exception, a hang (timeout) or a memory blow-up.

The test asserts zero ``silent``, zero ``crash`` and zero ``unclear``. Run this file as a script
for the table of counts (``python tests/test_bad_input_probe.py``; put the tree to probe first on
``PYTHONPATH``).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import re
import subprocess
import sys
import traceback
from collections import Counter
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bad_input_cases import build_cases, build_cli_cases

OUTCOMES = ("clear", "unclear", "silent", "crash")
TIMEOUT_S = 30.0  # a heavy in-process case
CLI_TIMEOUT_S = 90.0  # one command line (importing scipy alone takes seconds on a busy machine)
HEAVY_LIMIT_BYTES = 3 * 1024**3  # address space a heavy child may add before MemoryError


def names_parameter(message: str, names) -> bool:
    """True when ``message`` mentions one of ``names`` as a whole word (``--runs`` counts as runs)."""
    return any(
        re.search(rf"(?<![A-Za-z0-9_]){re.escape(n)}(?![A-Za-z0-9_])", message) for n in names
    )


def _vm_size() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def _child(case, heavy: bool, conn) -> None:
    import resource
    import warnings

    if heavy:
        lim = _vm_size() + HEAVY_LIMIT_BYTES
        resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
    warnings.simplefilter("ignore")
    try:
        case.call()
    except (ValueError, TypeError) as exc:
        conn.send(("error", type(exc).__name__, str(exc)))
    except BaseException as exc:
        conn.send(("other", type(exc).__name__, "".join(traceback.format_exception_only(exc))))
    else:
        conn.send(("return", "", ""))
    conn.close()


_WARM = (
    "constants geometry crlb positioning fresnel arrays propagation metrics montecarlo doppler_drive "
    "scenarios channel tracking.doppler tracking.upf tracking.pcrlb tracking.cv "
    "tracking.virtual_station tracking.gating"
).split()


def _warm_up() -> None:
    """Import every probed module once in the parent so forked children start warm."""
    import importlib

    for m in _WARM:
        importlib.import_module(f"tunnelkit.{m}")


def _classify(kind: str, exc: str, msg: str, names) -> tuple[str, str]:
    if kind == "return":
        return "silent", "returned without an error"
    if kind == "other":
        return "crash", f"{exc}: {msg.strip()[:200]}"
    if names_parameter(msg, names):
        return "clear", f"{exc}: {msg[:200]}"
    return "unclear", f"{exc}: {msg[:200]}"


def run_case(case) -> tuple[str, str]:
    """(outcome, detail) of one case: cheap ones in this process, heavy ones in a forked child
    with an address-space limit and a timeout (they may hang or exhaust memory)."""
    _warm_up()
    if not case.heavy:
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                case.call()
            except (ValueError, TypeError) as exc:
                return _classify("error", type(exc).__name__, str(exc), case.names)
            except Exception as exc:
                return _classify("other", type(exc).__name__, str(exc), case.names)
            return _classify("return", "", "", case.names)
    ctx = mp.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(case, case.heavy, send))
    proc.start()
    send.close()
    got = recv.poll(TIMEOUT_S)
    if not got:
        proc.kill()
        proc.join()
        return "crash", f"no answer within {TIMEOUT_S:g} s (hang)"
    try:
        kind, exc, msg = recv.recv()
    except EOFError:
        proc.join()
        return "crash", f"child died (exit code {proc.exitcode})"
    proc.join()
    return _classify(kind, exc, msg, case.names)


def run_cli_case(case) -> tuple[str, str]:
    env = dict(os.environ, TUNNELKIT_QUICK="1", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    try:
        res = subprocess.run(
            [sys.executable, "-m", "tunnelkit", *case.argv],
            capture_output=True,
            text=True,
            timeout=CLI_TIMEOUT_S,
            env=env,
        )
    except subprocess.TimeoutExpired:
        return "crash", f"no answer within {CLI_TIMEOUT_S:g} s (hang)"
    err = res.stderr.strip()
    if res.returncode == 0:
        return "silent", "exit status 0"
    if "Traceback" in err or res.returncode not in (1, 2):
        return "crash", f"exit {res.returncode}: {err.splitlines()[-1][:200] if err else ''}"
    if names_parameter(err, case.names):
        return "clear", err.splitlines()[-1][:200]
    return "unclear", err.splitlines()[-1][:200] if err else f"exit {res.returncode}"


CASES = build_cases()
CLI_CASES = build_cli_cases()


def run_cli_cases(cases) -> dict[str, tuple[str, str]]:
    """All command lines, two at a time."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(2) as pool:
        return dict(zip((c.id for c in cases), pool.map(run_cli_case, cases)))


def probe() -> dict[str, list[tuple[str, str, str]]]:
    """Run everything; {"api": [(id, outcome, detail)], "cli": [...]}."""
    api = [(c.id, *run_case(c)) for c in CASES]
    res = run_cli_cases(CLI_CASES)
    cli = [(c.id, *res[c.id]) for c in CLI_CASES]
    return {"api": api, "cli": cli}


def table(results) -> str:
    lines = [f"{'':8s} " + " ".join(f"{o:>8s}" for o in (*OUTCOMES, "total"))]
    total = Counter()
    for part, rows in results.items():
        cnt = Counter(o for _, o, _ in rows)
        total.update(cnt)
        lines.append(
            f"{part:8s} " + " ".join(f"{cnt[o]:8d}" for o in OUTCOMES) + f" {len(rows):8d}"
        )
    lines.append(
        f"{'all':8s} " + " ".join(f"{total[o]:8d}" for o in OUTCOMES) + f" {sum(total.values()):8d}"
    )
    return "\n".join(lines)


def test_case_ids_unique_and_enough():
    ids = [c.id for c in CASES] + [c.id for c in CLI_CASES]
    assert len(ids) == len(set(ids))
    assert len(CASES) >= 300 and len(CLI_CASES) >= 15


def test_names_parameter():
    assert names_parameter("runs: must be >= 1", ("runs",))
    assert names_parameter("argument --runs: invalid int value", ("runs",))
    assert not names_parameter("truns: bad", ("runs",))
    assert not names_parameter("index 3 is out of bounds", ("p",))


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input_gets_a_clear_error(case):
    outcome, detail = run_case(case)
    assert outcome == "clear", f"{case.id}: {outcome} ({detail})"


@pytest.fixture(scope="module")
def cli_results():
    return run_cli_cases(CLI_CASES)


@pytest.mark.parametrize("case", CLI_CASES, ids=[c.id for c in CLI_CASES])
def test_bad_command_line_gets_a_clear_error(case, cli_results):
    outcome, detail = cli_results[case.id]
    assert outcome == "clear", f"{case.id}: {outcome} ({detail})"


if __name__ == "__main__":  # pragma: no cover - the measurement behind the report
    res = probe()
    verbose = "-v" in sys.argv
    for part, rows in res.items():
        for cid, outcome, detail in rows:
            if verbose or outcome != "clear":
                print(f"{part:4s} {outcome:8s} {cid}: {detail}")
    print()
    print(table(res))
