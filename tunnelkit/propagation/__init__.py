"""Image-method propagation in the JAVELIN tunnel: LoS plus one specular bounce per surface.

The tunnel of Italiano et al. (2026), section 4.1 (:class:`Tunnel3D`, :func:`semicircular_tunnel`,
:func:`road_marking`); :func:`trace_paths` gives each :class:`Path` with its exact length to
every antenna (eq. 2 and 38) and the SR-NF lengths. World frame: x along the tunnel, y across,
z up, road at ``z = 0``; ``velocity = -range_rate``, ``doppler = fc * velocity / c`` (pinned by
tests). How it works (the "package docstring" the modules cite):
docs/internals/channel-and-propagation.md.

    >>> import tunnelkit as tk
    >>> from tunnelkit import propagation
    >>> sc = tk.load_scenario("italiano2026-straight")     # its builders are in this package
    >>> tun, arrs = sc.tunnel(), propagation.scenario_arrays(sc)
    >>> traj = sc.trajectory()
    >>> paths = propagation.trace_paths(tun, arrs[1], traj.position[0], traj.velocity[0], fc=5.9e9)
"""

from __future__ import annotations

from .materials import MATERIALS, concrete_permittivity, fresnel_te, reflection_coefficient
from .path import PATH_KINDS, SECOND_ORDER, Path, arrival_angles, as_path_list
from .paths import select_array, trace_paths
from .scenes import lane_trajectory, plate_from_table, scenario_arrays
from .surfaces import (
    FACET_BYTES,
    Box,
    Facet,
    Tunnel3D,
    close_tunnel,
    road_marking,
    semicircular_tunnel,
    truck_box,
)

__all__ = [
    "FACET_BYTES",
    "MATERIALS",
    "PATH_KINDS",
    "SECOND_ORDER",
    "Box",
    "Facet",
    "Path",
    "Tunnel3D",
    "arrival_angles",
    "as_path_list",
    "close_tunnel",
    "concrete_permittivity",
    "fresnel_te",
    "lane_trajectory",
    "plate_from_table",
    "reflection_coefficient",
    "road_marking",
    "scenario_arrays",
    "select_array",
    "semicircular_tunnel",
    "trace_paths",
    "truck_box",
]
