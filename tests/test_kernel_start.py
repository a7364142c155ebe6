"""Kernels start beside other processes that start kernels and take ports.

The site build (tools/site.py) executes notebooks in a process pool; each starts a kernel through
``_lecture.execute``. With TCP, a kernel's five ports are picked by binding and releasing them, and a
port taken by someone else in between kills the kernel (``Address already in use``). The kernels
listen on Unix sockets in a private directory instead; here four chapters are rendered at once
through the site build's own worker while another process keeps binding ephemeral ports on
127.0.0.1, and every kernel must start, over IPC, each in its own directory.
"""

from __future__ import annotations

import multiprocessing as mp
import socket
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import _lecture as lec  # noqa: E402

KERNELS = 4
PORT_TAKER_SECONDS = 40.0  # the port taker stops by itself after this, or when told
PORT_TAKER_MAX_HELD = 256  # sockets held at once
PORT_TAKER_MAX_BINDS = 400_000  # binds in all

CELLS = [
    "import json, ipykernel.connect\ninfo = json.loads(ipykernel.connect.get_connection_info())",
    "print(info['transport'], info['ip'])",
]


def _tools_site():
    """tools/site.py as a module (its name clashes with the standard ``site`` module)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("tunnelkit_site", ROOT / "tools" / "site.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _render(path: str, out: str) -> list[str]:
    """One chapter as the site build's pool renders it; returns what its second cell printed."""
    lec.EXECUTED = Path(out) / "executed"  # a cache of this test's own, never a hit
    site = _tools_site()
    entry = site._render((Path(path), Path(out), True, None, None, 60))
    assert (Path(out) / entry["page"]).is_file()
    nb = nbformat.read(lec.EXECUTED / f"{Path(path).stem}.quick.ipynb", as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    return "".join(o.get("text", "") for o in code[1].outputs).split()


def _take_ports(stop, started) -> None:
    """Bind ephemeral ports on 127.0.0.1 and release them, over and over, until told to stop."""
    held: list[socket.socket] = []
    end = time.monotonic() + PORT_TAKER_SECONDS
    started.set()
    try:
        for n in range(PORT_TAKER_MAX_BINDS):
            if stop.is_set() or time.monotonic() > end:
                break
            s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            s.bind(("127.0.0.1", 0))
            held.append(s)
            if len(held) >= PORT_TAKER_MAX_HELD:
                for old in held[: PORT_TAKER_MAX_HELD // 2]:
                    old.close()
                del held[: PORT_TAKER_MAX_HELD // 2]
            if n % 64 == 0:
                time.sleep(0.001)  # leave the two cores to the kernels now and then
    finally:
        for s in held:
            s.close()


def test_kernels_start_beside_port_takers_and_each_other(tmp_path):
    books = []
    for k in range(KERNELS):
        nb = nbformat.v4.new_notebook(
            cells=[nbformat.v4.new_markdown_cell(f"# Kernel {k}")]
            + [nbformat.v4.new_code_cell(c) for c in CELLS],
            metadata={"kernelspec": {"name": "python3", "display_name": "Python 3"}},
        )
        path = tmp_path / f"{k:02d}-kernel.ipynb"
        nbformat.write(nb, path)
        books.append(path)
    out = tmp_path / "site"
    out.mkdir()

    ctx = mp.get_context()
    stop, started = ctx.Event(), ctx.Event()
    taker = ctx.Process(target=_take_ports, args=(stop, started), daemon=True)
    taker.start()
    t0 = time.perf_counter()
    try:
        assert started.wait(10), "the port taker did not start"
        with ProcessPoolExecutor(max_workers=KERNELS) as pool:
            futures = [pool.submit(_render, str(b), str(out)) for b in books]
            printed = [f.result(timeout=120) for f in futures]
    finally:
        stop.set()
        taker.join(10)
        if taker.is_alive():
            taker.kill()
            taker.join(5)
    seconds = time.perf_counter() - t0
    assert [p[0] for p in printed] == ["ipc"] * KERNELS, printed
    dirs = [Path(p[1]).parent for p in printed]
    assert len(set(dirs)) == KERNELS, f"kernels shared an IPC directory: {dirs}"
    assert all(not d.exists() for d in dirs), "an IPC directory was left behind"
    assert seconds < 90, f"{KERNELS} kernels took {seconds:.0f} s"
