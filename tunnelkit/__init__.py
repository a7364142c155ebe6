"""tunnelkit — locating a vehicle inside a road tunnel with a single base station.

A small package under a sequence of notebooks (``notebooks/01-...`` to ``06-...``). Submodules
mirror the notebooks and load on first use, so ``import tunnelkit as tk`` stays fast:

``constants, geometry, tunnel2d, crlb, positioning`` (01) · ``fresnel`` (02) · ``arrays,
propagation, channel, extraction, signal_route, evaluation`` (03) · ``tracking`` (04-06) ·
``scenarios, metrics, montecarlo, plots, widgets, reference, reproduce`` (all) · ``notebook``
(``tk.setup_notebook()``, ``tk.solution``, ``tk.build_dir``) · ``_version``.
"""

from __future__ import annotations

import importlib
from typing import Any

from . import scenarios
from ._version import __version__
from .scenarios import list_scenarios, load_scenario

# the builders of a scenario's tunnel, trajectory and arrays live in the modules that define those
# objects and register themselves on import; the first lookup of a built-in kind imports its module
scenarios.registry.set_loader(importlib.import_module)


__all__ = [
    "QUICK",
    "__version__",
    "build_dir",
    "list_scenarios",
    "load_scenario",
    "mc_count",
    "quick_mode",
    "setup_notebook",
    "solution",
]


#: the notebooks' own calls, in :mod:`tunnelkit.notebook` (loaded by the first of them), and
#: quick mode, in :mod:`tunnelkit.montecarlo`: name -> the module that defines it
_ON_FIRST_USE = {
    "build_dir": "notebook",
    "setup_notebook": "notebook",
    "solution": "notebook",
    "QUICK": "montecarlo",
    "mc_count": "montecarlo",
    "quick_mode": "montecarlo",
}


def __dir__() -> list[str]:
    """The package's names with those loaded on first use."""
    return sorted(set(globals()) | set(__all__))


def __getattr__(name: str) -> Any:
    """Load submodules lazily: ``tk.fresnel`` imports ``tunnelkit.fresnel`` on first access; the
    notebooks' calls (``tk.setup_notebook()``) load :mod:`tunnelkit.notebook`, quick mode
    (``tk.QUICK``, ``tk.mc_count``) :mod:`tunnelkit.montecarlo`."""
    if name.startswith("_"):
        raise AttributeError(name)
    if name in _ON_FIRST_USE:
        value = getattr(importlib.import_module(f".{_ON_FIRST_USE[name]}", __name__), name)
        globals()[name] = value
        return value
    try:
        module = importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name == f"{__name__}.{name}":
            raise AttributeError(f"module 'tunnelkit' has no attribute {name!r}") from None
        raise
    globals()[name] = module
    return module
