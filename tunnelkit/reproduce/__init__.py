"""Registry of ``tunnelkit reproduce`` targets: one paper result each, "paper" beside "ours".

Adding a target is one module in this package with one decorated function::

    @register("jiang-crlb", help="...", default_runs=2000)
    def jiang_crlb(runs: int, seed: int, progress: bool, **parallel) -> Report: ...

``parallel`` holds ``workers``, ``scheduler`` and ``timeout``; the target passes them on to
:func:`tunnelkit.montecarlo.run_trials`, through which all its random trials go (module-level
trial functions bound with ``functools.partial``, so Dask can ship them to other processes). The
report must not depend on them: the same seed gives the same numbers serially or on N workers.

Modules here are imported on first use of :data:`REGISTRY` via :func:`targets`.
"""

from __future__ import annotations

import importlib
import json
import math
import pkgutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from .._validate import integer, positive
from ..montecarlo import CONNECT_TIMEOUT_S, parallel_options

__all__ = ["Report", "Target", "register", "run", "targets"]


@dataclass
class Report:
    """A table of results with notes; renders as text or JSON."""

    title: str
    columns: Sequence[str]
    rows: list[Sequence[Any]]
    notes: list[str] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)

    def records(self) -> list[dict[str, Any]]:
        """Rows as dicts keyed by column name."""
        return [dict(zip(self.columns, r)) for r in self.rows]

    def to_json(self) -> str:
        """Machine-readable form: title, meta, columns, rows (as records) and notes."""

        def clean(v):
            if isinstance(v, float) and not math.isfinite(v):
                return None
            return v

        recs = [{k: clean(v) for k, v in r.items()} for r in self.records()]
        return json.dumps(
            {
                "title": self.title,
                "meta": self.meta,
                "columns": list(self.columns),
                "rows": recs,
                "notes": self.notes,
            },
            indent=2,
        )

    def to_table(self) -> str:
        """Plain-text table for a terminal."""

        def fmt(v):
            if v is None:
                return "-"
            if isinstance(v, float):
                return "-" if not math.isfinite(v) else f"{v:.4g}"
            return str(v)

        cells = [[fmt(v) for v in r] for r in self.rows]
        widths = [
            max(len(str(c)), *(len(r[i]) for r in cells)) if cells else len(str(c))
            for i, c in enumerate(self.columns)
        ]
        line = "  ".join(str(c).ljust(w) for c, w in zip(self.columns, widths))
        out = [self.title, "=" * len(self.title)]
        out += [f"{k}: {v}" for k, v in self.meta.items()]
        out += ["", line, "-" * len(line)]
        out += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
        if self.notes:
            out += [""] + [f"* {n}" for n in self.notes]
        return "\n".join(out)


@dataclass(frozen=True)
class Target:
    """A registered reproduction: ``fn(runs, seed, progress, **parallel) -> Report``."""

    name: str
    help: str
    default_runs: int
    fn: Callable[..., Report]


_REGISTRY: dict[str, Target] = {}
_DISCOVERED = False


def register(name: str, *, help: str, default_runs: int):
    """Decorator registering a reproduction target under ``name``."""

    def deco(fn):
        if name in _REGISTRY:
            raise ValueError(f"name: reproduce target {name!r} registered twice")
        _REGISTRY[name] = Target(name, help, default_runs, fn)
        return fn

    return deco


def targets() -> dict[str, Target]:
    """All targets, importing every module of this package once."""
    global _DISCOVERED
    if not _DISCOVERED:
        for mod in pkgutil.iter_modules(__path__):
            importlib.import_module(f"{__name__}.{mod.name}")
        _DISCOVERED = True
    return dict(sorted(_REGISTRY.items()))


def run(
    name: str,
    *,
    runs: int | None = None,
    seed: int = 0,
    progress: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float = CONNECT_TIMEOUT_S,
) -> Report:
    """Run target ``name`` with ``runs`` Monte-Carlo runs (its default if None) and ``seed``,
    serially or on Dask (``workers`` local processes, or a running ``scheduler``; see
    :func:`tunnelkit.montecarlo.run_trials`). The report is the same either way."""
    reg = targets()
    if name not in reg:
        raise ValueError(f"name: unknown reproduce target {name!r}; available: {', '.join(reg)}")
    tgt = reg[name]
    runs = tgt.default_runs if runs is None else integer("runs", runs, minimum=1)
    seed = integer("seed", seed, minimum=0)
    workers, scheduler = parallel_options(workers, scheduler)
    timeout = positive("timeout", timeout)
    rep = tgt.fn(runs, seed, progress, workers=workers, scheduler=scheduler, timeout=timeout)
    rep.meta = {"target": name, "runs": runs, "seed": seed, **rep.meta}
    return rep
