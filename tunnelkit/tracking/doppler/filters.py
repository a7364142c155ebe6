"""What the vehicle knows and measures, and the Kalman filters on it (Halili et al. 2022,
sections 4-5).

:class:`DopplerSetup` (transmitter, carrier, epoch), the constant-velocity model
(:func:`cv_model`), the pinned-sign Doppler model and its Jacobian (:func:`doppler_model`,
:func:`doppler_jacobian`), the EKF on Doppler with the adaptive R of eq. 13-15
(:class:`DopplerEKF`), the scalar KFs on Doppler and ToA (:class:`SpeedKF`, :class:`RangeKF`) and
the dead reckoning of eq. 16 (:class:`HeadingDeadReckoning`). :func:`scalar_measurement` is the
input check of one epoch's measurement shared by the filters and the approaches.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter, KalmanFilter

from ..._physical import carrier, speeds, step_seconds
from ..._validate import (
    boolean,
    finite_array,
    instance,
    integer,
    nonnegative,
    positive,
    probability,
    real,
)
from ...constants import C
from ...doppler_drive import Drive, GnssFix
from ..cv import cv_process_noise, cv_transition
from ..reopening import (
    DEFAULT_GATE,
    DEFAULT_REOPEN_AFTER,
    REJECT,
    InnovationGate,
    gated_filterpy_update,
)

__all__ = [
    "DopplerEKF",
    "DopplerSetup",
    "HeadingDeadReckoning",
    "MeasurementWarning",
    "RangeKF",
    "SpeedKF",
    "cv_model",
    "doppler_jacobian",
    "doppler_model",
    "scalar_measurement",
]


class MeasurementWarning(UserWarning):
    """A measurement was dropped or rejected; the filter predicted only."""


@dataclass(frozen=True)
class DopplerSetup:
    """What the vehicle knows: transmitter (horizontal), its height above the antenna, carrier, epoch."""

    tx: np.ndarray
    dz: float
    fc: float
    dt: float

    def __post_init__(self) -> None:
        finite_array("tx", self.tx, shape=(2,))
        finite_array("dz", self.dz, ndim=0)
        carrier("fc", self.fc)
        step_seconds("dt", positive("dt", self.dt))

    @classmethod
    def from_drive(cls, drive: Drive) -> DopplerSetup:
        """The setup of a synthetic drive (transmitter position broadcast by the RSU)."""
        instance("drive", drive, Drive)
        return cls(tx=np.array(drive.tx_xy), dz=drive.dz, fc=drive.config.fc, dt=drive.config.dt)

    @property
    def k(self) -> float:
        """``f_c / c`` [Hz per m/s]: the Doppler of one metre per second of approach speed."""
        return self.fc / C


def scalar_measurement(name: str, z) -> float | None:
    """One epoch's measurement ``z`` (parameter ``name``): ``None`` for a dropped epoch (``None``
    or NaN), else a float; infinities and non-numbers are refused."""
    if type(name) is not str or not name:
        raise TypeError(f"name: expected the parameter's name, got {name!r}")
    if z is None:
        return None
    if type(z) is not float and isinstance(z, (str, bytes, bool, np.bool_)):
        raise TypeError(f"{name}: expected a number or None, got {type(z).__name__}")
    try:
        x = float(z)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected a number or None, got {type(z).__name__}") from None
    if math.isnan(x):
        return None
    if not math.isfinite(x):
        raise ValueError(f"{name}: must be finite or NaN (dropped), got {x}")
    return x


def _warn(msg: str) -> None:  # from a filter's _update: the warning names the caller's line
    warnings.warn(msg, MeasurementWarning, stacklevel=4)


def _check_setup(setup) -> DopplerSetup:
    if not isinstance(setup, DopplerSetup):
        raise TypeError(f"setup: expected a DopplerSetup, got {type(setup).__name__}")
    return setup


def _check_adaptive_form(adaptive_form: str) -> str:
    if adaptive_form not in ("posterior", "paper"):
        raise ValueError(f"adaptive_form: must be 'posterior' or 'paper', got {adaptive_form!r}")
    return adaptive_form


# --- the EKF on Doppler (section 4) ---------------------------------------------------------------


def _state(name: str, s) -> np.ndarray:
    """States ``[x, y, v_x, v_y]`` (..., 4): finite and real."""
    s = finite_array(name, s)
    if s.ndim == 0 or s.shape[-1] != 4:
        raise ValueError(f"{name}: expected states [x, y, v_x, v_y] (..., 4), got shape {s.shape}")
    return s


def cv_model(dt: float, q: float) -> tuple[np.ndarray, np.ndarray]:
    """``F`` (eq. 2) and ``Q`` (eq. 3) of the constant-velocity model, state ``[x, y, v_x, v_y]``."""
    dt = step_seconds("dt", positive("dt", dt))
    q = nonnegative("q", q)
    return cv_transition(dt), cv_process_noise(dt, q)  # the same model as Jiang eq. 40-41


def doppler_model(s, setup: DopplerSetup) -> np.ndarray:
    """``h(s)`` of eq. 5 with the pinned sign: ``-(f_c/c) v . (p - T) / r`` [Hz]."""
    s, setup = _state("s", s), _check_setup(setup)
    out = _doppler_model(s, setup)
    if not np.isfinite(out).all():
        raise ValueError("s: a position coincides with the transmitter, the Doppler is undefined")
    return out


def doppler_jacobian(s, setup: DopplerSetup) -> np.ndarray:
    """``H_k = dh/ds`` (eq. 7), shape (..., 1, 4), of the pinned-sign Doppler model.

    With ``w = p - T``, ``r = sqrt(|w|^2 + dz^2)``: ``dh/dp = -(f_c/c) (v / r - (v . w) w / r^3)``,
    ``dh/dv = -(f_c/c) w / r``.
    """
    s, setup = _state("s", s), _check_setup(setup)
    out = _doppler_jacobian(s, setup)
    if not np.isfinite(out).all():
        raise ValueError("s: a position coincides with the transmitter, the Jacobian is undefined")
    return out


# the filters call these every epoch on states they built themselves: no checks, no overhead
def _doppler_model(s: np.ndarray, setup: DopplerSetup) -> np.ndarray:
    w = s[..., :2] - setup.tx
    v = s[..., 2:]
    return -setup.k * np.sum(v * w, -1) / np.sqrt(np.sum(w * w, -1) + setup.dz**2)


def _doppler_jacobian(s: np.ndarray, setup: DopplerSetup) -> np.ndarray:
    w = s[..., :2] - setup.tx
    v = s[..., 2:]
    r = np.sqrt(np.sum(w * w, -1, keepdims=True) + setup.dz**2)
    vw = np.sum(v * w, -1, keepdims=True)
    dp = -setup.k * (v / r - vw * w / r**3)
    dv = -setup.k * w / r
    return np.concatenate([dp, dv], -1)[..., None, :]


def _adaptive_r(R_prev: float, e: float, H: np.ndarray, P: np.ndarray, a: float) -> float:
    """Eq. 15: ``R_k = a R_{k-1} + (1 - a) (e_k^2 + H P H^T)`` for a scalar measurement."""
    return float(a * R_prev + (1 - a) * (e * e + (H @ P @ H.T).item()))


class _KalmanState:
    """``x`` and ``P`` of a filter kept in a filterpy filter ``self.kf`` (the filter protocol,
    :mod:`tunnelkit.tracking.protocol`)."""

    kf: object

    @property
    def x(self) -> np.ndarray:
        """The state (filterpy's column ``kf.x`` as a vector)."""
        return self.kf.x[:, 0]

    @property
    def P(self) -> np.ndarray:
        """The state's covariance."""
        return self.kf.P


class DopplerEKF(_KalmanState):
    """EKF DS: the EKF on Doppler shift, eq. 1-12, optionally with the adaptive R of eq. 13-15.

    ``sigma_hz`` sets the constant ``R = sigma^2`` (the starting value when ``adaptive``); ``q`` is
    the spectral density of eq. 3 (paper: 0.5). ``a`` weighs the previous R in eq. 15 (the paper
    does not state it). The state starts at the GNSS fix with its covariance.

    ``gate`` (not in the paper; default 0.999, ``None`` switches it off) is a probability: a
    Doppler whose squared normalised innovation ``y^2 / S`` exceeds the chi-square quantile with
    one degree of freedom is treated as an outlier (a moving scatterer) and skipped (predict
    only); ``n_rejected`` counts them. After ``reopen_after`` consecutive rejections the next
    Doppler is taken with an inflated covariance (:mod:`tunnelkit.tracking.reopening`).
    """

    def __init__(
        self,
        setup: DopplerSetup,
        fix: GnssFix,
        *,
        sigma_hz: float = 32.79,
        q: float = 0.5,
        adaptive: bool = False,
        a: float = 0.9,
        adaptive_form: str = "posterior",
        gate: float | None = DEFAULT_GATE,
        reopen_after: int = DEFAULT_REOPEN_AFTER,
    ) -> None:
        _check_setup(setup)
        if not isinstance(fix, GnssFix):
            raise TypeError(f"fix: expected a GnssFix, got {type(fix).__name__}")
        sigma_hz = positive("sigma_hz", sigma_hz)
        q = nonnegative("q", q)
        self.a = probability("a", a, open_interval=False)
        _check_adaptive_form(adaptive_form)
        self.setup, self.adaptive, self.adaptive_form = (
            setup,
            boolean("adaptive", adaptive),
            adaptive_form,
        )
        kf = ExtendedKalmanFilter(dim_x=4, dim_z=1)
        kf.F, kf.Q = cv_model(setup.dt, q)
        kf.x = np.concatenate([fix.position, fix.velocity]).reshape(4, 1)
        kf.P = fix.covariance
        kf.R = np.array([[sigma_hz**2]])
        self.kf = kf
        self.gate = InnovationGate(gate, reopen_after=reopen_after)
        self._tx = tuple(float(t) for t in setup.tx)
        self._k, self._dz2 = setup.k, setup.dz**2

    @property
    def n_rejected(self) -> int:
        """Doppler samples the gate rejected (predicted only)."""
        return self.gate.n_rejected

    # one state per call (filterpy's column x): the arithmetic of _doppler_model and
    # _doppler_jacobian on Python floats, operation for operation (bit for bit the same result)
    # without the cost of numpy calls on two-element arrays
    def _h(self, x):
        x0, x1, v0, v1 = x.ravel().tolist()
        tx0, tx1 = self._tx
        w0, w1 = x0 - tx0, x1 - tx1
        r = math.sqrt(w0 * w0 + w1 * w1 + self._dz2)
        return np.array([[-self._k * (v0 * w0 + v1 * w1) / r]])

    def _H(self, x):
        x0, x1, v0, v1 = x.ravel().tolist()
        tx0, tx1 = self._tx
        w0, w1 = x0 - tx0, x1 - tx1
        r = math.sqrt(w0 * w0 + w1 * w1 + self._dz2)
        vw = v0 * w0 + v1 * w1
        r3 = float(np.power(np.array([r]), 3)[0])  # numpy's power, as _doppler_jacobian
        mk = -self._k
        return np.array(
            [[mk * (v0 / r - vw * w0 / r3), mk * (v1 / r - vw * w1 / r3), mk * w0 / r, mk * w1 / r]]
        )

    def predict(self) -> None:
        """Predict (eq. 8-9)."""
        kf = self.kf
        kf.predict()
        kf.P = 0.5 * (kf.P + kf.P.T)  # F P F^T and the Joseph form leave rounding asymmetry

    def update(self, z) -> np.ndarray:
        """Update with Doppler ``z`` [Hz] (eq. 10-12) unless ``z`` is None/NaN; the position."""
        return self._update(scalar_measurement("z", z))

    def step(self, z) -> np.ndarray:
        """:meth:`predict`, then :meth:`update` with Doppler ``z`` [Hz]; the position."""
        z = scalar_measurement("z", z)
        self.predict()
        return self._update(z)

    def _update(self, z: float | None) -> np.ndarray:
        kf = self.kf
        if z is None:
            _warn("Doppler: dropped epoch (None/NaN); EKF predicted only")
            kf.update(None, self._H, self._h)
            return self.position
        # the prior Jacobian is only needed by the adaptive R (kf.update makes its own)
        H = self._H(kf.x) if self.adaptive else None
        P_prior = kf.P.copy()
        zz = np.array([[z]])
        verdict = gated_filterpy_update(kf, lambda: kf.update(zz, self._H, self._h), self.gate)
        kf.P = 0.5 * (kf.P + kf.P.T)
        if verdict == REJECT:
            return self.position
        if self.adaptive:
            e = z - float(self._h(kf.x)[0, 0])  # eq. 13, post-fit residual
            P = kf.P if self.adaptive_form == "posterior" else P_prior
            kf.R = np.array([[_adaptive_r(float(kf.R[0, 0]), e, H, P, self.a)]])
        return self.position

    @property
    def position(self) -> np.ndarray:
        return self.kf.x[:2, 0].copy()

    @property
    def velocity(self) -> np.ndarray:
        return self.kf.x[2:, 0].copy()

    @property
    def approach_speed(self) -> float:
        """``-v . (p - T) / r`` of the current estimate [m/s] (positive when approaching)."""
        f = float(self._h(self.kf.x)[0, 0])
        if not math.isfinite(f):
            raise ValueError(
                "the estimate coincides with the transmitter, the Doppler is undefined"
            )
        return f / self.setup.k


# --- the KFs on Doppler and ToA (section 5) -------------------------------------------------------


class SpeedKF(_KalmanState):
    """KF DS: scalar KF on Doppler for the approach speed ``u`` (sec. 5), ``H = f_c / c``.

    The state is the speed towards the transmitter (positive approaching, negative receding), so
    ``z = (f_c/c) u + r`` is exactly linear; calling it "the speed" ignores the angle between the
    heading and the line of sight, which is the paper's simplification. Random-walk model with
    ``Q = q dt`` (the paper's ``Q = 0.5`` read as a spectral density so it does not depend on
    the epoch rate). ``gate``/``reopen_after`` as in :class:`DopplerEKF`.
    """

    def __init__(
        self,
        setup: DopplerSetup,
        u0: float,
        *,
        sigma_hz: float = 32.79,
        q: float = 0.5,
        sigma_u0: float = 0.5,
        adaptive: bool = False,
        a: float = 0.9,
        adaptive_form: str = "posterior",
        gate: float | None = DEFAULT_GATE,
        reopen_after: int = DEFAULT_REOPEN_AFTER,
    ) -> None:
        _check_setup(setup)
        sigma_hz = positive("sigma_hz", sigma_hz)
        q = nonnegative("q", q)
        u0 = float(finite_array("u0", u0, ndim=0))
        self.a = probability("a", a, open_interval=False)
        _check_adaptive_form(adaptive_form)
        self.adaptive, self.adaptive_form = boolean("adaptive", adaptive), adaptive_form
        kf = KalmanFilter(dim_x=1, dim_z=1)
        kf.x = np.array([[u0]])
        kf.P = np.array([[positive("sigma_u0", sigma_u0) ** 2]])
        kf.F = np.array([[1.0]])
        kf.Q = np.array([[q * setup.dt]])
        kf.H = np.array([[setup.k]])
        kf.R = np.array([[sigma_hz**2]])
        self.kf = kf
        self.gate = InnovationGate(gate, reopen_after=reopen_after)

    @property
    def n_rejected(self) -> int:
        """Doppler samples the gate rejected (predicted only)."""
        return self.gate.n_rejected

    def predict(self) -> None:
        """Predict (random walk)."""
        self.kf.predict()

    def update(self, z) -> float:
        """Update with Doppler ``z`` [Hz] unless dropped (None/NaN); the speed."""
        return self._update(scalar_measurement("z", z))

    def step(self, z) -> float:
        """:meth:`predict`, then :meth:`update` with Doppler ``z`` [Hz]; the speed."""
        z = scalar_measurement("z", z)
        self.predict()
        return self._update(z)

    def _update(self, z: float | None) -> float:
        kf = self.kf
        if z is None:
            _warn("Doppler: dropped epoch (None/NaN); speed KF predicted only")
            kf.update(None)
            return self.speed
        P_prior = kf.P.copy()
        zz = np.array([[z]])
        if gated_filterpy_update(kf, lambda: kf.update(zz), self.gate) == REJECT:
            return self.speed
        if self.adaptive:
            e = z - float((kf.H @ kf.x)[0, 0])  # eq. 13
            P = kf.P if self.adaptive_form == "posterior" else P_prior
            kf.R = np.array([[_adaptive_r(float(kf.R[0, 0]), e, kf.H, P, self.a)]])
        return self.speed

    @property
    def speed(self) -> float:
        return float(self.kf.x[0, 0])


class RangeKF(_KalmanState):
    """KF ToA: scalar KF on the transmitter-receiver distance (eq. 17-21).

    Prediction ``d_k = d_{k-1} - dt u_k`` with ``u`` the approach speed from the Doppler (eq. 17,
    sign corrected), ``Q = q dt``; update with ToA ``z = d / c + r`` (``H = 1/c``, eq. 19-21).

    ``calibrate`` removes the unknown clock offset against the GNSS distance ``d0`` (sec. 5:
    "perform calibration when using travel time measurements"). The paper does not say how; one
    sample would carry any error of that sample into every later epoch (a 100 m NLOS excess
    shifts the whole drive by 100 m), so the first ``calibration_epochs`` valid ToAs are
    compared with the dead-reckoned distance (predict only meanwhile); samples more than
    ``5 max(1.4826 MAD, sigma_toa)`` from their median are outliers (``calibration_outliers``
    counts them) and the offset is that of the first other sample: the paper's one-sample
    calibration, with the sample checked against the others. (Averaging the samples instead
    would average the dead-reckoning drift of the calibration window into the offset: a Doppler
    bias of 2 m/s over ten epochs moves it by about 0.3 m.) ``calibration_epochs=1`` is the
    unchecked single-sample calibration.

    Every later ToA passes a chi-square gate (``gate``, ``reopen_after``; see
    :mod:`tunnelkit.tracking.reopening`); ``n_rejected`` counts the rejected ToAs (gate and
    calibration). A ToA implying a distance below ``d_min`` (the transmitter's height above the
    antenna) is physically impossible and is rejected with a warning.
    """

    def __init__(
        self,
        setup: DopplerSetup,
        d0: float,
        *,
        sigma_toa: float = 3e-9,
        q: float = 0.5,
        sigma_d0: float = 2.0,
        calibrate: bool = True,
        calibration_epochs: int = 10,
        gate: float | None = DEFAULT_GATE,
        reopen_after: int = DEFAULT_REOPEN_AFTER,
    ) -> None:
        _check_setup(setup)
        d0 = positive("d0", d0)
        sigma_toa = positive("sigma_toa", sigma_toa)
        q = nonnegative("q", q)
        self.calibration_epochs = integer("calibration_epochs", calibration_epochs, minimum=1)
        self.setup, self.calibrate, self.sigma_toa = (
            setup,
            boolean("calibrate", calibrate),
            sigma_toa,
        )
        self.offset: float | None = None if calibrate else 0.0
        self.calibration_outliers = 0
        self._calib: list[float] = []  # ToA minus predicted distance / c
        self.d_min = abs(setup.dz)
        self._d_min_margin = 5 * sigma_toa * C
        kf = KalmanFilter(dim_x=1, dim_z=1, dim_u=1)
        kf.x = np.array([[d0]])
        kf.P = np.array([[positive("sigma_d0", sigma_d0) ** 2]])
        kf.F = np.array([[1.0]])
        kf.B = np.array([[setup.dt]])
        kf.Q = np.array([[q * setup.dt]])
        kf.H = np.array([[1.0 / C]])
        kf.R = np.array([[sigma_toa**2]])
        self.kf = kf
        self.gate = InnovationGate(gate, reopen_after=reopen_after)

    @property
    def n_rejected(self) -> int:
        """ToAs rejected by the gate or left out of the calibration."""
        return self.gate.n_rejected + self.calibration_outliers

    def _calibrated(self, z: float) -> bool:
        """Collect one calibration sample; True once the offset is set."""
        self._calib.append(z - self.distance / C)
        if len(self._calib) < self.calibration_epochs:
            return False
        o = np.asarray(self._calib)
        med = float(np.median(o))
        spread = max(1.4826 * float(np.median(np.abs(o - med))), self.sigma_toa)
        keep = np.abs(o - med) <= 5 * spread
        self.offset = float(o[np.argmax(keep)])  # the first sample that is not an outlier
        self.calibration_outliers = int(np.sum(~keep))
        return True

    def predict(self, u: float) -> None:
        """Predict with approach speed ``u`` [m/s] (eq. 17)."""
        self._predict(float(finite_array("u", u, ndim=0)))

    def update(self, z) -> float:
        """Update with ToA ``z`` [s] (eq. 19-21) unless dropped or impossible; the distance."""
        return self._update(scalar_measurement("z", z))

    def step(self, u: float, z) -> float:
        """:meth:`predict` with approach speed ``u`` [m/s], then :meth:`update` with ToA ``z``
        [s]; the distance."""
        u = float(finite_array("u", u, ndim=0))
        z = scalar_measurement("z", z)
        self._predict(u)
        return self._update(z)

    def _predict(self, u: float) -> None:
        self.kf.predict(u=np.array([[-u]]))

    def _update(self, z: float | None) -> float:
        kf = self.kf
        if z is not None and z <= 0:
            _warn(f"ToA: {z:.3e} s is not a time of flight; KF ToA predicted only")
            z = None
        if z is not None and self.offset is None and not self._calibrated(z):
            z = None  # still calibrating: predict only
        if z is not None and C * (z - self.offset) < self.d_min - self._d_min_margin:
            _warn(
                f"ToA: distance {C * (z - self.offset):.2f} m is below the physical minimum "
                f"{self.d_min:.2f} m; KF ToA predicted only"
            )
            z = None
        if z is None:
            kf.update(None)
            return self.distance
        zz = np.array([[z - self.offset]])
        gated_filterpy_update(kf, lambda: kf.update(zz), self.gate)
        return self.distance

    @property
    def distance(self) -> float:
        return float(self.kf.x[0, 0])


class HeadingDeadReckoning:
    """Eq. 16: ``x_k = x_{k-1} + dr sin(phi)``, ``y_k = y_{k-1} + dr cos(phi)``.

    ``phi`` is the heading from the y axis, taken from the past estimated positions (the last
    displacement longer than ``min_step``, oriented forward), starting from the GNSS velocity.
    ``dr`` is the signed change of the filtered distance along the direction of travel (positive
    forward). The paper defines it in words, "the difference between two successive distances
    (d_{k-1} and d_k)", with no order or sign rule: one fixed order moves the vehicle backwards on
    one of the two legs, and the magnitude ``|d_k - d_{k-1}|`` would turn a range correction that
    is later undone into two forward steps. Near the transmitter (where the distance barely
    changes) the position stalls: the paper's radial-motion approximation.
    """

    def __init__(self, p0, v0, *, min_step: float = 1e-3) -> None:
        self.p = finite_array("p0", p0, shape=(2,)).copy()
        v0 = speeds("v0", finite_array("v0", v0, shape=(2,)))
        if np.linalg.norm(v0) < 1e-6:
            raise ValueError("v0: speed of zero, the initial heading is undefined")
        self.phi = float(np.arctan2(v0[0], v0[1]))
        self.min_step = positive("min_step", min_step)
        self._last = self.p.copy()

    def step(self, dr: float) -> np.ndarray:
        """Advance by ``dr`` [m] along the current heading (back if negative); update the heading."""
        dr = real("dr", dr)
        self.p = self.p + dr * np.array([np.sin(self.phi), np.cos(self.phi)])
        disp = self.p - self._last
        if np.hypot(*disp) >= self.min_step:
            phi = float(np.arctan2(disp[0], disp[1]))
            if np.cos(phi - self.phi) < 0:  # a net step back: the vehicle still faces forward
                phi = float(np.arctan2(-disp[0], -disp[1]))
            self.phi = phi
            self._last = self.p.copy()
        return self.p.copy()
