"""Shared helpers of the lecture tools (present.py, site.py, figures.py) and the browser tests.

* notebook discovery (every ``notebooks/*.ipynb``, so chapters added later are picked up) and
  resolution of a short name such as ``02`` to its file;
* loopback ports (a free one, or a clear error when the asked one is taken);
* starting a server in its own process group and stopping it by its process id;
* kernels that talk over Unix sockets in a private temporary directory, not TCP ports (see
  ``notebook_client``);
* headless execution of a notebook (cached under ``build/executed/``) with plotly figures emitted
  as JSON (``PLOTLY_RENDERER=plotly_mimetype``) so no output refers to a CDN;
* extraction of the plotly figures of an executed notebook, including the live ``FigureWidget`` of
  an explorer (read back from the saved widget state);
* headline figures: a code cell containing a line ``# headline: <name>`` declares that the figure
  it displays is a headline figure of its notebook (see tools/figures.py).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
import weakref
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from _widget_dump import add_widget_dump, take_widget_dump

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
BUILD = ROOT / "build"
EXECUTED = BUILD / "executed"
HOST = "127.0.0.1"
HEADLINE = re.compile(r"^\s*#\s*headline:\s*([A-Za-z0-9][A-Za-z0-9_.-]*)\s*$", re.MULTILINE)
PLOTLY_MIME = "application/vnd.plotly.v1+json"
WIDGET_MIME = "application/vnd.jupyter.widget-view+json"
WIDGET_STATE = "application/vnd.jupyter.widget-state+json"
#: Debian's Chromium: kaleido (tools/figures.py) and the browser tests drive it.
CHROMIUM = "/usr/bin/chromium"


class LectureError(RuntimeError):
    """A user-facing failure: the tools print its message and exit non-zero."""


# ---------------------------------------------------------------- notebooks


def list_notebooks(directory: Path = NOTEBOOKS) -> list[Path]:
    """Every notebook of the workbook, in chapter order."""
    return sorted(p for p in directory.glob("*.ipynb") if not p.name.startswith("."))


def resolve_notebook(name: str, directory: Path = NOTEBOOKS) -> Path:
    """``02``, ``2``, ``02-fresnel-bound-and-mmax``, its ``.ipynb`` name or a path -> the notebook."""
    p = Path(name)
    if p.suffix == ".ipynb" and p.is_file():
        return p.resolve()
    books = list_notebooks(directory)
    stem = p.name.removesuffix(".ipynb")
    if stem.isdigit():
        hits = [
            b
            for b in books
            if b.stem.split("-", 1)[0].isdigit() and int(b.stem.split("-", 1)[0]) == int(stem)
        ]
    else:
        hits = [b for b in books if b.stem == stem] or [b for b in books if b.stem.startswith(stem)]
    if len(hits) == 1:
        return hits[0]
    known = ", ".join(b.stem for b in books) or "none"
    why = "is ambiguous" if hits else "does not exist"
    raise LectureError(f"notebook {name!r} {why}; notebooks in {directory}: {known}")


EXPLORER_TAG = "explorer"
EXPLORER_SETUP_TAG = "explorer-setup"
VIEWS = ("all", "explorers")


def _tags(cell) -> list[str]:
    return list(cell.get("metadata", {}).get("tags", []))


def explorers_notebook(path: Path, out_dir: Path | None = None) -> Path:
    """A reduced copy of a notebook for a lecture: its setup cell, then only the cells tagged
    ``explorer`` (the explorers and the text that introduces them).

    Cells tagged ``explorer-setup`` (what an explorer needs from earlier cells) run too, their
    output captured. Written whole to ``build/present/<name>.explorers.ipynb``; raises
    LectureError, writing nothing, when the notebook tags no explorer.
    """
    import nbformat

    nb = nbformat.read(path, as_version=4)
    cells = nb.cells
    code = [i for i, c in enumerate(cells) if c.cell_type == "code"]
    picked = [i for i, c in enumerate(cells) if EXPLORER_TAG in _tags(c)]
    if not code or not any(cells[i].cell_type == "code" for i in picked):
        src = path.parent / ".src" / f"{path.stem}.py"
        raise LectureError(
            f"{path.name} has no code cell tagged {EXPLORER_TAG!r}, so VIEW=explorers has nothing "
            f"to show (tag a cell in {src.relative_to(ROOT) if src.is_relative_to(ROOT) else src}: "
            f'`# %% tags=["{EXPLORER_TAG}"]`); VIEW=all serves the whole notebook'
        )
    title = title_of(nb, path.stem)
    out_cells = [
        nbformat.v4.new_markdown_cell(
            f"# {title}: the explorers\n\nOnly the interactive parts of `{path.name}`; the whole "
            f"chapter is `make present NB={path.stem.split('-', 1)[0]}`."
        )
    ]
    for i, c in enumerate(cells):
        tags = _tags(c)
        if i == code[0] or EXPLORER_TAG in tags:
            out_cells.append(c)
        elif EXPLORER_SETUP_TAG in tags and c.cell_type == "code":
            quiet = nbformat.v4.new_code_cell("%%capture\n" + _source(c))
            out_cells.append(quiet)
    reduced = nbformat.v4.new_notebook(cells=out_cells, metadata=nb.metadata)
    for k, c in enumerate(reduced.cells):
        c["id"] = f"explorers-{k:03d}"
    out_dir = out_dir or BUILD / "present"
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{path.stem}.explorers.ipynb"
    tmp = target.with_name(f".{target.name}.tmp")
    nbformat.write(reduced, tmp)
    tmp.replace(target)
    return target


def title_of(nb: dict[str, Any], fallback: str) -> str:
    """The first markdown heading of a notebook (its chapter title)."""
    for cell in nb.get("cells", []):
        if cell.get("cell_type") == "markdown":
            for line in _source(cell).splitlines():
                if line.startswith("#"):
                    # markdown emphasis and code marks are not shown as such in an HTML title
                    return re.sub(r"(\*{1,2}|`)([^*`]+)\1", r"\2", line.lstrip("#").strip())
    return fallback


def _source(cell: dict[str, Any]) -> str:
    src = cell.get("source", "")
    return "".join(src) if isinstance(src, list) else src


# ---------------------------------------------------------------- ports and servers


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def check_port(port: int) -> int:
    """Return ``port`` if it can be bound on 127.0.0.1, else raise a clear LectureError."""
    if not 1 <= port <= 65535:
        raise LectureError(f"port {port} is out of range (1-65535)")
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        try:
            s.bind((HOST, port))
        except OSError as exc:
            raise LectureError(
                f"port {port} on {HOST} is already in use ({exc.strerror}); "
                "pick another with PORT=... or leave it out for a free one"
            ) from None
    return port


def start_server(
    cmd: list[str], *, env: dict[str, str] | None = None, log: Path | None = None, cwd: Path = ROOT
) -> subprocess.Popen:
    """Start ``cmd`` in a new process group (so stop_server can end it and its kernels)."""
    with open(log or os.devnull, "wb") as out:  # the child keeps its own copy of the descriptor
        return subprocess.Popen(
            cmd,
            cwd=cwd,
            env=env,
            stdout=out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )


def stop_server(proc: subprocess.Popen, timeout: float = 15.0) -> int | None:
    """SIGTERM the process group led by ``proc.pid``, SIGKILL it if it lingers; return the code."""
    for sig, wait in ((signal.SIGTERM, timeout), (signal.SIGKILL, 5.0)):
        if proc.poll() is not None:
            break
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, sig)
        with contextlib.suppress(subprocess.TimeoutExpired):
            proc.wait(wait)
    # children (kernels) may outlive the leader: end what is left of its group
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(proc.pid, signal.SIGKILL)
    return proc.poll()


def child_pids(pid: int) -> list[int]:
    """Direct children of ``pid`` (Linux /proc); empty if it is gone."""
    try:
        return [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except (FileNotFoundError, ProcessLookupError):
        return []


def alive(pid: int, wait: float = 0.0) -> bool:
    """True while ``pid`` runs (a zombie counts as ended); polls up to ``wait`` seconds for it to end."""
    deadline = time.monotonic() + wait
    while True:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except (FileNotFoundError, ProcessLookupError):
            return False
        if state == "Z":
            return False
        if time.monotonic() >= deadline:
            return True
        time.sleep(0.05)


def wait_http(url: str, proc: subprocess.Popen, timeout: float = 90.0) -> None:
    """Poll ``url`` until it answers; raise if the server exits or the time runs out."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise LectureError(
                f"the server exited with code {proc.returncode} before answering at {url}"
            )
        try:
            with urllib.request.urlopen(url, timeout=2):
                return
        except urllib.error.HTTPError:
            return  # it answers (a 404 still means it is up)
        except (urllib.error.URLError, OSError):
            time.sleep(0.3)
    raise LectureError(f"no answer from {url} within {timeout:.0f} s")


@contextlib.contextmanager
def serving(
    cmd: list[str],
    url: str,
    *,
    env: dict[str, str] | None = None,
    log: Path | None = None,
    timeout: float = 90.0,
) -> Iterator[subprocess.Popen]:
    """Context manager: start a server, wait until ``url`` answers, always stop it by pid."""
    proc = start_server(cmd, env=env, log=log)
    try:
        wait_http(url, proc, timeout)
        yield proc
    finally:
        stop_server(proc)


@contextlib.contextmanager
def serving_on_free_port(
    make_cmd,
    path: str = "api",
    *,
    attempts: int = 3,
    env: dict[str, str] | None = None,
    log: Path | None = None,
    timeout: float = 90.0,
) -> Iterator[tuple[subprocess.Popen, str]]:
    """``serving`` on a port found free: yields ``(process, base URL)``.

    ``free_port`` binds and releases, so another process may take the port before the server binds
    it; the server then exits before answering. That case is tried again on a new port, up to
    ``attempts`` times (a server that runs but does not answer is not retried: that is a real
    failure). ``make_cmd(port)`` builds the command; ``path`` is polled under the base URL.
    """
    for attempt in range(1, attempts + 1):
        port = free_port()
        base = f"http://{HOST}:{port}/"
        proc = start_server(make_cmd(port), env=env, log=log)
        try:
            wait_http(base + path, proc, timeout)
        except LectureError:
            exited = proc.poll() is not None
            stop_server(proc)
            if exited and attempt < attempts:
                continue
            raise
        try:
            yield proc, base
        finally:
            stop_server(proc)
        return


def lab_command(port: int, root: Path, *extra: str) -> list[str]:
    """JupyterLab serving ``root`` on ``HOST:port``: no browser, no token or password, no news
    feed (every request stays on the loopback), kernels over IPC, no silent move to another port,
    as root where need be; ``extra`` switches after."""
    return [
        sys.executable,
        "-m",
        "jupyterlab",
        "--no-browser",
        f"--port={port}",
        f"--ServerApp.ip={HOST}",
        "--IdentityProvider.token=",
        "--ServerApp.password=",
        f"--ServerApp.root_dir={root}",
        "--LabApp.news_url=",
        "--ServerApp.port_retries=0",  # a port taken meanwhile ends the server: the caller retries
        IPC_TRANSPORT_FLAG,  # kernels on Unix sockets: no TCP port race between kernels
        *extra,
        "--allow-root",
    ]


def render_table(head: tuple[str, ...], body: list[tuple[str, ...]], markdown: bool) -> str:
    """Rows of strings as a markdown table or as aligned text (first column left-aligned)."""
    if markdown:
        lines = ["| " + " | ".join(head) + " |", "| " + " | ".join("---" for _ in head) + " |"]
        return "\n".join(lines + ["| " + " | ".join(b) + " |" for b in body])
    widths = [max(len(x) for x in col) for col in zip(head, *body, strict=True)]
    return "\n".join(
        "  ".join(x.ljust(w) if i == 0 else x.rjust(w) for i, (x, w) in enumerate(zip(r, widths)))
        for r in (head, *body)
    )


# ---------------------------------------------------------------- execution


#: Voila's command-line switch for the same transport; Voila keeps each kernel's sockets in its own
#: temporary connection directory (``voila_*`` under the system temporary directory).
IPC_TRANSPORT_FLAG = "--KernelManager.transport=ipc"


def notebook_client(nb, **kwargs):
    """An nbclient ``NotebookClient`` whose kernel listens on Unix sockets, not on TCP ports.

    With jupyter_client's default TCP transport the kernel manager picks five free ports by binding
    and releasing them, so two processes starting kernels at the same moment can be handed the same
    port: the kernel dies with ``ZMQError: Address already in use``, or one kernel's messages reach
    another's client ("Invalid Signature"). Here the five channels (and the connection file) live
    in a new directory of this process's own under the system temporary directory, which no other
    kernel uses; it is removed once the notebook has run and its kernel is shut down (or, if the
    kernel never started, when the client is collected). ``kwargs`` go to ``NotebookClient``.
    """
    from nbclient import NotebookClient
    from traitlets.config import Config

    ipc_dir = Path(tempfile.mkdtemp(prefix="tunnelkit-kernel-"))
    config = Config(kwargs.pop("config", None) or {})
    config.KernelManager.transport = "ipc"
    config.KernelManager.ip = str(ipc_dir / "kernel")  # sockets kernel-1 ... kernel-5
    config.KernelManager.connection_file = str(ipc_dir / "kernel.json")
    then = kwargs.pop("on_notebook_complete", None)

    def complete(**hook):  # nbclient runs this after the kernel's shutdown
        shutil.rmtree(ipc_dir, ignore_errors=True)
        return then(**hook) if then else None

    client = NotebookClient(nb, config=config, on_notebook_complete=complete, **kwargs)
    weakref.finalize(client, shutil.rmtree, ipc_dir, ignore_errors=True)
    return client


def kernel_env(quick: bool, solutions: bool = False) -> dict[str, str]:
    """Environment of an executing kernel: quick mode or not, plotly figures as JSON, and the
    exercises' solutions run at once (``TUNNELKIT_SOLUTIONS=1``, tunnelkit.solutions: the static
    site) or, by default, only when the reader asks for them (JupyterLab, Voila)."""
    env = dict(os.environ)
    env["PLOTLY_RENDERER"] = "plotly_mimetype"
    for var, on in (("TUNNELKIT_QUICK", quick), ("TUNNELKIT_SOLUTIONS", solutions)):
        if on:
            env[var] = "1"
        else:
            env.pop(var, None)
    return env


def inputs_digest(path: Path, quick: bool) -> str:
    """What an executed copy depends on: the notebook, this module, the package, the data."""
    h = hashlib.sha256(path.read_bytes())
    h.update(b"quick" if quick else b"full")
    for rule in (Path(__file__), Path(__file__).with_name("_widget_dump.py")):
        h.update(rule.read_bytes())  # these modules decide how notebooks are executed
    for base in (ROOT / "tunnelkit", ROOT / "data"):
        for f in sorted(base.rglob("*")):
            if f.is_file() and "__pycache__" not in f.parts:
                h.update(str(f.relative_to(ROOT)).encode())
                h.update(f.read_bytes())
    return h.hexdigest()


def execute(path: Path, *, quick: bool, timeout: int = 1800, use_cache: bool = True):
    """Execute a notebook headless (widget state kept), every exercise's solution included, and
    return it as a NotebookNode.

    The result is cached in ``build/executed/`` keyed on the notebook, the package sources, the
    data files and the mode, so ``make figures`` after ``make site`` does not run it again (nor
    the browser tests' site build after ``make notebooks``: tools/nbmake_cache.py).
    """
    import nbformat
    from nbclient.exceptions import CellExecutionError, CellTimeoutError, DeadKernelError

    digest = inputs_digest(path, quick)
    cached = executed_path(path, quick)
    if use_cache and cached.exists():
        nb = nbformat.read(cached, as_version=4)
        if nb.metadata.get("tunnelkit_lecture", {}).get("digest") == digest:
            return nb
    nb = nbformat.read(path, as_version=4)
    saved = dict(os.environ)
    env = kernel_env(quick, solutions=True)  # before the clear below, or it would start empty
    os.environ.clear()
    os.environ.update(env)  # the kernel inherits this process's environment
    try:
        add_widget_dump(nb)
        client = notebook_client(
            nb,
            timeout=timeout,
            kernel_name="python3",
            store_widget_state=True,
            resources={"metadata": {"path": str(path.parent)}},
        )
        client.execute()
    except (CellExecutionError, CellTimeoutError, DeadKernelError) as exc:
        plain = re.sub(r"\x1b\[[0-9;]*m", "", str(exc))  # the traceback comes with ANSI colours
        raise LectureError(f"{path.name} failed to execute:\n{plain}") from None
    finally:
        os.environ.clear()
        os.environ.update(saved)
    return store_executed(nb, path, quick, digest)


def executed_path(path: Path, quick: bool) -> Path:
    """Where ``execute`` keeps a notebook's executed copy."""
    return EXECUTED / f"{path.stem}.{'quick' if quick else 'full'}.ipynb"


def store_executed(nb, path: Path, quick: bool, digest: str):
    """Take the dump cell off a notebook run by ``execute``'s rules, keep the figures it printed and
    the inputs' digest in its metadata, and write it to the cache (whole, or not at all)."""
    import nbformat

    live = take_widget_dump(nb)
    nb.metadata["tunnelkit_lecture"] = {"digest": digest, "quick": quick, "figure_widgets": live}
    cached = executed_path(path, quick)
    cached.parent.mkdir(parents=True, exist_ok=True)
    tmp = cached.with_name(f".{cached.name}.{os.getpid()}.tmp")
    nbformat.write(nb, tmp)
    tmp.replace(cached)
    return nb


# ---------------------------------------------------------------- figures in an executed notebook


@dataclass
class FoundFigure:
    """One plotly figure displayed by a code cell of an executed notebook."""

    cell: int  #: index of the code cell in the notebook
    output: int  #: index of the output in that cell
    figure: dict[str, Any]  #: plotly JSON: {"data": [...], "layout": {...}}
    widget: bool  #: True when it is the live FigureWidget of an explorer
    headline: str | None  #: name from a ``# headline: <name>`` line of the cell, if any


def live_figures(nb) -> dict[str, dict[str, Any]]:
    """model_id -> final figure of each FigureWidget, as dumped by ``execute`` (empty if none)."""
    return nb.metadata.get("tunnelkit_lecture", {}).get("figure_widgets", {})


def widget_states(nb) -> dict[str, dict[str, Any]]:
    """model_id -> widget model state saved with the notebook (empty if none)."""
    return nb.metadata.get("widgets", {}).get(WIDGET_STATE, {}).get("state", {})


def with_buffers(model: dict[str, Any]) -> dict[str, Any]:
    """A widget model's state with its binary buffers (numpy arrays) put back as plain lists.

    Saved widget state keeps arrays apart, as base64 ``buffers`` with a path into the state; the
    state holds ``{"dtype", "shape"}`` at that path.
    """
    import base64
    import copy

    import numpy as np

    state = copy.deepcopy(model.get("state", {}))
    for buf in model.get("buffers", []):
        *path, last = buf["path"]
        node = state
        for key in path[:-1]:
            node = node[key]
        spec = node[path[-1]] if path else None
        raw = (
            base64.b64decode(buf["data"])
            if buf.get("encoding", "base64") == "base64"
            else buf["data"]
        )
        if isinstance(spec, dict) and last == "buffer" and "dtype" in spec:
            arr = np.frombuffer(raw, dtype=spec["dtype"]).reshape(spec.get("shape", -1))
            node[path[-1]] = arr.tolist()
        else:
            node = node[path[-1]] if path else node
            node[last] = raw
    return state


def widget_figures(
    model_id: str, states: dict[str, dict[str, Any]], live: dict[str, dict[str, Any]] | None = None
) -> list[dict[str, Any]]:
    """Plotly figures held by a widget or any of its descendants (a FigureWidget in an explorer).

    ``live`` (model id -> figure, dumped from the kernel after the last cell) wins over the saved
    widget state, which misses the changes a FigureWidget sent as deltas.
    """
    found, todo, seen = [], [model_id], set()
    while todo:
        mid = todo.pop(0)
        if mid in seen or mid not in states:
            continue
        seen.add(mid)
        st = with_buffers(states[mid])
        if live and mid in live:
            found.append(live[mid])
        elif "_widget_data" in st and "_widget_layout" in st:
            found.append({"data": st["_widget_data"], "layout": st["_widget_layout"]})
        for child in st.get("children", []) or []:
            if isinstance(child, str) and child.startswith("IPY_MODEL_"):
                todo.append(child.removeprefix("IPY_MODEL_"))
    return found


def output_figures(
    output: dict[str, Any], states: dict[str, dict[str, Any]], live: dict[str, dict[str, Any]]
) -> tuple[list[dict[str, Any]], bool]:
    """The plotly figures one cell output displays, and whether the output is a widget.

    A plotly output gives its one figure; a widget output (an explorer) the figures held by the
    widget or its descendants (possibly none); any other output none.
    """
    data = output.get("data", {})
    if PLOTLY_MIME in data:
        fig = data[PLOTLY_MIME]
        return [json.loads(fig) if isinstance(fig, str) else dict(fig)], False
    if WIDGET_MIME in data:
        return widget_figures(data[WIDGET_MIME]["model_id"], states, live), True
    return [], False


def is_progress_bar(model_id: str, states: dict[str, dict[str, Any]]) -> bool:
    """True for a tqdm progress bar (an HBox holding a FloatProgress) or a widget closed since it
    was displayed (tqdm's ``leave=False`` bars): outputs a static page should drop."""
    if model_id not in states:
        return True
    children = states[model_id].get("state", {}).get("children", []) or []
    kids = [str(c).removeprefix("IPY_MODEL_") for c in children]
    return any(states.get(k, {}).get("model_name") == "FloatProgressModel" for k in kids)


def figures_of(nb) -> list[FoundFigure]:
    """Every plotly figure an executed notebook displays, in order."""
    states = widget_states(nb)
    live = live_figures(nb)
    out: list[FoundFigure] = []
    for ci, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        m = HEADLINE.search(_source(cell))
        name = m.group(1) if m else None
        for oi, o in enumerate(cell.get("outputs", [])):
            figs, widget = output_figures(o, states, live)
            out.extend(FoundFigure(ci, oi, fig, widget, name) for fig in figs)
    return out


def die(message: str, code: int = 2) -> int:
    """Print a user-facing error to stderr and return the exit code."""
    print(f"error: {message}", file=sys.stderr)
    return code
