"""JAVELIN (Italiano et al. 2026, sections 3.2-3.5): single-base-station tracking of a vehicle and
its virtual UEs, in small roles.

``state`` (eq. 43) · ``measurement`` (eq. 44-52, Algorithm 1 checks, curvature models, pre-filters)
· ``noise`` (fixed or reported measurement noise) · ``consider`` (the bias-aware tracker's noise
and update) · ``motion`` (eq. 62-63, VUE motion) · ``associate`` (eq. 56-59 gated costs, Algorithm
2, global nearest neighbour) · ``manage`` (Algorithm 3, LoS test eq. 60-61, Doppler test,
initiators) · ``measuredbirth`` (VUEs born with the covariance of their angles) · ``linearbirth``
(the birth's intersection linearised, a born VUE's cross-covariance with the biases) · ``reflector``
(eq. 51's reflector curvature) · ``update`` (eq. 64-68, Joseph form, joint innovation test) ·
``roles`` (:class:`JavelinDesign`: numbers + one object per role) · ``designs`` (the named
designs as factories) · ``arraydesign`` (the array design's tracker) · ``surfaces`` (VUEs born
from known planes) · ``tracker`` (Algorithm 4) · ``iterated`` (the first fix and the iterated
update) · ``runs`` (a start drawn, a stream run in one call) · ``tenfiloc`` (the snapshot
baseline, eq. 69) · ``config`` (section 4.2 numbers). The chi-square gate is
:class:`tunnelkit.tracking.gating.ChiSquareGate`.
"""

from __future__ import annotations

from ..._lazy import lazy_exports
from ..gating import ChiSquareGate as ChiSquareGate

# name -> defining submodule, loaded on first use: running JAVELIN loads neither the TeNFiLoc
# baseline, the designs' geometric initiator nor the bias-aware noise unless a caller asks for them. The trackers
# register themselves (``tracker``: JAVELIN, ``tenfiloc``: TeNFiLoc) in the "italiano2026" family.
_EXPORTS: dict[str, str] = {
    "global_nearest_neighbour": "associate",
    "greedy_nearest_neighbour": "associate",
    "JavelinConfig": "config",
    "JavelinWarning": "measurement",
    "PathMeasurements": "measurement",
    "measurement_model": "measurement",
    "track_model": "measurement",
    "ConsiderNoise": "consider",
    "Associator": "roles",
    "DelayCheck": "roles",
    "DopplerClutter": "roles",
    "FixedBirth": "roles",
    "FixedNoise": "roles",
    "JavelinDesign": "roles",
    "JointTestUpdater": "roles",
    "JosephUpdater": "roles",
    "MeasuredBirth": "measuredbirth",
    "MirrorMotion": "roles",
    "RandomWalk": "roles",
    "ReflectorCurvature": "roles",
    "ReportedNoise": "roles",
    "VueCurvature": "roles",
    "JavelinState": "state",
    "TeNFiLoc": "tenfiloc",
    "Javelin": "tracker",
    "JavelinRun": "tracker",
    "StepReport": "tracker",
    "draw_start": "runs",
    "run_javelin": "runs",
}
__all__ = sorted([*_EXPORTS, "ChiSquareGate", "designs"])
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
