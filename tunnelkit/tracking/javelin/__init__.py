"""JAVELIN (Italiano et al. 2026, sections 3.2-3.5): single-base-station tracking of a vehicle and
its virtual UEs, in small roles.

``state`` (eq. 43) · ``measurement`` (eq. 44-52, Algorithm 1 checks, curvature models,
pre-filters) · ``noise`` (fixed or reported measurement noise) · ``motion`` (eq. 62-63, VUE
motion) · ``associate`` (eq. 56-59 gated costs, Algorithm 2, global nearest neighbour) ·
``manage`` (Algorithm 3, LoS test eq. 60-61, Doppler test, initiators) · ``update`` (eq. 64-68,
Joseph form, joint innovation test) · ``roles`` (:class:`JavelinDesign`: numbers + one object
per role) · ``designs`` (the named designs as factories) · ``tracker`` (Algorithm 4) ·
``tenfiloc`` (the snapshot baseline, eq. 69) · ``config`` (section 4.2 numbers). The
chi-square gate is :class:`tunnelkit.tracking.gating.ChiSquareGate`.
"""

from __future__ import annotations

from ..gating import ChiSquareGate
from ..registry import register
from . import designs
from .associate import global_nearest_neighbour, greedy_nearest_neighbour
from .config import JavelinConfig
from .measurement import JavelinWarning, PathMeasurements, measurement_model, track_model
from .roles import (
    Associator,
    ConsiderNoise,
    DelayCheck,
    DopplerClutter,
    FixedBirth,
    FixedNoise,
    JavelinDesign,
    JointTestUpdater,
    JosephUpdater,
    MeasuredBirth,
    MirrorMotion,
    RandomWalk,
    ReflectorCurvature,
    ReportedNoise,
    VueCurvature,
)
from .state import JavelinState
from .tenfiloc import TeNFiLoc
from .tracker import Javelin, JavelinRun, StepReport, draw_start, run_javelin

__all__ = [
    "Associator",
    "ChiSquareGate",
    "ConsiderNoise",
    "DelayCheck",
    "DopplerClutter",
    "FixedBirth",
    "FixedNoise",
    "Javelin",
    "JavelinConfig",
    "JavelinDesign",
    "JavelinRun",
    "JavelinState",
    "JavelinWarning",
    "JointTestUpdater",
    "JosephUpdater",
    "MeasuredBirth",
    "MirrorMotion",
    "PathMeasurements",
    "RandomWalk",
    "ReflectorCurvature",
    "ReportedNoise",
    "StepReport",
    "TeNFiLoc",
    "VueCurvature",
    "designs",
    "draw_start",
    "global_nearest_neighbour",
    "greedy_nearest_neighbour",
    "measurement_model",
    "run_javelin",
    "track_model",
]

register("italiano2026", "JAVELIN")(Javelin)
register("italiano2026", "TeNFiLoc")(TeNFiLoc)
