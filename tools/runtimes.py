"""How long each notebook's Run All takes: wall time and the kernel's CPU time, as a table.

    python tools/runtimes.py                 # quick mode (TUNNELKIT_QUICK=1), every notebook
    python tools/runtimes.py 03 07           # only these chapters
    python tools/runtimes.py --full          # full mode (the papers' counts: long)
    python tools/runtimes.py --markdown      # the table of docs/runtimes.md, in markdown

Each notebook runs alone, top to bottom, with nbclient and the ``python3`` kernel (what Run All in
JupyterLab does), one after the other. One extra cell after the last reads the kernel's CPU time
with ``resource.getrusage``: user + system time of the kernel process itself (``RUSAGE_SELF``, all
its threads, BLAS included) and of the child processes it waited for (``RUSAGE_CHILDREN``, e.g. a
local process pool). The kernel's start-up is in both numbers (it is part of Run All too).

Why CPU time: on a machine shared with other work the wall time grows with the load; the CPU time
is what the notebook asks of the machine and is what an idle machine with enough cores takes at
most (less where BLAS runs on two cores at once). It is not strictly load-independent: BLAS
threads that spin while waiting for a core burn CPU, so under a heavy load the CPU time grows too;
``--threads 1`` (``OMP_NUM_THREADS``/``OPENBLAS_NUM_THREADS``/``MKL_NUM_THREADS`` = 1) removes
that and gives a number that depends on the notebook alone. The load average (1 minute) is printed
before and after each notebook.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _lecture import (
    LectureError,
    die,
    kernel_env,
    list_notebooks,
    notebook_client,
    render_table,
    resolve_notebook,
)

MARK = "TUNNELKIT-RUSAGE "
PROBE = f"""import json as _json, resource as _resource
_s, _c = _resource.getrusage(_resource.RUSAGE_SELF), _resource.getrusage(_resource.RUSAGE_CHILDREN)
print({MARK!r} + _json.dumps({{"self": _s.ru_utime + _s.ru_stime, "children": _c.ru_utime + _c.ru_stime}}))
"""
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def measure(path: Path, *, quick: bool, threads: int | None = None, timeout: int = 1800) -> dict:
    """Run one notebook with an extra last cell; its wall time, kernel CPU times, load averages."""
    import nbformat

    nb = nbformat.read(path, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(PROBE))
    env = kernel_env(quick)
    for var in THREAD_VARS:
        if threads:
            env[var] = str(threads)
    saved = dict(os.environ)
    os.environ.clear()
    os.environ.update(env)  # the kernel inherits this process's environment
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    try:
        client = notebook_client(
            nb,
            timeout=timeout,
            kernel_name="python3",
            resources={"metadata": {"path": str(path.parent)}},
        )
        client.execute()
    except Exception as exc:  # a failing cell: say which notebook
        raise LectureError(f"{path.name} failed: {type(exc).__name__}: {exc}") from exc
    finally:
        os.environ.clear()
        os.environ.update(saved)
    wall = time.perf_counter() - t0
    text = "".join(o.get("text", "") for o in nb.cells[-1].outputs if o.get("name") == "stdout")
    line = next((ln for ln in text.splitlines() if ln.startswith(MARK)), None)
    if line is None:
        raise LectureError(f"{path.name}: the CPU-time cell printed nothing ({text!r})")
    cpu = json.loads(line[len(MARK) :])
    return {
        "notebook": path.stem,
        "wall_s": wall,
        "cpu_self_s": cpu["self"],
        "cpu_children_s": cpu["children"],
        "cpu_s": cpu["self"] + cpu["children"],
        "load_before": load0,
        "load_after": os.getloadavg()[0],
    }


def table(rows: list[dict], markdown: bool) -> str:
    head = ("notebook", "kernel CPU [s]", "of which children [s]", "wall [s]", "load avg (1 min)")
    body = [
        (
            r["notebook"],
            f"{r['cpu_s']:.1f}",
            f"{r['cpu_children_s']:.1f}",
            f"{r['wall_s']:.1f}",
            f"{r['load_before']:.1f}-{r['load_after']:.1f}",
        )
        for r in rows
    ]
    return render_table(head, body, markdown)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebooks", nargs="*", help="chapter numbers or names (default: all)")
    ap.add_argument("--full", action="store_true", help="full mode (default: quick mode)")
    ap.add_argument(
        "--threads",
        type=int,
        default=None,
        help="BLAS/OpenMP threads of the kernel (default: as set)",
    )
    ap.add_argument("--timeout", type=int, default=1800, help="seconds per cell (default 1800)")
    ap.add_argument("--markdown", action="store_true", help="print the table as markdown")
    ap.add_argument("--json", type=Path, default=None, help="also write the rows to this file")
    args = ap.parse_args(argv)
    if args.threads is not None and args.threads < 1:
        return die(f"--threads must be at least 1, got {args.threads}")
    try:
        books = [resolve_notebook(n) for n in args.notebooks] or list_notebooks()
    except LectureError as exc:
        return die(str(exc))
    mode = "full" if args.full else "quick"
    print(
        f"{len(books)} notebook(s), {mode} mode, BLAS threads "
        f"{args.threads or 'as set'}, {os.cpu_count()} CPU(s), {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}",
        flush=True,
    )
    rows = []
    for b in books:
        try:
            r = measure(b, quick=not args.full, threads=args.threads, timeout=args.timeout)
        except LectureError as exc:
            return die(str(exc), 1)
        print(
            f"  {r['notebook']}: CPU {r['cpu_s']:.1f} s, wall {r['wall_s']:.1f} s "
            f"(load {r['load_before']:.1f}-{r['load_after']:.1f})",
            flush=True,
        )
        rows.append(r)
    print(table(rows, args.markdown))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
