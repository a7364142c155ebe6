"""Tracking a vehicle from virtual-station TOA/DOA (Jiang et al. 2023, section 4.2).

The measurement at epoch ``k`` (eq. 42-45) stacks the ranges and then the bearings from every
station to the vehicle::

    Z_k = [d_1k .. d_Nk, beta_1k .. beta_Nk] + V_k,   V_k ~ N(0, R),
    R   = diag(sigma_d^2 .. sigma_d^2, sigma_theta^2 .. sigma_theta^2)

In NLOS the stations are the two virtual stations (the base station mirrored in the walls,
eq. 3-4); in LOS the base station itself (the direct path) comes first. The state follows the
constant-velocity model of :mod:`tunnelkit.tracking.cv` (eq. 40-41).

Four interchangeable estimators are registered in family ``"jiang2023"``:

``TSWLS``  snapshot two-stage WLS (eq. 29-39, :func:`tunnelkit.positioning.tswls`), no motion model;
``EKF``    filterpy ``ExtendedKalmanFilter`` with the analytic Jacobian (sign-corrected eq. A2);
``UKF``    filterpy ``UnscentedKalmanFilter`` with ``MerweScaledSigmaPoints`` (eq. 46-58);
``UPF``    the unscented particle filter of :mod:`tunnelkit.tracking.upf` (eq. 46-63).

All speak filterpy: ``x``, ``P``, ``predict()``, ``update(z)`` with ``update(None)`` for a missed
epoch. A measurement containing NaN is treated as missed (predict only) with a warning. Bearing
residuals are wrapped to ``(-pi, pi]`` and bearing means are taken relative to a reference, so a
bearing near +-pi does not average to zero.

Not in the paper, on by default: the EKF, UKF and UPF gate each measurement vector on the squared
Mahalanobis distance of its innovation against ``chi2_2N(gate)`` (``gate = 0.999``,
:mod:`tunnelkit.tracking.gating`); a rejected vector (a gross range or bearing outlier) is a
missed epoch, counted in ``n_rejected``; ``gate=None`` gives the paper's filters.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter, MerweScaledSigmaPoints, UnscentedKalmanFilter

from .. import positioning
from .._validate import finite_array, integer, positive, rng_or_error
from ..crlb import _wrap, fim_toa_doa, toa_doa, toa_doa_jacobian, wrap_angle
from .cv import STATE_DIM, cv_process_noise, cv_transition
from .gating import DEFAULT_GATE, DEFAULT_REOPEN_AFTER, InnovationGate, gated_filterpy_update
from .registry import register

__all__ = [
    "FAMILY",
    "EstimatorBase",
    "VsEKF",
    "VsExperiment",
    "VsModel",
    "VsTSWLS",
    "VsUKF",
    "experiment",
    "initial_states",
    "measurement_ok",
    "model_from_scenario",
    "monte_carlo",
    "regularized_cholesky",
    "run_estimator",
    "track",
]

#: registry family of this setting
FAMILY = "jiang2023"


# --- numerics shared by the UKF and the UPF -------------------------------------------------------


def regularized_cholesky(P, *, name: str = "P", rel_floor: float = 1e-10) -> np.ndarray:
    """Lower Cholesky factor(s) of ``P`` (..., n, n), regularising instead of failing.

    ``P`` is symmetrised first. Where it is not positive definite (rounding, a collapsed
    particle, a bad prior) its eigenvalues are clipped to ``rel_floor * max(|eig|)`` (at least
    ``1e-12``) and a ``RuntimeWarning`` says so; the factor is never NaN.
    """
    P = np.asarray(P, dtype=float)
    if not np.all(np.isfinite(P)):
        raise ValueError(f"{name}: covariance contains NaN or infinite values")
    P = 0.5 * (P + np.swapaxes(P, -1, -2))
    try:
        return np.linalg.cholesky(P)
    except np.linalg.LinAlgError:
        pass
    ev, V = np.linalg.eigh(P)
    floor = np.maximum(rel_floor * np.max(np.abs(ev), axis=-1, keepdims=True), 1e-12)
    n_bad = int(np.sum(np.any(ev < floor, axis=-1)))
    warnings.warn(
        f"{name}: {n_bad} covariance matrix(es) not positive definite; eigenvalues clipped "
        f"to keep the Cholesky factor defined",
        RuntimeWarning,
        stacklevel=2,
    )
    ev = np.maximum(ev, floor)
    P = (V * ev[..., None, :]) @ np.swapaxes(V, -1, -2)
    P = 0.5 * (P + np.swapaxes(P, -1, -2))
    return np.linalg.cholesky(P)


def _upper_sqrt(P):
    """filterpy's ``sqrt_method`` convention: upper-triangular ``U`` with ``U^T U = P``."""
    return regularized_cholesky(P, name="UKF sigma-point covariance").T


# --- measurement model ----------------------------------------------------------------------------


@dataclass(frozen=True)
class VsModel:
    """Constant-velocity state (eq. 40-41) observed by ranges and bearings (eq. 42-45).

    ``stations`` (N, 2): the base station first if ``los``, then the virtual stations.
    ``sigma_theta`` [rad], ``sigma_d`` [m] are the measurement noise levels, ``period`` [s] the
    observation period ``T1``, ``q`` [m^2/s^3] the process-noise density (see :mod:`.cv`).
    """

    stations: np.ndarray
    sigma_theta: float
    sigma_d: float
    period: float
    q: float
    los: bool = False
    F: np.ndarray = field(init=False, repr=False)
    Q: np.ndarray = field(init=False, repr=False)
    R: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        st = finite_array("stations", self.stations, ndim=2)
        if st.shape[1] != 2 or st.shape[0] < 1:
            raise ValueError(f"stations: expected shape (N, 2) with N >= 1, got {st.shape}")
        set_ = object.__setattr__
        set_(self, "stations", st)
        set_(self, "sigma_theta", positive("sigma_theta", self.sigma_theta))
        set_(self, "sigma_d", positive("sigma_d", self.sigma_d))
        set_(self, "period", positive("period", self.period))
        set_(self, "q", positive("q", self.q))
        set_(self, "F", cv_transition(self.period))
        set_(self, "Q", cv_process_noise(self.period, self.q))
        n = st.shape[0]
        set_(self, "R", np.diag([self.sigma_d**2] * n + [self.sigma_theta**2] * n))

    # sizes and masks
    @property
    def n_stations(self) -> int:
        return int(self.stations.shape[0])

    @property
    def dim_z(self) -> int:
        """Length of one measurement vector (eq. 45): N ranges then N bearings."""
        return 2 * self.n_stations

    @property
    def angle_mask(self) -> np.ndarray:
        """True for the bearing components of ``Z``."""
        n = self.n_stations
        return np.r_[np.zeros(n, bool), np.ones(n, bool)]

    # eq. 42-45
    def hx(self, x) -> np.ndarray:
        """``f_2(X)`` of eq. 45 for state(s) ``x`` (..., 4) -> (..., 2N)."""
        d, th = toa_doa(np.asarray(x)[..., :2], self.stations)
        return np.concatenate([d, th], axis=-1)

    def jacobian(self, x) -> np.ndarray:
        """``d f_2 / d X`` (..., 2N, 4): the position block of eq. A2-A9 (sign-corrected), zeros
        for the velocities."""
        x = np.asarray(x, dtype=float)
        J = toa_doa_jacobian(x[..., :2], self.stations)
        return np.concatenate([J, np.zeros_like(J)], axis=-1)

    def residual_z(self, a, b) -> np.ndarray:
        """``a - b`` with the bearing components wrapped to ``(-pi, pi]``."""
        r = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
        n = self.n_stations
        r[..., n:] = _wrap(r[..., n:])  # inner loop: inputs are checked where they enter
        return r

    def z_mean(self, sigmas, Wm) -> np.ndarray:
        """Weighted mean of measurement sigma points (..., S, 2N) with weights ``Wm`` (S,).

        Bearings are averaged as wrapped offsets from the first sigma point, so the mean of
        bearings straddling +-pi is right; the result's bearings are wrapped.
        """
        sig = np.asarray(sigmas, dtype=float)
        ref = sig[..., :1, :]
        m = ref[..., 0, :] + np.einsum(
            "s,...sj->...j", np.asarray(Wm, float), self.residual_z(sig, ref)
        )
        n = self.n_stations
        m[..., n:] = _wrap(m[..., n:])
        return m

    def log_likelihood(self, z, x) -> np.ndarray:
        """``log p(Z | X)`` up to a constant, for state(s) ``x`` (..., 4) and ``z`` broadcasting."""
        r = self.residual_z(z, self.hx(x))
        return -0.5 * np.sum(r * r / np.diag(self.R), axis=-1)

    def simulate(self, positions, rng: np.random.Generator, size: int | None = None) -> np.ndarray:
        """Noisy measurements ``Z`` (eq. 44) at true positions (T, 2): shape (T, 2N) or (size, T, 2N)."""
        d_hat, th_hat = positioning.simulate_toa_doa(
            positions, self.stations, self.sigma_theta, self.sigma_d, rng, size=size
        )
        return np.concatenate([d_hat, wrap_angle(th_hat)], axis=-1)

    def position_fim(self, p) -> np.ndarray:
        """Fisher information of the position from one epoch (eq. 20-27, corrected), (..., 2, 2)."""
        return fim_toa_doa(p, self.stations, self.sigma_theta, self.sigma_d)

    def with_noise(self, sigma_theta: float, sigma_d: float) -> VsModel:
        """The same geometry and motion model at another noise level."""
        return VsModel(self.stations, sigma_theta, sigma_d, self.period, self.q, self.los)


def model_from_scenario(
    scenario,
    *,
    level: int | tuple[float, float] = 0,
    los: bool = False,
    q: float | None = None,
    period: float | None = None,
) -> VsModel:
    """Build a :class:`VsModel` from a scenario name or :class:`~tunnelkit.scenarios.Scenario`.

    ``level`` is an index into the scenario's ``[noise] levels`` or an explicit
    ``(sigma_theta [rad], sigma_d [m])``. ``q`` defaults to ``[tracking] q`` and ``period`` to
    the trajectory's sampling period (the observation period ``T1`` of eq. 41).
    """
    from ..scenarios import load_scenario

    sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
    tunnel = sc.tunnel()
    bs = sc.base_station()
    stations = tunnel.virtual_stations(bs)
    if los:
        stations = np.vstack([bs, stations])
    if isinstance(level, tuple):
        sth, sd = level
    else:
        levels = sc.noise_levels()
        level = integer("level", level, minimum=0)
        if level >= len(levels):
            raise ValueError(
                f"level: index {level} out of range, the scenario has {len(levels)} levels"
            )
        sth, sd = levels[level]
    q = sc.get("tracking.q") if q is None else q
    period = sc.trajectory(tunnel).period if period is None else period
    return VsModel(stations, sth, sd, period, q, los)


def initial_states(truth_x0, P0, rng: np.random.Generator, size: int | None = None) -> np.ndarray:
    """Prior means drawn from ``N(truth_x0, P0)``: (4,) or (size, 4).

    Drawing the prior mean around the truth (instead of starting at it) makes the filters' prior
    ``N(x0_hat, P0)`` honest, which is what the posterior CRLB with ``J_0 = P0^-1`` assumes.
    """
    x0 = finite_array("truth_x0", truth_x0, shape=(STATE_DIM,))
    L = regularized_cholesky(finite_array("P0", P0, shape=(STATE_DIM, STATE_DIM)), name="P0")
    rng = rng_or_error("rng", rng)
    shape = (STATE_DIM,) if size is None else (integer("size", size, minimum=1), STATE_DIM)
    return x0 + rng.standard_normal(shape) @ L.T


def measurement_ok(z, dim_z: int, *, who: str = "update") -> np.ndarray | None:
    """``z`` as a float vector, or ``None`` (with a warning) if it is missing or holds NaN/inf.

    ``None`` means "missed epoch": the caller predicts only.
    """
    if z is None:
        return None
    try:
        arr = np.asarray(z, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"z: expected {dim_z} numbers or None, got {type(z).__name__}") from exc
    if arr.shape != (dim_z,):
        raise ValueError(f"z: expected shape ({dim_z},), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        warnings.warn(
            f"{who}: measurement contains NaN/inf; epoch skipped (predict only)",
            RuntimeWarning,
            stacklevel=3,
        )
        return None
    return arr


# --- estimators -----------------------------------------------------------------------------------


class EstimatorBase:
    """Common surface: ``x`` (4,), ``P`` (4, 4), ``position``, ``predict()``, ``update(z)``."""

    name = "base"
    model: VsModel

    @property
    def position(self) -> np.ndarray:
        return np.asarray(self.x, dtype=float)[:2].copy()

    def step(self, z, *, first: bool = False) -> np.ndarray:
        """``predict()`` (unless ``first``) then ``update(z)``; returns the state estimate."""
        if not first:
            self.predict()
        self.update(z)
        return np.asarray(self.x, dtype=float).copy()

    @classmethod
    def run(
        cls, model: VsModel, Z, x0, P0, *, rng: np.random.Generator | None = None, **options
    ) -> np.ndarray:
        """Estimates (R, T, 4) for measurement runs ``Z`` (R, T, 2N) and priors ``x0`` (R, 4).

        The default loops over runs; vectorised estimators override it. A row of NaN in ``Z``
        is a missed epoch.
        """
        Z = np.asarray(Z, dtype=float)
        x0 = np.asarray(x0, dtype=float)
        out = np.empty((*Z.shape[:2], STATE_DIM))
        for r in range(Z.shape[0]):
            est = cls(model, x0[r], P0, rng=rng, **options)
            out[r] = track(est, Z[r])
        return out


def _check_prior(x0, P0) -> tuple[np.ndarray, np.ndarray]:
    x0 = finite_array("x0", x0, shape=(STATE_DIM,))
    P0 = finite_array("P0", P0, shape=(STATE_DIM, STATE_DIM))
    if not np.allclose(P0, P0.T, atol=1e-12 * max(1.0, np.abs(P0).max())):
        raise ValueError("P0: must be symmetric")
    if np.any(np.linalg.eigvalsh(P0) <= 0):
        raise ValueError("P0: must be positive definite")
    return x0.copy(), P0.copy()


def _check_model(model) -> VsModel:
    if not isinstance(model, VsModel):
        raise TypeError(
            f"model: expected a VsModel (see model_from_scenario), got {type(model).__name__}"
        )
    return model


@register(FAMILY, "TSWLS")
class VsTSWLS(EstimatorBase):
    """Snapshot TSWLS (Jiang eq. 29-39) behind the filter interface; no motion model.

    ``update(z)`` replaces the position by the TSWLS solution of this epoch alone; the velocity is
    the difference of successive fixes divided by the time between them (the prior velocity until
    the second fix). ``P`` holds the inverse snapshot Fisher information in the position block. On
    a missed epoch the previous fix (and velocity) is held (a snapshot method has nothing to
    predict with).
    """

    name = "TSWLS"

    def __init__(self, model: VsModel, x0, P0, *, rng: np.random.Generator | None = None) -> None:
        self.model = _check_model(model)
        self.x, self.P = _check_prior(x0, P0)
        self._has_fix = False
        self._since = 0  # epochs (predict calls) since the last fix

    def predict(self) -> None:
        self._since += 1

    def update(self, z) -> None:
        z = measurement_ok(z, self.model.dim_z, who="TSWLS")
        if z is None:
            return
        n, m = self.model.n_stations, self.model
        p = positioning.tswls(m.stations, z[:n], z[n:], m.sigma_d, m.sigma_theta)
        if self._has_fix and self._since > 0:  # a missed epoch in between doubles the time
            self.x[2:] = (p - self.x[:2]) / (self._since * m.period)
        self.x[:2] = p
        self.P[:2, :2] = np.linalg.inv(m.position_fim(p))
        self._has_fix = True
        self._since = 0

    @classmethod
    def run(cls, model, Z, x0, P0, *, rng=None, **options) -> np.ndarray:
        """Vectorised over runs and epochs in one :func:`tunnelkit.positioning.tswls` call."""
        model = _check_model(model)
        Z = np.asarray(Z, dtype=float)
        n = model.n_stations
        ok = np.all(np.isfinite(Z), axis=-1)
        Zf = np.where(ok[..., None], Z, model.hx(np.asarray(x0)[:, None, :]))  # placeholder rows
        p = positioning.tswls(
            model.stations, Zf[..., :n], Zf[..., n:], model.sigma_d, model.sigma_theta
        )
        # hold the last fix over missed epochs (the prior before the first fix)
        ep = np.arange(Z.shape[1])
        idx = np.maximum.accumulate(np.where(ok, ep, -1), axis=1)  # last fix at or before k
        x0 = np.asarray(x0, dtype=float)
        prior = np.broadcast_to(x0[:, None, :2], p.shape)
        held = np.take_along_axis(p, np.maximum(idx, 0)[..., None], axis=1)
        pos = np.where((idx >= 0)[..., None], held, prior)
        # velocity at a fix: displacement from the previous fix over the time between them (as
        # in update()); held over missed epochs; the prior velocity until the second fix
        prev = np.concatenate([np.full((Z.shape[0], 1), -1), idx[:, :-1]], axis=1)
        p_prev = np.take_along_axis(p, np.maximum(prev, 0)[..., None], axis=1)
        v_prior = np.broadcast_to(x0[:, None, 2:], p.shape)
        gap = ((ep - prev) * model.period)[..., None]
        v_fix = np.where((ok & (prev >= 0))[..., None], (p - p_prev) / gap, v_prior)
        held_v = np.take_along_axis(v_fix, np.maximum(idx, 0)[..., None], axis=1)
        vel = np.where((idx >= 0)[..., None], held_v, v_prior)
        return np.concatenate([pos, vel], axis=-1)


class _FilterpyEstimator(EstimatorBase):
    """An estimator wrapping a filterpy filter in ``self.filter``; P is kept symmetric.

    ``gate`` is the chi-square gate of the innovation (probability, or None for none).
    """

    filter: ExtendedKalmanFilter | UnscentedKalmanFilter
    gate: InnovationGate

    @property
    def n_rejected(self) -> int:
        """Measurements the gate rejected (predicted only)."""
        return self.gate.n_rejected

    @property
    def n_reopened(self) -> int:
        """Measurements taken with an inflated covariance after repeated rejections."""
        return self.gate.n_reopened

    @property
    def x(self) -> np.ndarray:
        return self.filter.x

    @property
    def P(self) -> np.ndarray:
        return self.filter.P

    def _symmetrize(self) -> None:
        P = self.filter.P
        self.filter.P = 0.5 * (P + P.T)


@register(FAMILY, "EKF")
class VsEKF(_FilterpyEstimator):
    """filterpy ``ExtendedKalmanFilter`` on eq. 40-45 with the analytic Jacobian and wrapped
    bearing residuals; ``gate``/``reopen_after`` as in :mod:`tunnelkit.tracking.gating`."""

    name = "EKF"

    def __init__(
        self,
        model: VsModel,
        x0,
        P0,
        *,
        rng: np.random.Generator | None = None,
        gate: float | None = DEFAULT_GATE,
        reopen_after: int = DEFAULT_REOPEN_AFTER,
    ) -> None:
        self.model = _check_model(model)
        self.gate = InnovationGate(gate, reopen_after=reopen_after)
        x0, P0 = _check_prior(x0, P0)
        f = ExtendedKalmanFilter(dim_x=STATE_DIM, dim_z=model.dim_z)
        f.x, f.P = x0, P0
        f.F, f.Q, f.R = model.F.copy(), model.Q.copy(), model.R.copy()
        self.filter = f

    def predict(self) -> None:
        self.filter.predict()
        self._symmetrize()

    def update(self, z) -> None:
        z = measurement_ok(z, self.model.dim_z, who="EKF")
        m, f = self.model, self.filter
        if z is None:
            f.update(None, m.jacobian, m.hx)
            return
        # filterpy updates P in Joseph form; symmetrise to remove rounding asymmetry
        gated_filterpy_update(
            f, lambda: f.update(z, m.jacobian, m.hx, residual=m.residual_z), self.gate
        )
        self._symmetrize()


@register(FAMILY, "UKF")
class VsUKF(_FilterpyEstimator):
    """filterpy ``UnscentedKalmanFilter`` with ``MerweScaledSigmaPoints`` (eq. 46-58).

    ``alpha, beta, kappa`` are the scaling parameters of eq. 47-50. The square root of the
    sigma-point covariance is a regularised Cholesky factor (warns instead of failing). Bearings
    use the wrapped residual and reference-based mean of :class:`VsModel`. ``gate`` and
    ``reopen_after`` as in :mod:`tunnelkit.tracking.gating` (a reopened measurement redraws the
    sigma points from the inflated prior).
    """

    name = "UKF"

    def __init__(
        self,
        model: VsModel,
        x0,
        P0,
        *,
        rng: np.random.Generator | None = None,
        alpha: float = 1.0,
        beta: float = 2.0,
        kappa: float = 0.0,
        gate: float | None = DEFAULT_GATE,
        reopen_after: int = DEFAULT_REOPEN_AFTER,
    ) -> None:
        self.model = _check_model(model)
        self.gate = InnovationGate(gate, reopen_after=reopen_after)
        x0, P0 = _check_prior(x0, P0)
        pts = MerweScaledSigmaPoints(
            STATE_DIM,
            alpha=positive("alpha", alpha),
            beta=beta,
            kappa=kappa,
            sqrt_method=_upper_sqrt,
        )
        f = UnscentedKalmanFilter(
            dim_x=STATE_DIM,
            dim_z=model.dim_z,
            dt=model.period,
            hx=model.hx,
            fx=lambda x, dt: model.F @ x,
            points=pts,
            z_mean_fn=model.z_mean,
            residual_z=model.residual_z,
        )
        f.x, f.P = x0, P0
        f.Q, f.R = model.Q.copy(), model.R.copy()
        # filterpy draws sigma points only in predict(); the first epoch updates the prior directly
        f.sigmas_f = pts.sigma_points(x0, P0)
        self.filter = f

    def predict(self) -> None:
        self.filter.predict()

    def update(self, z) -> None:
        z = measurement_ok(z, self.model.dim_z, who="UKF")
        f = self.filter
        if z is None:
            f.update(None)
            return

        def redraw() -> None:  # sigma points of the inflated prior
            f.sigmas_f = f.points_fn.sigma_points(f.x, f.P)

        gated_filterpy_update(f, lambda: f.update(z), self.gate, redraw=redraw)
        self._symmetrize()


def track(estimator, Z) -> np.ndarray:
    """Run ``estimator`` over the measurements ``Z`` (T, 2N) (rows may be ``None``/NaN): (T, 4).

    Epoch 0 updates the prior directly; every later epoch predicts, then updates.
    """
    out = np.empty((len(Z), STATE_DIM))
    for k, z in enumerate(Z):
        z = None if z is None or not np.all(np.isfinite(np.asarray(z, dtype=float))) else z
        out[k] = estimator.step(z, first=(k == 0))
    return out


def run_estimator(
    name: str, model: VsModel, Z, x0, P0, *, rng: np.random.Generator | None = None, **options
) -> np.ndarray:
    """Estimates (R, T, 4) of registry member ``name`` over measurement runs ``Z`` (R, T, 2N)."""
    from .registry import get

    cls = get(FAMILY, name)
    model = _check_model(model)
    Z = np.asarray(Z, dtype=float)
    if Z.ndim != 3 or Z.shape[-1] != model.dim_z:
        raise ValueError(f"Z: expected shape (runs, epochs, {model.dim_z}), got {Z.shape}")
    x0 = finite_array("x0", x0, shape=(Z.shape[0], STATE_DIM))
    _check_prior(x0[0], P0)
    if rng is not None:
        rng_or_error("rng", rng)
    return cls.run(model, Z, x0, P0, rng=rng, **options)


# --- experiments (Jiang section 5) -----------------------------------------------------------------


@dataclass(frozen=True)
class VsExperiment:
    """A scenario at one noise level: ``model``, true states ``truth`` (T, 4), prior covariance ``P0``."""

    model: VsModel
    truth: np.ndarray
    P0: np.ndarray
    scenario: str = ""

    @property
    def times(self) -> np.ndarray:
        return np.arange(self.truth.shape[0]) * self.model.period

    def simulate(self, runs: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """``(Z, x0)``: measurements (runs, T, 2N) and prior means (runs, 4) drawn with ``rng``."""
        runs = integer("runs", runs, minimum=1)
        rng = rng_or_error("rng", rng)
        Z = self.model.simulate(self.truth[:, :2], rng, size=runs)
        x0 = initial_states(self.truth[0], self.P0, rng, size=runs)
        return Z, x0


def experiment(
    scenario: str = "jiang2023-straight",
    *,
    level: int | tuple[float, float] = 0,
    los: bool = False,
    q: float | None = None,
    p0_sigma=None,
) -> VsExperiment:
    """Model, ground truth and prior of a scenario (its ``[tracking]`` section supplies ``q`` and
    ``p0_sigma`` unless given)."""
    from ..scenarios import load_scenario

    sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
    model = model_from_scenario(sc, level=level, los=los, q=q)
    traj = sc.trajectory()
    truth = np.concatenate([traj.position, traj.velocity], axis=-1)
    ps = (
        sc.get("tracking.p0_sigma", shape=(2,))
        if p0_sigma is None
        else finite_array("p0_sigma", p0_sigma, shape=(2,))
    )
    if np.any(ps <= 0):
        raise ValueError(f"p0_sigma: must be > 0, got {ps}")
    P0 = np.diag([ps[0] ** 2, ps[0] ** 2, ps[1] ** 2, ps[1] ** 2])
    return VsExperiment(model, truth, P0, sc.name)


def monte_carlo(
    exp: VsExperiment,
    runs: int,
    seed: int | np.random.Generator = 0,
    *,
    names=None,
    options: dict | None = None,
    progress: bool = False,
) -> dict[str, np.ndarray]:
    """Estimates (runs, T, 4) of each registry member on the same simulated runs.

    ``options`` maps an algorithm name to keyword options (e.g. ``{"UPF": {"n_particles": 200}}``).
    Every estimator gets its own child generator of ``seed`` by its position in ``names``, so a
    call with the same ``names`` gives the same numbers. ``progress``: a tqdm bar over the
    estimators (it draws no random numbers).
    """
    from tqdm.auto import tqdm

    from ..montecarlo import spawn_rngs
    from .registry import family

    fam = family(FAMILY)
    names = list(fam) if names is None else list(names)
    rng_data, *rng_alg = spawn_rngs(seed, 1 + len(names))
    Z, x0 = exp.simulate(runs, rng_data)
    opts = options or {}
    out = {}
    with tqdm(names, desc=f"{runs} runs", leave=False, disable=not progress) as bar:
        for n, r in zip(bar, rng_alg):
            bar.set_postfix_str(n)
            out[n] = run_estimator(n, exp.model, Z, x0, exp.P0, rng=r, **opts.get(n, {}))
    return out
