"""Probe: a few hundred bad inputs over the public callables and the command line.

Each case (``tests/bad_input_cases.py``) runs in a forked child with an address-space limit and a
timeout and is classified as

* ``clear``   -- ValueError/TypeError whose message names the bad parameter;
* ``unclear`` -- ValueError/TypeError that does not name it;
* ``silent``  -- returned a value (a wrong number, NaN or an empty result) without an error;
* ``crash``   -- any other exception, a hang (timeout) or a memory blow-up.

A command line runs as ``python -m tunnelkit`` would, in a child forked from the test process
after every command's module has been imported once (its exit status and standard error are the
interpreter's: ``test_a_forked_command_line_is_the_interpreters`` compares the two).

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
    "tracking.virtual_station tracking.gating tracking.reopening"
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


CLI_ENV = {"TUNNELKIT_QUICK": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def run_cli_case(case) -> tuple[str, str]:
    """(outcome, detail) of one command line run as ``python -m tunnelkit`` in a new interpreter."""
    try:
        res = subprocess.run(
            [sys.executable, "-m", "tunnelkit", *case.argv],
            capture_output=True,
            text=True,
            timeout=CLI_TIMEOUT_S,
            env={**os.environ, **CLI_ENV},
        )
    except subprocess.TimeoutExpired:
        return "crash", f"no answer within {CLI_TIMEOUT_S:g} s (hang)"
    return _classify_cli(res.returncode, res.stderr, case.names)


def _classify_cli(code: int, stderr: str, names) -> tuple[str, str]:
    err = stderr.strip()
    if code == 0:
        return "silent", "exit status 0"
    if "Traceback" in err or code not in (1, 2):
        return "crash", f"exit {code}: {err.splitlines()[-1][:200] if err else ''}"
    if names_parameter(err, names):
        return "clear", err.splitlines()[-1][:200]
    return "unclear", err.splitlines()[-1][:200] if err else f"exit {code}"


def _cli_child(argv, err_fd: int) -> None:
    """In a forked child: what ``python -m tunnelkit ARGV`` does (tunnelkit/__main__.py), its
    standard error to ``err_fd``, its exit status as the interpreter would set it."""
    import traceback as tb

    code = 70
    try:
        os.environ.update(CLI_ENV)
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(err_fd, 2)
        # new streams on the descriptors (a test run's capture may have replaced sys.stdout/err)
        sys.stdout = open(1, "w", closefd=False)
        sys.stderr = open(2, "w", closefd=False, errors="backslashreplace")
        sys.argv = ["tunnelkit", *argv]
        from tunnelkit.cli import main

        try:
            status = main(list(argv))
        except SystemExit as exc:
            status = exc.code
        except BaseException:
            tb.print_exc()
            status = 1
        if status is None or isinstance(status, int):
            code = status or 0
        else:  # sys.exit("message"): printed, status 1
            print(status, file=sys.stderr)
            code = 1
        sys.stdout.flush()
        sys.stderr.flush()
    finally:
        os._exit(code)


def run_cli_case_forked(case) -> tuple[str, str]:
    """``run_cli_case`` in a child forked from this process, where the command line's modules are
    already imported: the same exit status and standard error without a new interpreter per case
    (``test_a_forked_command_line_is_the_interpreters`` compares the two)."""
    import select
    import signal
    import time

    from tunnelkit.cli import build_parser

    build_parser()  # every command's module imported once here, inherited by every child

    read, write = os.pipe()
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(read)
        _cli_child(case.argv, write)
    os.close(write)
    chunks, deadline = [], time.monotonic() + CLI_TIMEOUT_S
    with os.fdopen(read, "rb") as err:
        while time.monotonic() < deadline:
            if select.select([err], [], [], 0.5)[0]:
                chunk = os.read(err.fileno(), 65536)
                if not chunk:
                    break
                chunks.append(chunk)
        else:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return "crash", f"no answer within {CLI_TIMEOUT_S:g} s (hang)"
    _, status = os.waitpid(pid, 0)
    code = os.waitstatus_to_exitcode(status)
    return _classify_cli(code, b"".join(chunks).decode(errors="replace"), case.names)


CASES = build_cases()
CLI_CASES = build_cli_cases()


def run_cli_cases(cases) -> dict[str, tuple[str, str]]:
    """All command lines, one after the other, each in a child forked from this process."""
    return {c.id: run_cli_case_forked(c) for c in cases}


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


def test_a_forked_command_line_is_the_interpreters():
    """The forked run of a command line gives what a new interpreter gives: a clear error, and a
    case that runs without error (``mmax --help``: exit 0) is still seen as silent."""
    from bad_input_cases import CliCase

    for case in (CLI_CASES[0], CliCase("mmax --help", ("mmax", "--help"), ("M",))):
        assert run_cli_case_forked(case) == run_cli_case(case), case.id
    assert run_cli_case_forked(CLI_CASES[0])[0] == "clear"


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
