"""Serve one notebook as a live dashboard with Voila on 127.0.0.1 (code hidden, widgets live).

    python tools/present.py 02            # free port, full mode
    python tools/present.py 02 --port 8866 --quick
    python tools/present.py 02 --view explorers   # only the cells tagged "explorer"

The notebook is executed by Voila's kernel when the page opens; explorers build their figure with
its initial state before display, so the page shows the right state when it connects. Ctrl-C (or
SIGTERM) stops Voila and its kernel. ``--view explorers`` serves a reduced copy of the notebook
(``build/present/NN-name.explorers.ipynb``: the setup cell and the cells tagged ``explorer``).
Exit status 2 for an unknown notebook or view, a notebook without explorers, or a port in use; 1
when Voila does not come up.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _lecture import (
    BUILD,
    HOST,
    IPC_TRANSPORT_FLAG,
    VIEWS,
    LectureError,
    check_port,
    die,
    explorers_notebook,
    free_port,
    kernel_env,
    resolve_notebook,
    start_server,
    stop_server,
    wait_http,
)

#: Voila's lab template with the exercises' solutions collapsed (tools/jupyter/voila/templates/);
#: Voila finds it through JUPYTER_PATH (voila_env)
TEMPLATE = "tunnelkit"
JUPYTER_DATA = Path(__file__).resolve().parent / "jupyter"


def voila_env(quick: bool) -> dict[str, str]:
    """The environment of Voila and its kernel: kernel_env, and JUPYTER_PATH led by the directory
    that holds the tunnelkit template."""
    env = kernel_env(quick)
    env["JUPYTER_PATH"] = os.pathsep.join(
        p for p in (str(JUPYTER_DATA), env.get("JUPYTER_PATH", "")) if p
    )
    return env


def voila_command(notebook: Path, port: int) -> list[str]:
    """The Voila command line for one notebook on 127.0.0.1:port, sources stripped.

    Its kernels talk over Unix sockets in Voila's own temporary directory, not TCP ports, so a
    kernel started beside another process's cannot be handed a port that one takes
    (``notebook_client`` in _lecture.py says more).
    """
    return [
        sys.executable,
        "-m",
        "voila",
        str(notebook),
        f"--port={port}",
        f"--Voila.ip={HOST}",
        "--no-browser",
        "--strip_sources=True",
        "--theme=light",
        f"--template={TEMPLATE}",
        "--VoilaConfiguration.show_tracebacks=True",
        "--Voila.open_browser=False",
        IPC_TRANSPORT_FLAG,
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebook", help="chapter number (02), name (02-fresnel-...) or path")
    ap.add_argument(
        "--port", type=int, default=None, help="port on 127.0.0.1 (default: a free one)"
    )
    ap.add_argument(
        "--quick", action="store_true", help="TUNNELKIT_QUICK=1 (small Monte-Carlo counts)"
    )
    ap.add_argument(
        "--timeout", type=float, default=90.0, help="seconds to wait for Voila to answer"
    )
    ap.add_argument(
        "--view",
        default="all",
        help=f"what to serve: {' or '.join(VIEWS)} (only the cells tagged 'explorer')",
    )
    args = ap.parse_args(argv)
    try:
        if args.view not in VIEWS:
            raise LectureError(f"unknown view {args.view!r}; choose one of: {', '.join(VIEWS)}")
        nb = resolve_notebook(args.notebook)
        port = check_port(args.port) if args.port is not None else free_port()
        if args.view == "explorers":
            nb = explorers_notebook(nb)
    except LectureError as exc:
        return die(str(exc))
    url = f"http://{HOST}:{port}/"
    log = BUILD / "logs" / f"voila-{port}.log"
    log.parent.mkdir(parents=True, exist_ok=True)

    def _stop(signum, _frame):
        raise KeyboardInterrupt

    # SIGTERM acts like Ctrl-C, installed before the start so that a stop always reaches `finally`
    signal.signal(signal.SIGTERM, _stop)
    proc = None
    try:
        proc = start_server(voila_command(nb, port), env=voila_env(args.quick), log=log)
        wait_http(url + "api", proc, args.timeout)
        mode = "quick" if args.quick else "full"
        print(
            f"presenting {nb.name} ({mode} mode, view {args.view}) at {url}  "
            f"(log: {log}; Ctrl-C to stop)",
            flush=True,
        )
        proc.wait()
        return die(f"Voila exited with code {proc.returncode}; see {log}", 1)
    except LectureError as exc:
        tail = log.read_text(errors="replace").splitlines()[-15:] if log.exists() else []
        return die(f"{exc}\n" + "\n".join(tail), 1)
    except KeyboardInterrupt:
        print("stopping Voila", flush=True)
        return 0
    finally:
        if proc is not None:
            stop_server(proc, timeout=8.0)  # well inside the 15 s a caller's stop_server grants


if __name__ == "__main__":
    sys.exit(main())
