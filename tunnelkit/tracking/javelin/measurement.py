"""JAVELIN's measurement model of eq. 44-52 (the path parameters of one epoch it reads are
:class:`tunnelkit.tracking.measurements.PathMeasurements`, re-exported here and by the package).

Per path ``l`` the extraction (Algorithm 1) gives azimuth ``phi``, elevation ``psi``, curvature
``kappa`` (near field only), delay distance ``d`` (with the clock bias) and radial speed ``v``.
The model maps a track position to them (base station ``b`` at the reference antenna):

- UE (eq. 46-48): ``phi_0 = atan2(y_u, x_u)``, ``psi_0 = atan2(z_u, sqrt(x_u^2 + y_u^2))``,
  ``kappa_0 = ||p_u||``;
- VUE ``p_v = [x_u, y_v, z_v]`` (eq. 49-52): the same angles of ``p_v``, ``kappa_l = ||p_r||``
  with the reflector ``p_r`` of eq. 45, and ``Delta d_l = ||p_v|| - ||p_u||``,

all coordinates relative to ``b``. We write eq. 45 as ``kappa = ||p_v|| A / B`` with
``w = p_v - p_u``, ``A = w . ((p_u + p_v)/2)`` and ``B = w . p_v``, which gives the closed-form
Jacobian of :func:`track_model` (tested against finite differences). ``atan2`` replaces the
paper's ``tan^-1(y/x)`` so a UE behind the array (``x < 0``) keeps its true bearing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._validate import finite_array, nonnegative, real, vector
from ...geometry import spherical_jacobian
from ..measurements import JavelinWarning, PathMeasurements
from .state import vue_positions

__all__ = [
    "DelayCheck",
    "DopplerClutter",
    "JavelinWarning",
    "PathMeasurements",
    "ReflectorCurvature",
    "VueCurvature",
    "measurement_model",
    "track_model",
]

PHI, PSI, KAPPA, RANGE = 0, 1, 2, 3


def track_model(
    x, bs=(0.0, 0.0, 0.0), kappa_model: str = "reflector"
) -> tuple[np.ndarray, np.ndarray]:
    """Per-track predictions ``[phi, psi, kappa, range]`` (L_hat, 4) and Jacobians (L_hat, 4, D).

    Eq. 46-51 plus the range ``||p - b||`` from which the TDoA of eq. 52 is differenced.
    ``kappa_model="vue"`` sets the VUE curvature to its range (wavefront centred on the VUE)
    instead of eq. 51's reflector distance.
    """
    x = finite_array("x", x, ndim=1)
    if x.size < 3 or (x.size - 3) % 2:
        raise ValueError(f"x: expected 3 + 2 n entries (eq. 43), got {x.size}")
    b = vector("bs", bs, 3)
    if kappa_model not in ("reflector", "vue"):
        raise ValueError(f"kappa_model: expected 'reflector' or 'vue', got {kappa_model!r}")
    D = x.size
    n_v = (D - 3) // 2
    pos = np.vstack([x[:3], vue_positions(x)])
    q = pos - b
    rho2 = q[:, 0] ** 2 + q[:, 1] ** 2
    rho = np.sqrt(rho2)
    r2 = rho2 + q[:, 2] ** 2
    r = np.sqrt(r2)
    if np.any(rho < 1e-9):
        raise ValueError("x: a track lies on the base station's vertical axis, azimuth undefined")
    pred = np.empty((n_v + 1, 4))
    pred[:, PHI] = np.arctan2(q[:, 1], q[:, 0])
    pred[:, PSI] = np.arctan2(q[:, 2], rho)
    pred[:, RANGE] = r
    pred[:, KAPPA] = r
    # derivatives w.r.t. the track point q (L, 4, 3)
    dq = np.zeros((n_v + 1, 4, 3))
    sph = spherical_jacobian(q)
    dq[:, PHI], dq[:, PSI], dq[:, RANGE] = sph[:, 0], sph[:, 1], sph[:, 2]
    dq[:, KAPPA] = dq[:, RANGE]
    J = np.zeros((n_v + 1, 4, D))
    J[0, :, 0:3] = dq[0]
    if n_v:
        J[1:, :, 0] = dq[1:, :, 0]
        cols = 3 + 2 * np.arange(n_v)
        rows = np.arange(1, n_v + 1)
        J[rows, :, cols] = dq[1:, :, 1]
        J[rows, :, cols + 1] = dq[1:, :, 2]
        if kappa_model == "reflector":
            from .reflector import reflector_kappa  # eq. 51's curvature (the paper's model)

            kap, dk_u, dk_v = reflector_kappa(q[0], q[1:])
            pred[1:, KAPPA] = kap
            J[1:, KAPPA, :] = 0.0
            J[1:, KAPPA, 0] = dk_v[:, 0]  # x of the VUE is x_u
            J[1:, KAPPA, 1] = dk_u[:, 1]
            J[1:, KAPPA, 2] = dk_u[:, 2]
            J[rows, KAPPA, cols] = dk_v[:, 1]
            J[rows, KAPPA, cols + 1] = dk_v[:, 2]
    return pred, J


def check_track_model(pred, J) -> tuple[np.ndarray, np.ndarray]:
    """``pred`` (L, 4) and ``J`` (L, 4, D) as :func:`track_model` returns them: numeric arrays of
    matching shapes (the boundary check of every stage that takes them; NaN allowed, a far
    track's curvature can be undefined). Errors name ``pred`` or ``J``."""
    out = []
    for name, a, nd in (("pred", pred, 2), ("J", J, 3)):
        if isinstance(a, str | bytes) or a is None:
            raise TypeError(f"{name}: expected a numeric array from track_model, got {a!r:.40}")
        arr = np.asarray(a)
        if arr.dtype.kind not in "iuf":
            raise TypeError(f"{name}: expected real numbers, got dtype {arr.dtype}")
        if arr.ndim != nd or arr.shape[1:2] != (4,):
            want = "(L, 4)" if nd == 2 else "(L, 4, D)"
            raise ValueError(f"{name}: expected shape {want} (track_model), got {arr.shape}")
        if not np.isfinite(arr[:, [PHI, PSI, RANGE]]).all():  # only a curvature may be undefined
            raise ValueError(f"{name}: the angle and delay rows must be finite")
        out.append(arr)
    if out[0].shape[0] != out[1].shape[0]:
        raise ValueError(f"J: {out[1].shape[0]} tracks, pred has {out[0].shape[0]}")
    return out[0], out[1]


def measurement_model(
    x, bs=(0.0, 0.0, 0.0), kappa_model: str = "reflector"
) -> tuple[np.ndarray, np.ndarray]:
    """The stacked model ``h(s)`` of eq. 44 and its Jacobian ``H`` (eq. 55), shape (K,), (K, D).

    ``h = [phi_0..phi_{L-1}, psi_0.., kappa_0.., Delta d_1..Delta d_{L-1}]`` with
    ``K = 4 L_hat - 1``; the TDoA is relative to the UE (LoS) path as in eq. 52.
    """
    pred, J = track_model(x, bs, kappa_model)
    h = np.concatenate(
        [pred[:, PHI], pred[:, PSI], pred[:, KAPPA], pred[1:, RANGE] - pred[0, RANGE]]
    )
    H = np.concatenate([J[:, PHI], J[:, PSI], J[:, KAPPA], J[1:, RANGE] - J[0, RANGE]])
    return h, H


@dataclass(frozen=True)
class ReflectorCurvature:
    """The curvature of a reflected path is the distance to the reflection point (eq. 51, the
    SR-NF model)."""

    name = "reflector"

    def predict(self, x, bs):
        """Predicted ``(phi, psi, kappa, range)`` per track (L, 4) and the Jacobian (L, 4, D)."""
        return track_model(x, bs, self.name)


@dataclass(frozen=True)
class VueCurvature(ReflectorCurvature):
    """The curvature of a reflected path is the distance to its VUE (the radius of the exact
    wavefront, what the maximum-likelihood route measures; ours)."""

    name = "vue"


@dataclass(frozen=True)
class DelayCheck:
    """Algorithm 1's checks: a path with a NaN angle or ``d < min_d`` is dropped; ``min_d = 0``
    as printed, ``-c b_max`` keeps the paths a negative clock bias pushed below zero (ours)."""

    min_d: float = 0.0

    def __post_init__(self) -> None:
        v = real("min_d", self.min_d)
        if not (np.isfinite(v) and v <= 0):
            raise ValueError(f"min_d: expected a finite value <= 0, got {self.min_d!r}")

    def __call__(self, meas: PathMeasurements, speed: float | None) -> tuple[PathMeasurements, int]:
        """The kept paths and how many were dropped (``speed`` unused)."""
        return meas.sanitised(self.min_d)


@dataclass(frozen=True)
class DopplerClutter:
    """A path whose radial speed exceeds the vehicle speed by more than ``margin`` [m/s] cannot
    come from a static reflector (``|v| <= ||v_u||`` for any mirror image) and is dropped before
    association (ours). Applies only while the speed message is present (``speed`` not None)."""

    margin: float = 1.0

    def __post_init__(self) -> None:
        nonnegative("margin", self.margin)

    def __call__(self, meas: PathMeasurements, speed: float | None) -> tuple[PathMeasurements, int]:
        if speed is None or not len(meas):
            return meas, 0
        fast = np.abs(meas.v) > abs(speed) + self.margin  # NaN v: kept
        n = int(fast.sum())
        return (meas.subset(np.flatnonzero(~fast)), n) if n else (meas, 0)
