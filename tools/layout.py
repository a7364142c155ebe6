"""The package's layout, measured: import cycles, arrows that run back up, private names imported
across modules, function-local imports and module sizes (``python tools/layout.py``).

Every import counts, the ones inside functions included (a cycle hidden in a function is still a
cycle). A name imported from a package's ``__init__`` is followed to the submodule that defines
it. ``RANKS`` is the intended direction of the signal route (synthesis -> extraction -> tracking
-> simulation -> design): a module may import only from a lower rank or from its own top-level
package; two packages of the same rank (``extraction`` and ``tracking``) may not import each
other. Above the core stands the studies layer (:data:`STUDIES`: research beside the course, the
papers' tables), below the command line: it imports the core, and no core module imports it.
``tests/test_layout.py`` asserts the result.
"""

from __future__ import annotations

import argparse
import ast
import json
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "tunnelkit"
MAX_LINES = 600
#: declarative tables, exempt from the size limit
SIZE_EXEMPT: set[str] = set()
#: the table of names a package ``__init__`` re-exports lazily, name -> submodule
LAZY_TABLE = "_EXPORTS"

#: rank of each top-level module or subpackage of tunnelkit (lower = nearer the ground)
RANKS = {
    "_validate": 0,
    "_lazy": 0,  # a package's names loaded on first use (PEP 562)
    "_checks": 0.25,  # more checks of the validation layer, built on _validate
    "_domains": 0.25,  # checks of structured arrays (weights, SPD matrices, ranges), on _validate
    "_physical": 0.3,  # the hard physical ranges (a carrier, a vehicle's speed), on _validate
    "_parallel": 0.3,  # where trials run (workers or a scheduler address), checked once
    "_scheduler": 0.1,  # a running Dask scheduler's address, checked (imports nothing of ours)
    "_version": 0,  # the package version, imports nothing
    "constants": 0.5,
    "angles": 0.5,  # angles wrapped to (-pi, pi], the bearings' innovations
    "solutions": 0.5,  # the notebooks' solution cells (an IPython magic), imports nothing of ours
    "notebook": 1.2,  # the notebooks' own calls (setup, solutions, build dir), on montecarlo
    "sizes": 0.4,  # sizes in bytes as text (read and written), for the memory budget
    "budget": 0.5,
    "report": 0.5,
    "schema": 0.5,
    "schemadoc": 0.6,  # the schema written out: TOML templates, the Markdown reference
    "geometry": 1,
    "tunnel2d": 1.05,
    "reflection": 1.05,  # where a path reflects off a plane (specular point, eq. 45), on geometry  # Jiang's 2-D tunnel and its virtual stations, on geometry's lines
    "odometry": 1,  # the V2X odometry messages as a model
    "reckoning": 1.1,  # dead reckoning on the odometry messages and its bound
    "crlb": 1,
    "settling": 0.9,  # the settled epochs of a drive (the tracker's start-up left out)
    "metrics": 1,
    "montecarlo": 1,
    "runner": 1.1,  # the Monte-Carlo runner (serial or Dask) over montecarlo's seeds
    "arrays": 1,
    "calibration": 1,  # an array's calibration error, drawn and checked (imports nothing of ours above)
    "scenarios": 2,
    "positioning": 2,
    "fresnel": 2,
    "reference": 3,
    "propagation": 3,
    "tunnels": 3.5,
    "doppler_drive": 3,
    "channel": 4,
    "rt": 4,
    "extraction": 5,
    "tracking": 5,
    "evaluation": 6,
    "signal_route": 7,
    "efficiency": 7,
    "consistency": 3.6,  # the geometry-consistency test of one snapshot's paths (planes only)
    "path_consistency": 7.5,  # the geometry-consistency test on a signal route's epoch
    "simulation": 8,
    "design": 9,
    "plots": 10,
    "widgets": 11,
    "studies": 11.5,  # the studies layer: research beside the course, over the core
    "reproduce": 12,  # the studies layer: the papers' tables (tunnelkit reproduce)
    "commands": 12.5,
    "cli": 13,
    "__main__": 14,
    "": 2.5,  # tunnelkit/__init__.py: quick mode and scenarios, the rest lazily
}


#: the studies layer: every package here ranks above the core (all that ranks lower) and below the
#: command line (which may import it for ``tunnelkit reproduce``)
STUDIES = ("studies", "reproduce")


def _modules(root: Path) -> dict[str, Path]:
    mods = {}
    for p in sorted((root / PACKAGE).rglob("*.py")):
        parts = p.with_suffix("").relative_to(root).parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        mods[name] = p
    return mods


def _is_pkg(mods, name):
    return mods.get(name, Path()).name == "__init__.py"


def _base(mods, name: str, level: int, module: str | None) -> str:
    pkg = name if _is_pkg(mods, name) else name.rsplit(".", 1)[0]
    if level:
        parts = pkg.split(".")
        parts = parts[: len(parts) - (level - 1)]
        return ".".join(parts + ([module] if module else []))
    return module or ""


def _lazy_table(node: ast.stmt) -> dict[str, str]:
    """A package's ``_EXPORTS = {name: "submodule", ...}`` (:mod:`tunnelkit._lazy`), else {}."""
    if not (
        isinstance(node, ast.Assign)
        and [getattr(t, "id", None) for t in node.targets] == [LAZY_TABLE]
        and isinstance(node.value, ast.Dict)
    ):
        return {}
    return {
        ast.literal_eval(k): ast.literal_eval(v) for k, v in zip(node.value.keys, node.value.values)
    }


def analyse(root: Path = ROOT) -> dict:
    mods = _modules(root)
    trees = {n: ast.parse(p.read_text()) for n, p in mods.items()}
    # what each package __init__ re-exports: name -> defining submodule
    reexport: dict[str, dict[str, str]] = defaultdict(dict)
    for n, t in trees.items():
        if not _is_pkg(mods, n):
            continue
        for node in t.body:
            if isinstance(node, ast.ImportFrom):
                b = _base(mods, n, node.level, node.module)
                if b in mods:
                    for a in node.names:
                        reexport[n][a.asname or a.name] = b
            for name, sub in _lazy_table(node).items():  # loaded on first use (tunnelkit._lazy)
                reexport[n][name] = f"{n}.{sub.partition(':')[0]}"

    def target(b: str, name: str) -> str | None:
        if f"{b}.{name}" in mods:
            return f"{b}.{name}"
        if b in mods:
            seen = set()
            while _is_pkg(mods, b) and name in reexport.get(b, {}) and b not in seen:
                seen.add(b)
                b = reexport[b][name]
            return b
        return None

    edges: dict[str, set] = defaultdict(set)
    local_imports, private = [], []
    for n, t in trees.items():
        top_nodes = {id(x) for x in t.body}
        for stmt in t.body:  # module-level if/try blocks count as top level
            if isinstance(stmt, ast.If | ast.Try):
                top_nodes |= {id(x) for x in ast.walk(stmt)}
        for node in ast.walk(t):
            if isinstance(node, ast.ImportFrom):
                b = _base(mods, n, node.level, node.module)
                if not b.startswith(PACKAGE):
                    continue
                is_local = id(node) not in top_nodes
                for a in node.names:
                    tg = target(b, a.name)
                    if tg is None or tg == n:
                        continue
                    edges[n].add(tg)
                    if a.name.startswith("_") and not a.name.startswith("__"):
                        private.append(f"{n} imports {a.name} from {tg}")
                if is_local:
                    local_imports.append(n)
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith(PACKAGE) and a.name in mods and a.name != n:
                        edges[n].add(a.name)
                        if id(node) not in top_nodes:
                            local_imports.append(n)
    # package __init__ -> its own submodules are structure, not dependencies
    graph = {
        n: {m for m in edges[n] if not (_is_pkg(mods, n) and m.startswith(n + "."))} for n in mods
    }
    cycles = _cycles(graph)

    def top(m: str) -> str:
        parts = m.split(".")
        return parts[1] if len(parts) > 1 else ""

    upward, unranked = [], sorted({top(m) for m in mods} - set(RANKS))
    for a, bs in graph.items():
        for b in bs:
            ta, tb = top(a), top(b)
            if ta == tb or ta not in RANKS or tb not in RANKS:
                continue
            if RANKS[tb] >= RANKS[ta]:
                upward.append(f"{a} -> {b}")
    floor = min(RANKS[s] for s in STUDIES)
    core_to_studies = sorted(
        f"{a} -> {b}"
        for a, bs in graph.items()
        for b in bs
        if top(b) in STUDIES and top(a) in RANKS and RANKS[top(a)] < floor
    )
    sizes = {n: len(p.read_text().splitlines()) for n, p in mods.items()}
    big = {n: s for n, s in sizes.items() if s > MAX_LINES and n not in SIZE_EXEMPT}
    return {
        "cycles": cycles,
        "upward": sorted(upward),
        "core_to_studies": core_to_studies,
        "unranked": unranked,
        "private_imports": sorted(private),
        "function_local_imports": len(local_imports),
        "over_limit": dict(sorted(big.items(), key=lambda kv: -kv[1])),
        "modules": len(mods),
    }


def _cycles(graph: dict[str, set]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in graph:
                    continue
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return sorted(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    r = analyse()
    if a.json:
        print(json.dumps(r, indent=2))
        return 0
    print(f"modules: {r['modules']}")
    print(f"import cycles: {len(r['cycles'])}")
    for c in r["cycles"]:
        print("   ", " <-> ".join(c))
    print(f"arrows that run back up: {len(r['upward'])}")
    for u in r["upward"]:
        print("   ", u)
    print(f"core modules importing the studies layer: {len(r['core_to_studies'])}")
    for u in r["core_to_studies"]:
        print("   ", u)
    print(f"private names imported across modules: {len(r['private_imports'])}")
    for p in r["private_imports"]:
        print("   ", p)
    print(f"function-local imports: {r['function_local_imports']}")
    print(f"modules over {MAX_LINES} lines: {len(r['over_limit'])}")
    for n, s in r["over_limit"].items():
        print(f"    {n}: {s}")
    if r["unranked"]:
        print("unranked:", r["unranked"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
