"""The scenario schema: one declarative spec per family, every file validated against it on load.

A file's family is chosen by its ``paper`` key (``"jiang2023"``, ``"italiano2026"``,
``"halili2022"``; none: your own tunnel, family ``user``). Each family is a :class:`Table` of
:class:`Key` s (:data:`FAMILIES`); the same spec validates a file (:func:`validate`), writes a
template and documents the schema (:mod:`tunnelkit.schemadoc`). Validation is strict: any
problem is a :class:`ScenarioError` naming the file, the section and the key.

How it works: docs/internals/scenarios.md.
"""

import importlib

from .spec import FAMILIES, Key, ScenarioError, Table, family_of, validate

#: names this package held when it was one module, each loaded from its module when asked for
#: (a family's spec only then: a file of one family loads that family's spec alone)
_MOVED = {
    "KEY_TYPES": "spec",
    "shape_text": "spec",
    "validate_table": "spec",
    "JIANG": "jiang",
    "HALILI": "halili",
    "ITALIANO": "tunnel3d",
    "USER": "user",
    "USER_SHAPES": "user",
}


def __getattr__(name: str):
    if name in _MOVED:
        return getattr(importlib.import_module(f"{__name__}.{_MOVED[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "FAMILIES",
    "Key",
    "ScenarioError",
    "Table",
    "family_of",
    "validate",
]
