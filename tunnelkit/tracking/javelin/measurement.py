"""JAVELIN measurements: the path parameters of one epoch and the model of eq. 44-52.

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

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..._checks import series, unchecked
from ..._validate import boolean, finite_array, nonnegative, real, vector
from ...constants import C
from ...geometry import spherical_jacobian
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


class JavelinWarning(UserWarning):
    """A fault in the measurement stream the tracker works around (dropped path, missing message)."""


def _opt(name: str, value, n: int) -> np.ndarray:
    if value is None:
        return np.full(n, np.nan)
    arr = np.asarray(value, dtype=float).reshape(-1)
    if arr.size != n:
        raise ValueError(f"{name}: expected {n} values (one per path), got {arr.size}")
    return arr.copy()


def _reported(cov, sigma_d, n: int):
    """Checked ``cov`` (n, 3, 3) and ``sigma_d`` (n,): both given or both ``None``."""
    if cov is None and sigma_d is None:
        return None, None
    if cov is None or sigma_d is None:
        raise ValueError("cov, sigma_d: give both (the reported uncertainty) or neither")
    cov = np.array(cov, dtype=float)
    if cov.shape != (n, 3, 3):
        raise ValueError(f"cov: expected shape ({n}, 3, 3), got {cov.shape}")
    sd = np.array(sigma_d, dtype=float).reshape(-1)
    if sd.size != n:
        raise ValueError(f"sigma_d: expected {n} values (one per path), got {sd.size}")
    if not (np.all(np.isfinite(sd)) and np.all(sd > 0)):
        raise ValueError("sigma_d: every value must be finite and > 0")
    if not np.all(np.isfinite(cov)):
        raise ValueError("cov: every entry must be finite")
    cov = 0.5 * (cov + np.swapaxes(cov, 1, 2))
    # the curvature block may be absent (far field): only the angular block must be positive
    if n and not np.all(np.linalg.eigvalsh(cov[:, :2, :2]) > 0):
        raise ValueError("cov: the (phi, psi) block of every path must be positive definite")
    return cov, sd


def _bias(bias_cov, cov, sigma_d, n: int):
    """Checked ``bias_cov`` (n, 4, 4): symmetric, positive semi-definite, and no larger than the
    reported covariance it is a share of (``cov`` / ``sigma_d``) in any direction."""
    if bias_cov is None:
        return None
    if cov is None:
        raise ValueError("bias_cov: needs the reported covariance (cov, sigma_d) it is a share of")
    b = np.array(bias_cov, dtype=float)
    if b.shape != (n, 4, 4):
        raise ValueError(f"bias_cov: expected shape ({n}, 4, 4), got {b.shape}")
    if not np.all(np.isfinite(b)):
        raise ValueError("bias_cov: every entry must be finite")
    b = 0.5 * (b + np.swapaxes(b, 1, 2))
    total = np.zeros((n, 4, 4))
    total[:, :3, :3] = cov
    total[:, 3, 3] = sigma_d**2
    total[:, :3, 3] = total[:, 3, :3] = b[:, :3, 3]  # the d cross terms are not reported
    scale = np.sqrt(np.clip(np.diagonal(total, axis1=1, axis2=2), 1e-300, None))
    tol = 1e-9
    for name, m in (("bias_cov", b), ("cov - bias_cov", total - b)):
        if n and np.min(np.linalg.eigvalsh(m / scale[:, :, None] / scale[:, None, :])) < -tol:
            raise ValueError(f"bias_cov: {name} must be positive semi-definite for every path")
    return b


@dataclass
class PathMeasurements:
    """Sanitised path parameters of one epoch (Algorithm 1, lines 4-12): what the signal route
    gives (:func:`tunnelkit.signal_route.measurements_from_estimates`) and the trackers take.

    Arrays have one entry per kept path: ``phi``/``psi`` azimuth and elevation (eq. 46-47),
    ``kappa`` the curvature radius (NaN where only the far-field estimate is valid), ``d`` the
    delay distance with the clock bias and ``v`` the radial speed (NaN where unknown). ``source``
    keeps each kept path's row in the input (the raw
    :class:`tunnelkit.extraction.PathEstimates` on the signal route, the arrays given to
    :meth:`from_arrays`). ``origin`` (3,): the world position the angles are seen from (the
    array's reference antenna on the signal route; ``None`` when the caller did not say). The
    route sorts the paths by ``d`` (path 0 the earliest arrival); ``delta_d``, ``z`` (eq. 52,
    54), ``near_field``, ``direction`` and ``wave_origins`` are derived from the fields.

    Optionally the extraction reports its own uncertainty per path (ours, not in the paper):
    ``cov`` (n, 3, 3) the covariance of ``(phi, psi, kappa)`` [rad^2, rad m, m^2] and ``sigma_d``
    (n,) [m] the standard deviation of ``d``, e.g. the CRLB at the estimate of an efficient
    estimator (:func:`tunnelkit.extraction.estimate_crlb`). Both or neither; a tracker with
    ``measurement_noise="reported"`` uses them instead of its fixed sigmas. ``bias_cov``
    (n, 4, 4), with a reported covariance only: the share of it over ``(phi, psi, kappa, d)``
    that repeats from one epoch to the next (a calibration error drawn once per array, a bias of
    the estimator's model, :func:`~tunnelkit.signal_route.judging.apply_budget`), which a
    bias-aware tracker (:class:`~.noise.ConsiderNoise`) keeps apart from the white share
    ``cov - bias_cov``.

    The one container of kept paths from the extraction to the trackers. Not it: the raw
    extraction output (:class:`tunnelkit.extraction.PathEstimates`: every path found, in the
    array's frame, before Algorithm 1), one simulated epoch's record around it
    (:class:`tunnelkit.signal_route.Epoch`: truth, tensor, estimates and these measurements), a
    whole drive (:class:`tunnelkit.simulation.DriveData`: one per epoch, with the truth and the
    V2X messages), the rows one update stacks (:class:`~.update.StackedMeasurement`, eq. 54 of
    the associated paths) and Halili's per-epoch Doppler and delay series
    (:class:`tunnelkit.doppler_drive.DopplerToaMeasurements`).
    """

    phi: np.ndarray
    psi: np.ndarray
    kappa: np.ndarray
    d: np.ndarray
    v: np.ndarray
    source: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    cov: np.ndarray | None = None
    sigma_d: np.ndarray | None = None
    bias_cov: np.ndarray | None = None
    origin: np.ndarray | None = None

    def __post_init__(self) -> None:
        # built directly (not through from_arrays): 1-D float arrays of one length, and a
        # default ``source`` so that ``subset`` works (NaN angles: the tracker sanitises them)
        for name in ("phi", "psi", "kappa", "d", "v", "source"):
            series(name, getattr(self, name), finite=name == "source")
        for name in ("phi", "psi", "kappa", "d", "v"):
            setattr(self, name, np.asarray(getattr(self, name), dtype=float).reshape(-1))
        # a measured radial speed may be an extraction's outlier (the tracker gates it), never
        # faster than light
        fast = np.abs(self.v[np.isfinite(self.v)])
        if fast.size and fast.max() >= C:
            raise ValueError(
                f"v: a measured radial speed of {fast.max():.4g} m/s, faster than light"
            )
        n = self.phi.size
        for name in ("psi", "kappa", "d", "v"):
            if getattr(self, name).size != n:
                raise ValueError(
                    f"{name}: expected {n} values (one per path), got {getattr(self, name).size}"
                )
        src = np.asarray(self.source, dtype=int).reshape(-1)
        if src.size == 0 and n:
            src = np.arange(n)
        if src.size != n:
            raise ValueError(f"source: expected {n} values (one per path), got {src.size}")
        self.source = src
        self.cov, self.sigma_d = _reported(self.cov, self.sigma_d, n)
        self.bias_cov = _bias(self.bias_cov, self.cov, self.sigma_d, n)
        if self.origin is not None:
            self.origin = vector("origin", self.origin, 3)

    @property
    def reported(self) -> bool:
        """Whether the extraction reported a covariance for every path."""
        return self.cov is not None

    @property
    def near_field(self) -> np.ndarray:
        """Whether each path carries a curvature (a near-field estimate, ``kappa`` not NaN)."""
        return np.isfinite(self.kappa)

    @property
    def delta_d(self) -> np.ndarray:
        """``d - d[0]``: the delay differences to the first path (eq. 52, ``delta_d[0] = 0``)."""
        return self.d - self.d[0] if self.d.size else self.d.copy()

    @property
    def z(self) -> np.ndarray:
        """Eq. 54 stacked vector ``[phi; psi; kappa; delta_d[1:]]`` (kappa NaN for far-field)."""
        return np.concatenate([self.phi, self.psi, self.kappa, self.delta_d[1:]])

    @property
    def direction(self) -> np.ndarray:
        """Unit arrival directions from ``phi``/``psi`` (elevation), shape (n, 3)."""
        c = np.cos(self.psi)
        return np.column_stack([c * np.cos(self.phi), c * np.sin(self.phi), np.sin(self.psi)])

    @property
    def wave_origins(self) -> np.ndarray:
        """``origin + kappa * direction`` (n, 3), NaN rows for far-field paths (Fig. 5); needs
        ``origin``."""
        if self.origin is None:
            raise ValueError("origin: not given, so the wave origins have no position")
        return self.origin + self.kappa[:, None] * self.direction

    def sanitised(self, min_d: float = 0.0) -> tuple[PathMeasurements, int]:
        """These paths through the checks of Algorithm 1 (idempotent), and how many were dropped.

        ``source`` keeps pointing into the original input."""
        real("min_d", min_d)
        # this record's fields were checked when it was built: Algorithm 1's tests alone (what
        # from_arrays does after its checks), the kept paths a record built unchecked (the
        # tracker sanitises every epoch's paths)
        keep = np.isfinite(self.phi) & np.isfinite(self.psi) & ~(self.d < min_d)
        idx = np.flatnonzero(keep)
        kappa = np.where(np.isfinite(self.kappa) & (self.kappa > 0), self.kappa, np.nan)
        d = np.where(np.isfinite(self.d), self.d, np.nan)
        v = np.where(np.isfinite(self.v), self.v, np.nan)
        sub = [None if a is None else a[idx] for a in (self.cov, self.sigma_d, self.bias_cov)]
        clean = unchecked(
            PathMeasurements, self.phi[idx], self.psi[idx], kappa[idx], d[idx], v[idx],
            self.source[idx], *sub, self.origin,
        )  # fmt: skip
        return clean, len(self) - len(clean)

    @classmethod
    def from_arrays(
        cls,
        phi,
        psi,
        kappa=None,
        d=None,
        v=None,
        *,
        warn: bool = True,
        cov=None,
        sigma_d=None,
        min_d: float = 0.0,
        bias_cov=None,
    ) -> PathMeasurements:
        """Apply the consistency checks of Algorithm 1 and drop unusable paths.

        (i) ``d < min_d``: path discarded (``min_d = 0`` as printed; ``-c b_max`` keeps what the
        clock bias explains, see :func:`tunnelkit.extraction.algorithm1`); (ii) ``kappa < 0``
        (or NaN): far field, no curvature; ours: a path with a NaN/inf angle is discarded with a
        :class:`JavelinWarning`. ``cov`` / ``sigma_d`` / ``bias_cov``: the reported uncertainty
        of every input path and its repeating share (see the class).
        """
        for name, value in (("phi", phi), ("psi", psi), ("kappa", kappa), ("d", d), ("v", v)):
            if value is not None:
                series(name, value)
        boolean("warn", warn), real("min_d", min_d)
        phi = np.asarray(phi, dtype=float).reshape(-1)
        n = phi.size
        psi = _opt("psi", psi, n)
        kappa, d, v = _opt("kappa", kappa, n), _opt("d", d, n), _opt("v", v, n)
        bad_angle = ~(np.isfinite(phi) & np.isfinite(psi))
        if warn and np.any(bad_angle):
            warnings.warn(
                f"{int(bad_angle.sum())} path(s) with a NaN angle dropped",
                JavelinWarning,
                stacklevel=2,
            )
        keep = ~bad_angle & ~(d < min_d)
        kappa = np.where(np.isfinite(kappa) & (kappa > 0), kappa, np.nan)
        d = np.where(np.isfinite(d), d, np.nan)
        v = np.where(np.isfinite(v), v, np.nan)
        idx = np.flatnonzero(keep)
        cov, sigma_d = _reported(cov, sigma_d, n)
        bias_cov = _bias(bias_cov, cov, sigma_d, n)
        if cov is not None:
            cov, sigma_d = cov[idx], sigma_d[idx]
        if bias_cov is not None:
            bias_cov = bias_cov[idx]
        return cls(phi[idx], psi[idx], kappa[idx], d[idx], v[idx], idx, cov, sigma_d, bias_cov)

    @classmethod
    def empty(cls) -> PathMeasurements:
        """No path this epoch (everything missed)."""
        z = np.zeros(0)
        return cls(z, z.copy(), z.copy(), z.copy(), z.copy(), np.zeros(0, dtype=int))

    def __len__(self) -> int:
        return self.phi.size

    def subset(self, idx) -> PathMeasurements:
        """The paths at positions ``idx``."""
        raw = np.asarray(idx) if not isinstance(idx, str | bytes) else None
        if raw is None or raw.ndim != 1 or (raw.size and raw.dtype.kind not in "iu"):
            raise TypeError(f"idx: expected a 1-D array of path indices, got {idx!r:.40}")
        if raw.size and (raw.min() < -len(self) or raw.max() >= len(self)):
            raise ValueError(
                f"idx: path indices must lie in [0, {len(self) - 1}], got {raw.tolist()}"
            )
        idx = np.asarray(idx, dtype=int)
        return PathMeasurements(
            self.phi[idx],
            self.psi[idx],
            self.kappa[idx],
            self.d[idx],
            self.v[idx],
            self.source[idx],
            None if self.cov is None else self.cov[idx],
            None if self.sigma_d is None else self.sigma_d[idx],
            None if self.bias_cov is None else self.bias_cov[idx],
            self.origin,
        )

    def triples(self) -> np.ndarray:
        """``(phi, psi, kappa)`` per path, shape (n, 3) (NaN kappa where far field)."""
        return np.column_stack([self.phi, self.psi, self.kappa])


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
            kap, dk_u, dk_v = _reflector_kappa(q[0], q[1:])
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


def _reflector_kappa(qu: np.ndarray, qv: np.ndarray):
    """``||p_r||`` of eq. 45 for VUEs ``qv`` (n, 3) of UE ``qu`` (3,), with its gradients.

    Returns kappa (n,), d kappa / d q_u (n, 3) (lateral and vertical entries used) and
    d kappa / d q_v (n, 3) (the x entry carries the shared ``x_u`` dependence).
    """
    w = qv - qu  # x component is zero by construction
    A = 0.5 * (np.sum(qv[:, 1:] ** 2, axis=1) - np.sum(qu[1:] ** 2))
    B = np.sum(w * qv, 1)
    rv = np.linalg.norm(qv, axis=1)
    degenerate = (np.abs(B) < 1e-9) | (np.linalg.norm(w, axis=1) < 1e-9)
    Bs = np.where(degenerate, 1.0, B)
    kap = np.where(degenerate, rv, rv * A / Bs)
    # A = 1/2 (|q_v,yz|^2 - |q_u,yz|^2); B = (q_v - q_u)_yz . q_v,yz
    dA_u = np.zeros_like(qv)
    dA_u[:, 1:] = -qu[1:]
    dA_v = np.zeros_like(qv)
    dA_v[:, 1:] = qv[:, 1:]
    dB_u = np.zeros_like(qv)
    dB_u[:, 1:] = -qv[:, 1:]
    dB_v = np.zeros_like(qv)
    dB_v[:, 1:] = 2.0 * qv[:, 1:] - qu[1:]
    drv_v = qv / rv[:, None]
    g_u = (rv[:, None] * dA_u) / Bs[:, None] - (rv * A / Bs**2)[:, None] * dB_u
    g_v = (rv[:, None] * dA_v + A[:, None] * drv_v) / Bs[:, None] - (rv * A / Bs**2)[:, None] * dB_v
    sgn = np.where(kap < 0, -1.0, 1.0)[:, None]  # ||p_r|| = |t| ||p_v||
    g_u = np.where(degenerate[:, None], 0.0, sgn * g_u)
    g_v = np.where(degenerate[:, None], drv_v, sgn * g_v)
    return np.abs(kap), g_u, g_v


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
