"""Drive variants: a preset's straight-lane drive over another length (:func:`drive_variant`),
the route that ``tunnelkit reproduce javelin-table1 --length 120`` drives; built once and kept. The
drive simulator itself is :mod:`tunnelkit.simulation.drives`.
"""

from __future__ import annotations

from .._validate import positive
from ..scenarios import load_scenario, with_values
from ..settling import SETTLE_S, settled
from ..signal_route import SignalRoute

__all__ = ["MAX_DRIVE_LENGTH", "drive_variant"]


#: longest drive of :func:`drive_variant` [m] (the 120 m drive of the stress matrix and some room)
MAX_DRIVE_LENGTH = 200.0
_VARIANTS: dict[tuple, SignalRoute] = {}


def drive_variant(scenario: str, length: float) -> SignalRoute:
    """The image-channel route of preset ``scenario`` (a straight-lane drive, ``trajectory.kind =
    "lane3d"``) driven over ``length`` metres: the trajectory from ``x_end + length`` to the
    preset's ``x_end`` (same lane, speed, epoch period, road markings), the tunnel lengthened to
    at least ``2 (x_start + 25 m)`` (it is centred on the base station) so the drive starts 25 m
    inside it. ``length = 120`` is the 120 m variant of ``tunnelkit reproduce javelin-table1
    --length 120`` (UE ranges up to 125 m, where the images cluster within a few degrees and
    centimetres of the line of sight). Built once per ``(scenario, length)`` and kept."""
    if not isinstance(scenario, str):
        raise TypeError(f"scenario: expected a preset name, got {type(scenario).__name__}")
    length = positive("length", length)
    if length > MAX_DRIVE_LENGTH:
        raise ValueError(f"length: at most {MAX_DRIVE_LENGTH:g} m, got {length:g}")
    key = (scenario, float(length))
    if key not in _VARIANTS:
        sc = load_scenario(scenario)
        traj = sc.raw["trajectory"]
        if traj.get("kind") != "lane3d":
            raise ValueError(
                f"scenario: {scenario!r} does not drive a straight lane (trajectory kind "
                f"{traj.get('kind')!r}); a drive length applies to lane3d trajectories only"
            )
        x_end = float(traj["x_end"])
        x_start = x_end + length
        tunnel = max(float(sc.raw["tunnel"]["length"]), 2.0 * (x_start + 25.0))
        sc = with_values(sc, {"trajectory.x_start": x_start, "tunnel.length": tunnel})
        route = SignalRoute.from_scenario(sc)
        if not settled(route.trajectory.t).size:  # nothing to score, never an RMSE of 0
            raise ValueError(
                f"length: a {length:g} m drive ends within the tracker's {SETTLE_S:g} s start-up "
                "(settling.SETTLE_S): nothing settled to score; give a longer drive"
            )
        _VARIANTS[key] = route
    return _VARIANTS[key]
