"""Image-method propagation in the JAVELIN tunnel: LoS plus one specular bounce per surface.

The tunnel of Italiano et al. (2026), section 4.1: straight, semicircular cross-section (100 m long,
10 m wide, 5 m high) built from ``n_facets`` planar facets plus the road, the base station at the
centre 4.8 m high, and four metallic radio-reflective road markings (RRMs): finite plates placed
per scenario. World frame: x along the tunnel, y across, z up, road at ``z = 0``.

For every surface the vehicle (UE) is mirrored into a virtual UE (VUE); the reflected path exists
when the straight line from the array's reference antenna to the VUE crosses the surface *inside
the finite facet* (the specular point) and neither leg is blocked by a box (a truck). Each
:class:`Path` carries the exact length to **every antenna** (a spherical wavefront centred on the
VUE, eq. 2 and 38) and, for comparison, the SR-NF lengths (the wavefront centred on the reflection
point, the model of the paper's reference 13).

    >>> import tunnelkit as tk
    >>> from tunnelkit import propagation
    >>> sc = tk.load_scenario("italiano2026-straight")     # its builders are in this package
    >>> tun, arrs = sc.tunnel(), propagation.scenario_arrays(sc)
    >>> traj = sc.trajectory()
    >>> paths = propagation.trace_paths(tun, arrs[1], traj.position[0], traj.velocity[0], fc=5.9e9)

Sign conventions (pinned by tests): ``range_rate`` is the time derivative of the path length;
``velocity = -range_rate`` (positive when the path shortens, i.e. the vehicle approaches) and
``doppler = fc * velocity / c``, so that eq. 1's time phase ``+2 pi k f_d T0`` and eq. 15's
``v = c f_d / fc`` hold with a physical carrier ``exp(j 2 pi fc (t - d(t)/c))``.

One module per job, re-exported here:

- :mod:`.materials` — concrete's permittivity and the Fresnel coefficients;
- :mod:`.surfaces` — facets, plates, blocking boxes and the tunnels they make;
- :mod:`.paths` — the image-method paths (:func:`trace_paths`);
- :mod:`.scenes` — the scenario builders (plates, the ``semicircular3d`` tunnel, the ``lane3d``
  trajectory, :func:`scenario_arrays`).
"""

from __future__ import annotations

from .materials import MATERIALS, concrete_permittivity, fresnel_te, reflection_coefficient
from .paths import (
    PATH_KINDS,
    SECOND_ORDER,
    Path,
    arrival_angles,
    as_path_list,
    second_order_paths,
    select_array,
    trace_paths,
)
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
    "second_order_paths",
    "select_array",
    "semicircular_tunnel",
    "trace_paths",
    "truck_box",
]
