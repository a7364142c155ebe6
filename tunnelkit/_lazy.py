"""A package's names loaded on first use (PEP 562), so importing one submodule loads no other.

A package ``__init__`` lists what it re-exports in a table, name -> defining submodule
(``"route_bounds": "bounds"``; ``"PRESETS_ALIAS": "impairments:PRESETS"`` for a name exported
under another), its ``__all__`` the table's names (one list, not two) and takes its module
``__getattr__`` and ``__dir__`` from :func:`lazy_exports`::

    _EXPORTS = {"DesignSetup": "setup", "route_bounds": "bounds"}
    __all__ = sorted(_EXPORTS)
    __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)

``pkg.route_bounds`` and ``from pkg import route_bounds`` import ``pkg.bounds`` the first time and
keep the object on the package; ``pkg.bounds`` (a submodule by its own name) imports it. The table
must be named ``_EXPORTS`` and be a literal: ``tools/layout.py`` reads it to follow a name
imported from the package to the submodule that defines it.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable


def lazy_exports(
    package: str, table: dict[str, str]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The module ``__getattr__`` and ``__dir__`` of ``package`` re-exporting ``table`` lazily."""

    def __getattr__(name: str) -> object:
        where = table.get(name)
        if where is None:
            if name.startswith("_"):
                raise AttributeError(f"module {package!r} has no attribute {name!r}")
            try:  # a submodule by its own name
                return importlib.import_module(f".{name}", package)
            except ModuleNotFoundError as exc:
                if exc.name != f"{package}.{name}":
                    raise
                raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        module, _, attr = where.partition(":")
        value = getattr(importlib.import_module(f".{module}", package), attr or name)
        setattr(sys.modules[package], name, value)  # later lookups skip __getattr__
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(table))

    return __getattr__, __dir__
