"""Edited copies of a scenario (:func:`with_values`): dotted keys of its file replaced, the
result validated again as a file is."""

from __future__ import annotations

import copy
import re
from typing import Any

from ..schema import ScenarioError
from .files import scenario_from_dict
from .model import Scenario

__all__ = ["with_values"]

_INDEX_RE = re.compile(r"(\w+)\[(\d+|\*)\]")


def with_values(scenario: Scenario, changes: dict[str, Any]) -> Scenario:
    """A copy of ``scenario`` with dotted keys of its file replaced, validated again.

    ``{"radio.fc": 28e9, "base_station.position": [0, 0, 5.5],
    "base_station.arrays[*].shape": [16, 16], "base_station.arrays[0].tilt_deg": 10.0}``;
    ``[*]`` sets the key in every table of the array. Setting a value to ``None`` removes the key.
    Raises :class:`ScenarioError` naming the key if the result is invalid (design sweeps).
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a Scenario, got {type(scenario).__name__}")
    if not isinstance(changes, dict):
        raise TypeError(f"changes: expected a dict of dotted keys, got {type(changes).__name__}")
    raw = copy.deepcopy(scenario.raw)
    for dotted, value in changes.items():
        if not isinstance(dotted, str) or not dotted:
            raise TypeError(f"changes: keys must be dotted key strings, got {dotted!r}")
        *parents, last = dotted.split(".")
        targets = [raw]
        for part in parents:
            m = _INDEX_RE.fullmatch(part)
            name, idx = (m.group(1), m.group(2)) if m else (part, None)
            nxt = []
            for t in targets:
                if idx is None:
                    nxt.append(t.setdefault(name, {}))
                    continue
                arr = t.get(name)
                if not isinstance(arr, list):
                    raise ScenarioError(
                        f"{scenario.path.name}: '{dotted}': no array of tables {name!r}"
                    )
                if idx == "*":
                    nxt.extend(arr)
                elif int(idx) < len(arr):
                    nxt.append(arr[int(idx)])
                else:
                    raise ScenarioError(
                        f"{scenario.path.name}: '{dotted}': {name} has {len(arr)} tables"
                    )
            targets = nxt
        for t in targets:
            if not isinstance(t, dict):
                raise ScenarioError(f"{scenario.path.name}: '{dotted}': not a table")
            if value is None:
                t.pop(last, None)
            else:
                t[last] = copy.deepcopy(value)
    return scenario_from_dict(raw, scenario.path)
