"""Registry of interchangeable estimators, grouped by family (``"jiang2023"``, ``"halili2022"``,
``"italiano2026"``).

``@register(family_name, name)`` registers a factory (a class or a function returning a
configured estimator); ``family(family_name)`` gives ``{name: factory}`` in registration order,
:func:`get` one member and :func:`families` the names; modules declared with :func:`provide` are
imported on the first lookup of their family. One call protocol per family: every member is
built and run the same way (``tests/test_registry.py`` runs each through it) and its ``name`` is
its registered name. Each family's protocol in full: docs/internals/tracking.md.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from .._validate import text

__all__ = ["families", "family", "get", "provide", "register"]

_REG: dict[str, dict[str, Callable[..., Any]]] = {}
#: family -> modules to import before the family is looked up (keeps ``import tunnelkit`` light)
_PROVIDERS: dict[str, list[str]] = {}


def provide(family_name: str, module: str) -> None:
    """Declare that importing ``module`` registers members of ``family_name``."""
    text("family_name", family_name), text("module", module)
    _PROVIDERS.setdefault(family_name, [])
    if module not in _PROVIDERS[family_name]:
        _PROVIDERS[family_name].append(module)


def register(family_name: str, name: str):
    """Decorator registering ``obj`` as ``name`` in ``family_name``."""
    text("family_name", family_name), text("name", name)

    def deco(obj):
        fam = _REG.setdefault(family_name, {})
        if name in fam and fam[name] is not obj:
            raise ValueError(f"name: {name!r} registered twice in family {family_name!r}")
        fam[name] = obj
        return obj

    return deco


def _load(family_name: str) -> None:
    for mod in _PROVIDERS.get(family_name, []):
        importlib.import_module(mod)


def families() -> list[str]:
    """Known family names."""
    return sorted(set(_REG) | set(_PROVIDERS))


def family(family_name: str) -> dict[str, Callable[..., Any]]:
    """All members of a family: those of its providers in the order they were declared (each
    module's in its registration order), then any registered directly; the same order whichever
    module was imported first."""
    _load(family_name)
    if family_name not in _REG:
        raise ValueError(f"family_name: unknown family {family_name!r}; known: {families()}")
    mods = _PROVIDERS.get(family_name, [])
    members = list(_REG[family_name].items())

    def rank(item) -> int:
        mod = getattr(item[1], "__module__", "") or ""
        hits = [k for k, p in enumerate(mods) if mod == p or mod.startswith(p + ".")]
        return hits[0] if hits else len(mods)

    return dict(sorted(members, key=rank))  # a stable sort keeps each module's own order


def get(family_name: str, name: str) -> Callable[..., Any]:
    """One member, e.g. ``get("jiang2023", "UPF")``; imports the family's modules only until one
    has registered ``name``."""
    for mod in _PROVIDERS.get(family_name, []):
        if name in _REG.get(family_name, {}):
            return _REG[family_name][name]
        importlib.import_module(mod)
    fam = family(family_name)
    if name not in fam:
        raise ValueError(f"name: {name!r} is not in family {family_name!r}; members: {list(fam)}")
    return fam[name]
