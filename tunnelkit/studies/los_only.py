"""The line of sight alone on the ray-traced channel: the study's variants around the design's tracker.

The path taken for the line of sight (:func:`tunnelkit.design.los.los_path`: of the arrivals
within 0.3 m of the earliest, the lowest in elevation; the window chosen on seed 0 among 0.3 /
0.6 / 1.0 m; the true line of sight in 87-89 % of the epochs, the earliest alone in 62-64 %) and
the table of its sigmas by elevation live in the core (:mod:`tunnelkit.design.los`). This study
adds what the design does not use: the path dropped where the fit flags it (:func:`flagged_los`)
and JAVELIN told one constant sigma per angle (:func:`los_design`). ``benchmarks/bench_rt_los.py``
runs them beside the traced design and dead reckoning (``docs/results/traced-robust.md``).
"""

from __future__ import annotations

import numpy as np

from .._validate import instance, nonnegative
from ..design.los import LOS_WINDOW_M, angle_sigma, los_path
from ..simulation.prefilter import traced_measurements
from ..tracking.javelin import JavelinDesign
from .traced import traced_design

__all__ = ["flagged_los", "los_design"]


def flagged_los(ep, route, window: float = LOS_WINDOW_M):
    """A drive adapter (:func:`tunnelkit.simulation.simulate_routes`, ``adapters=``): of the
    epoch's ML measurements (every row, as ``"ml-all"``), the path :func:`los_path` takes for the
    line of sight, kept only where the fit does not flag it: ``(None, reason)`` when the fit put
    that path in its threshold region (``PathEstimates.below_threshold``: its SNR below the
    threshold of the method of interval errors, or unresolved from another path, where its
    errors leave the bound). Uses the fit's own verdict, no truth."""

    window = nonnegative("window", window)
    pm, _ = traced_measurements(ep, route, prefilter=False)  # checks ep and route
    if len(pm) == 0:
        return None, "no path"
    m = ep.measurements
    j = los_path(pm.d, pm.psi, window)
    flags = ep.estimates.below_threshold
    if flags is not None and bool(flags[m.source[pm.source[j]]]):
        return None, "the path taken for the line of sight is in the fit's threshold region"
    return pm.subset(np.array([j])), None


def los_design(sigma_angle: float, base=None, sigma_elevation: float | None = None):
    """``base`` (default the traced design, :func:`tunnelkit.studies.traced.traced_design`) told
    ``sigma_angle`` [rad] for the azimuth of the path it is fed and ``sigma_elevation`` [rad]
    (default ``sigma_angle``) for its elevation (the other sigmas unchanged)."""

    sigma_angle = angle_sigma("sigma_angle", sigma_angle)
    el = sigma_angle if sigma_elevation is None else angle_sigma("sigma_elevation", sigma_elevation)

    base = traced_design() if base is None else instance("base", base, JavelinDesign)
    return base.with_(sigma_phi=sigma_angle, sigma_psi=el)
