"""Scenarios: each paper's setup, and your own tunnel, as a validated TOML file.

Presets live in ``data/scenarios/`` and load by name; your own file loads by path
(``load_scenario("my-tunnel.toml")``). A file has a few top-level keys (``name``, ``paper``,
``description``) and sections (``[tunnel]``, ``[base_station]``, ``[radio]``, ``[trajectory]``
...). Its ``paper`` key picks the family whose schema (:mod:`tunnelkit.schema`) it is validated
against on load; without ``paper`` it is your own tunnel (family ``user``, shapes in
:mod:`tunnelkit.tunnels`). Sections with a ``kind`` key are built into objects by a registered
builder (``tunnel.kind = "walls2d"`` gives a :class:`tunnelkit.geometry.Tunnel2D`,
``"rectangular"`` a :class:`tunnelkit.propagation.Tunnel3D`), see :func:`register_tunnel` /
:func:`register_trajectory`. Errors are :class:`ScenarioError` naming the file and the key.

    >>> import tunnelkit as tk
    >>> sc = tk.load_scenario("jiang2023-straight")
    >>> traj = sc.trajectory()          # times, positions, velocities
    >>> mine = tk.scenarios.with_values(tk.load_scenario("example-rectangular-28ghz"),
    ...                                 {"base_station.arrays[*].shape": [16, 16]})

The package holds the files and the builder registry only; the builders live with the objects
they build and register themselves on import:

- :mod:`.registry` — the registries of builders by kind (one call protocol each), :class:`Trajectory`;
- :mod:`.model` — :class:`Scenario`, a loaded file and the objects its builders make;
- :mod:`.files` — finding, reading and validating files (:func:`load_scenario`, :func:`with_values`);
- :mod:`.checks` — sizes and placement checked on load;
- :mod:`.templates` — commented templates of your own tunnel (:func:`template`, loaded on first
  use);
- :mod:`.jiang` — the builders of Jiang et al. (2023)'s 2-D scenarios.
"""

from __future__ import annotations

from .._lazy import lazy_exports
from ..schema import ScenarioError
from .checks import MAX_ELEMENTS, MAX_SAMPLES, MAX_TENSOR_BYTES
from .files import (
    ALLOWED_REQUIRES,
    check_all,
    data_dir,
    list_scenarios,
    load_scenario,
    scenario_from_dict,
    scenario_path,
    with_values,
)
from .model import Scenario
from .registry import (
    Trajectory,
    register_arrays,
    register_check,
    register_trajectory,
    register_tunnel,
)

#: loaded on first use (:mod:`tunnelkit._lazy`): a loaded scenario needs no template writer
_EXPORTS = {"template": "templates"}

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
