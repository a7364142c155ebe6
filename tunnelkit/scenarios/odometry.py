"""A scenario's ``[odometry]`` section read into the model of its V2X messages
(:class:`tunnelkit.odometry.Odometry`): a named model with the terms the file gives replaced, in
the units automotive data sheets use (:func:`odometry_from_scenario`, behind
:meth:`tunnelkit.scenarios.Scenario.odometry`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..odometry import MODELS, WHITE, Odometry

__all__ = ["odometry_from_scenario"]

#: a scenario file's ``[odometry]`` keys: the :class:`~tunnelkit.odometry.Odometry` field each
#: sets, and its unit
_FILE_KEYS = {
    "speed_scale": ("speed_scale", 1.0),
    "speed_noise": ("speed_noise", 1.0),
    "heading_bias_deg": ("heading_bias", float(np.radians(1.0))),
    "heading_drift_deg_per_sqrt_h": ("heading_drift", float(np.radians(1.0) / 60.0)),
    "yaw_rate_bias_deg_per_h": ("yaw_rate_bias", float(np.radians(1.0) / 3600.0)),
    "heading_noise_deg": ("heading_noise", float(np.radians(1.0))),
    "rate_hz": ("rate", 1.0),
    "dropout": ("dropout", 1.0),
}


def odometry_from_scenario(scenario) -> Odometry:
    """The scenario's ``[odometry]`` section: its ``model`` (a name of
    :data:`tunnelkit.odometry.MODELS`) with the terms it gives replaced (angles in degrees, the
    drift in deg/sqrt(h), the yaw-rate bias in deg/h, ``rate_hz = 0`` a message per epoch); a
    scenario without the section drives on the paper's white model
    (:data:`tunnelkit.odometry.WHITE`)."""
    sections = getattr(scenario, "sections", None)
    if not isinstance(sections, dict):
        raise TypeError(
            f"scenario: expected a loaded scenarios.Scenario, got {type(scenario).__name__}"
        )
    sec = sections.get("odometry")
    if sec is None:
        return WHITE
    kw = {}
    for key, (name, scale) in _FILE_KEYS.items():
        if key in sec:
            kw[name] = float(sec[key]) * scale
    if "rate" in kw and kw["rate"] == 0.0:
        kw["rate"] = None
    return replace(MODELS[sec["model"]], **kw)
