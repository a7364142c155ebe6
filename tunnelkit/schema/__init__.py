"""The scenario schema: one declarative spec per family, every file validated against it on load.

A scenario file belongs to one *family*, chosen by its ``paper`` key:

* ``paper = "jiang2023"``: Jiang's 2-D tunnel (two wall lines, a 2-D base station, noise levels);
* ``paper = "italiano2026"``: the JAVELIN tunnel (semicircular facets, RRMs, URAs, 5G SRS radio);
* ``paper = "halili2022"``: Halili's drive (plain sections read into ``drive.DriveConfig``);
* no ``paper`` key: **your own tunnel** (family ``user``): a rectangular, semicircular or
  horseshoe tunnel, a base station with ULAs/URAs, a radio and a lane or slalom trajectory.

Each family is a :class:`Table` of :class:`Key` s (type, unit, range, default, doc string). The same
spec validates a file (:func:`validate`), writes a commented template and documents the schema
(:mod:`tunnelkit.schemadoc`: ``render_template``, ``to_markdown``, printed by ``tunnelkit scenarios
doc``), so the three never drift apart. Validation is strict:
``shape = [10.5, 10]``, a bool or a string where a number is expected, NaN, a value out of range,
a missing required key and an unknown key (reported with the nearest valid name) are all a
:class:`ScenarioError` naming the file, the section and the key.

Modules: :mod:`.spec` (keys, tables, validation, :data:`FAMILIES` by name), then one per family's
spec, imported when a file of that family is first read: :mod:`.jiang`, :mod:`.halili` and
:mod:`.tunnel3d` (the JAVELIN tunnel and your own, which share their tables).
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
    "USER": "tunnel3d",
    "USER_SHAPES": "tunnel3d",
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
