"""JAVELIN for an array-design sweep at any carrier and array size: :func:`array_design`, told
the covariances the extraction reports (so no 5.9 GHz constant enters), with its gate, VUE walks
and update iterations (``ARRAY_DESIGN_*``), and births at the UE's mirror image in the tunnel's
known planes when it is given them (:class:`~.surfaces.GeometricBirth`).
"""

from __future__ import annotations

import numpy as np

from .associate import Associator
from .consider import ConsiderNoise
from .designs import ours
from .measuredbirth import MeasuredBirth
from .measurement import DelayCheck, VueCurvature
from .roles import JavelinDesign
from .surfaces import GeometricBirth
from .update import JointTestUpdater

__all__ = [
    "ARRAY_DESIGN_GATE",
    "ARRAY_DESIGN_KNOWN_VUE_WALK",
    "ARRAY_DESIGN_UPDATE_ITERATIONS",
    "ARRAY_DESIGN_VUE_WALK",
    "array_design",
]


#: the array design's association gate: with reported covariances of micrometres to millimetres,
#: the paper's p = 0.99 gates out a true path in 1 % of track-epochs (a 3-sigma V2X heading error
#: moves the LoS prediction by centimetres), and a LoS track that misses its path loses the UE
#: (seed 0, italiano2026-straight 16 x 16: 5.7 cm worst run against a 0.04 mm bound). The
#: candidates a wider gate lets in are ranked by the likelihood cost, so the gate only has to
#: keep out what is physically impossible.
ARRAY_DESIGN_GATE = 1.0 - 1e-6

#: the array design's VUE random walk [m/sqrt(s)]: a design's surfaces are planes (walls, road,
#: the facets of a curved roof), on which a VUE moves exactly by the mirrored UE displacement
#: (``MirrorMotion``); the paper's 0.3 m/sqrt(s) discards at every epoch what the VUE tracks
#: learnt about the surfaces, and with it most of what the reflections say about the UE.
ARRAY_DESIGN_VUE_WALK = 1e-3

#: the VUE random walk [m/sqrt(s)] of the array design when its VUEs come from the tunnel's known
#: planes (:class:`~.surfaces.GeometricBirth`): such a VUE is the UE's mirror image, so the walk
#: only keeps its covariance regular. At :data:`ARRAY_DESIGN_VUE_WALK` every VUE drifts by about
#: a millimetre per second independently of the UE, as much as a 32 x 32 array's whole error at
#: 28 GHz: each VUE's state then takes up part of its path's repeating calibration bias and hands
#: it to the UE over the following epochs (28 GHz example, 32 x 32, 0.5 deg phase error, 20 runs,
#: seed 0: settled RMSE 1.89 mm at 1e-3 against 0.89 mm here, the bound over the drive 0.86 mm;
#: 4 x 4 and 8 x 8 unchanged within 3 %).
ARRAY_DESIGN_KNOWN_VUE_WALK = 1e-6

#: the array design's relinearisations of each epoch's update at most (an iterated EKF,
#: ``JavelinConfig.update_iterations``): the first epoch after the angle-only fix corrects the UE
#: by up to a metre along its ray, beyond the range where the curvature and delay rows are
#: linear at a large array's precision (italiano2026-straight, 16 x 16, ideal channel, 20 runs,
#: seed 0: first epoch 3.4 mm RMS against a 0.35 mm bound with one step, 0.52 mm iterated; the
#: settled RMSE over the bound over the drive 22.3 -> 1.24); later epochs settle in one extra
#: step
ARRAY_DESIGN_UPDATE_ITERATIONS = 10


def array_design(crlb: dict, min_d: float = 0.0, planes=None, **overrides) -> JavelinDesign:
    """JAVELIN for an array-design sweep at any carrier and array size (our design, curvature
    centred on the VUE): every path's measurement covariance is the one the extraction reports
    (the CRLB at its estimate, which the ML route attains), so no 5.9 GHz constant enters, and
    the share of it that repeats every epoch (a calibration error, a model bias:
    ``PathMeasurements.bias_cov``) is carried as a consider parameter of the path's track, not
    averaged down (:class:`ConsiderNoise`, a Schmidt-Kalman update:
    :func:`~.consider.consider_update`); pairs are ranked by ``eta^2 + ln det S`` (``Associator(cost="likelihood")``),
    so a new, wide track cannot take a path an established track predicts to a millimetre; a VUE
    is born with the covariance of the angles that placed it (:class:`MeasuredBirth`), so two new
    tracks a few degrees apart cannot swap their paths in the next epoch; and pairs whose stacked
    innovation is inconsistent are left out of the update (``JointTestUpdater(0.999)``), which
    catches a wrong LoS taken by eq. 61 after the per-pair gate missed the true one; the gate is
    wide (:data:`ARRAY_DESIGN_GATE`), each epoch's update is iterated
    (:data:`ARRAY_DESIGN_UPDATE_ITERATIONS`), and the VUEs move with the mirrored UE displacement with a
    small random walk on top (:data:`ARRAY_DESIGN_VUE_WALK`; :data:`ARRAY_DESIGN_KNOWN_VUE_WALK`
    for VUEs from known planes). ``min_d``:
    Algorithm 1's delay check (``-c b_max`` keeps the paths a negative clock bias pushed below
    zero). The fixed sigmas, used only in an epoch whose Fisher information is singular at the
    estimate, are ``crlb`` (``d`` [m], ``direction`` [rad], ``kappa`` [m]; e.g. an upper percentile
    of the route's per-path bounds); ``sigma_delta_d`` is ``sqrt(2)`` times the delay-distance
    sigma (a difference of two delays). ``planes`` (the tunnel's known surfaces,
    :class:`tunnelkit.geometry.Plane` or anything with ``normal`` and ``offset``; default none):
    VUEs are born at the UE's mirror image in the plane that explains their path
    (:class:`~.surfaces.GeometricBirth`) instead of learnt from their angles. It steps on eq. 62's
    held message, not our designs' midpoint: the design's bounds over a drive
    (:mod:`tunnelkit.design.drivebound`) model that step, and the tracker they are set beside
    must run the model they bound.
    """
    if not isinstance(crlb, dict):
        raise TypeError(f"crlb: expected a dict of per-path bounds, got {type(crlb).__name__}")

    def pick(k):
        v = crlb.get(k)
        if v is None or not np.isfinite(v) or v <= 0:
            raise ValueError(f"crlb: {k!r} must be finite and > 0, got {v!r}")
        return float(v)

    ang, kap, d = pick("direction"), pick("kappa"), pick("d")
    base = ours()
    if planes is None:
        birth = MeasuredBirth(update_at_birth=base.initiator.update_at_birth)
    else:
        if isinstance(planes, str | bytes) or not hasattr(planes, "__iter__"):
            raise TypeError(f"planes: expected a list of planes, got {type(planes).__name__}")
        planes = list(planes)
        if not all(hasattr(p, "normal") and hasattr(p, "offset") for p in planes):
            raise TypeError("planes: expected planes with a normal and an offset")
        birth = GeometricBirth.from_planes(planes)
    return (
        base.with_(
            curvature=VueCurvature(),
            noise=ConsiderNoise(fallback=base.noise),
            associator=Associator(cost="likelihood", solver=base.associator.solver),
            initiator=birth,
            updater=JointTestUpdater(0.999),
            gate_probability=ARRAY_DESIGN_GATE,
            sigma_vue_walk=ARRAY_DESIGN_VUE_WALK if planes is None else ARRAY_DESIGN_KNOWN_VUE_WALK,
            sigma_phi=ang,
            sigma_psi=ang,
            sigma_kappa=kap,
            sigma_delta_d=float(np.sqrt(2.0) * d),
            update_iterations=ARRAY_DESIGN_UPDATE_ITERATIONS,
            motion_step="held",
        )
        .with_prefilter(DelayCheck(float(min_d)))
        .with_(**overrides)
    )
