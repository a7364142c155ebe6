"""Scenarios: each paper's setup, and your own tunnel, as a validated TOML file.

Presets in ``data/scenarios/`` load by name, your own file by path (:func:`load_scenario`,
:func:`with_values`); a file is validated against its family's schema (:mod:`tunnelkit.schema`)
and its sections with a ``kind`` key are built by registered builders (:func:`register_tunnel`,
:func:`register_trajectory`) into a :class:`Scenario`. Errors are :class:`ScenarioError` naming
the file and the key. How it works: docs/internals/scenarios.md.

    >>> import tunnelkit as tk
    >>> sc = tk.load_scenario("jiang2023-straight")
    >>> traj = sc.trajectory()          # times, positions, velocities
    >>> mine = tk.scenarios.with_values(tk.load_scenario("example-rectangular-28ghz"),
    ...                                 {"base_station.arrays[*].shape": [16, 16]})
"""

from __future__ import annotations

from .._lazy import lazy_exports
from ..schema import ScenarioError
from .checks import MAX_ELEMENTS, MAX_SAMPLES, MAX_TENSOR_BYTES
from .files import (
    ALLOWED_REQUIRES,
    data_dir,
    list_scenarios,
    load_scenario,
    scenario_from_dict,
    scenario_path,
)
from .model import Scenario
from .registry import (
    Trajectory,
    register_arrays,
    register_check,
    register_trajectory,
    register_tunnel,
)

#: loaded on first use (:mod:`tunnelkit._lazy`): a loaded scenario needs no template writer, no
#: editor and no check of every preset
_EXPORTS = {"template": "templates", "with_values": "edit", "check_all": "checkall"}

__all__ = [
    "ALLOWED_REQUIRES",
    "MAX_ELEMENTS",
    "MAX_SAMPLES",
    "MAX_TENSOR_BYTES",
    "Scenario",
    "ScenarioError",
    "Trajectory",
    "check_all",
    "data_dir",
    "list_scenarios",
    "load_scenario",
    "register_arrays",
    "register_check",
    "register_trajectory",
    "register_tunnel",
    "scenario_from_dict",
    "scenario_path",
    "template",
    "with_values",
]
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
