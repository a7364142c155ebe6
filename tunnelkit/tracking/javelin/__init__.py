"""JAVELIN (Italiano et al. 2026, sections 3.2-3.5): single-base-station tracking of a vehicle and
its virtual UEs, in small roles.

``state`` (eq. 43) · ``measurement`` (eq. 44-52, Algorithm 1 checks) · ``motion`` (eq. 62-63) ·
``gate`` (eq. 56-59) · ``associate`` (Algorithm 2, greedy and global nearest neighbour) ·
``manage`` (Algorithm 3, LoS test eq. 60-61, Doppler test) · ``update`` (eq. 64-68, Joseph form)
· ``tracker`` (Algorithm 4) · ``tenfiloc`` (the snapshot baseline, eq. 69) · ``config``
(section 4.2 parameters) · ``geometric`` (an exact measurement source for unit tests only).
"""

from __future__ import annotations

from ..registry import register
from .associate import global_nearest_neighbour, greedy_nearest_neighbour
from .config import JavelinConfig
from .gate import ChiSquareGate
from .measurement import JavelinWarning, PathMeasurements, measurement_model, track_model
from .state import JavelinState
from .tenfiloc import TeNFiLoc
from .tracker import Javelin, JavelinRun, StepReport, run_javelin

__all__ = [
    "ChiSquareGate",
    "Javelin",
    "JavelinConfig",
    "JavelinRun",
    "JavelinState",
    "JavelinWarning",
    "PathMeasurements",
    "StepReport",
    "TeNFiLoc",
    "global_nearest_neighbour",
    "greedy_nearest_neighbour",
    "measurement_model",
    "run_javelin",
    "track_model",
]

register("italiano2026", "JAVELIN")(Javelin)
register("italiano2026", "TeNFiLoc")(TeNFiLoc)
