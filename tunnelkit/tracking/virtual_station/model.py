"""The virtual-station measurement model (Jiang et al. 2023, eq. 40-45), its priors and the
numerics the estimators share.

:class:`VsModel` holds the stations, noise levels and constant-velocity model;
:func:`model_from_scenario` builds it from a scenario; :func:`initial_states` draws prior means;
:func:`measurement_ok`, :func:`check_model` and :func:`check_prior` are the input checks of every
estimator of family ``"jiang2023"``; :func:`regularized_cholesky` is the covariance square root of
the UKF and the UPF.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ... import positioning
from ..._checks import real_array
from ..._validate import boolean, finite_array, integer, positive, probability, rng_or_error, text
from ...budget import check_elements
from ...crlb import fim_toa_doa, toa_doa, toa_doa_jacobian, wrap_angle
from ...scenarios import load_scenario
from ..cv import STATE_DIM, cv_process_noise, cv_transition

__all__ = [
    "FAMILY",
    "VsModel",
    "check_model",
    "check_prior",
    "initial_states",
    "measurement_ok",
    "model_from_scenario",
    "regularized_cholesky",
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
    name = text("name", name)
    probability("rel_floor", rel_floor)
    real_array(name, P)
    P = np.asarray(P, dtype=float)
    if not np.all(np.isfinite(P)):
        raise ValueError(f"{name}: covariance contains NaN or infinite values")
    if P.ndim < 2 or P.shape[-1] != P.shape[-2]:
        raise ValueError(f"{name}: expected square matrices (..., n, n), got shape {P.shape}")
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
        set_(self, "los", boolean("los", self.los))
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
        x = np.asarray(x)
        if x.dtype.kind not in "iuf" or x.ndim == 0 or x.shape[-1] != STATE_DIM:
            raise ValueError(
                f"x: expected real state(s) (..., {STATE_DIM}), got {x.dtype} of shape {x.shape}"
            )
        if not np.isfinite(x).all():
            raise ValueError("x: contains NaN or infinite values")
        d, th = toa_doa(x[..., :2], self.stations)
        return np.concatenate([d, th], axis=-1)

    # the filters' own states and predictions (finite by construction, never at a station):
    # the arithmetic of hx / residual_z without their input checks, which cost more than the
    # arithmetic on one sigma point (filterpy's UKF calls them once per sigma point)
    def _h(self, x) -> np.ndarray:
        """:meth:`hx` unchecked (bit for bit the same result)."""
        p = np.asarray(x, dtype=float)[..., :2]
        st = self.stations
        dx = p[..., None, 0] - st[:, 0]
        dy = p[..., None, 1] - st[:, 1]
        return np.concatenate([np.hypot(dx, dy), np.arctan2(dy, dx)], axis=-1)

    def _residual(self, a, b) -> np.ndarray:
        """:meth:`residual_z` unchecked (bit for bit the same result)."""
        r = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
        n = self.stations.shape[0]
        if r.size < 64:  # one sigma point: the formula of wrap_angle inline
            r[..., n:] = np.pi - np.mod(np.pi - r[..., n:], 2.0 * np.pi)
        else:  # a particle cloud: the check is cheap beside wrap_angle's fast path
            r[..., n:] = wrap_angle(r[..., n:])
        return r

    def jacobian(self, x) -> np.ndarray:
        """``d f_2 / d X`` (..., 2N, 4): the position block of eq. A2-A9 (sign-corrected), zeros
        for the velocities."""
        x = np.asarray(x, dtype=float)
        if x.ndim == 0 or x.shape[-1] != STATE_DIM or not np.isfinite(x).all():
            raise ValueError(f"x: expected finite state(s) (..., {STATE_DIM}), got {x.shape}")
        J = toa_doa_jacobian(x[..., :2], self.stations)
        return np.concatenate([J, np.zeros_like(J)], axis=-1)

    def residual_z(self, a, b) -> np.ndarray:
        """``a - b`` with the bearing components wrapped to ``(-pi, pi]``."""
        r = real_array("a", a) - real_array("b", b)
        n = self.n_stations
        r[..., n:] = wrap_angle(r[..., n:])
        return r

    def z_mean(self, sigmas, Wm) -> np.ndarray:
        """Weighted mean of measurement sigma points (..., S, 2N) with weights ``Wm`` (S,).

        Bearings are averaged as wrapped offsets from the first sigma point, so the mean of
        bearings straddling +-pi is right; the result's bearings are wrapped.
        """
        sig = finite_array("sigmas", sigmas)
        if sig.ndim < 2:
            raise ValueError(f"sigmas: expected sigma points (..., S, 2N), got shape {sig.shape}")
        finite_array("Wm", Wm, shape=(sig.shape[-2],))
        ref = sig[..., :1, :]
        m = ref[..., 0, :] + np.einsum(
            "s,...sj->...j", np.asarray(Wm, float), self.residual_z(sig, ref)
        )
        n = self.n_stations
        m[..., n:] = wrap_angle(m[..., n:])
        return m

    def log_likelihood(self, z, x) -> np.ndarray:
        """``log p(Z | X)`` up to a constant, for state(s) ``x`` (..., 4) and ``z`` broadcasting."""
        real_array("z", z)
        r = self.residual_z(z, self.hx(x))
        return -0.5 * np.sum(r * r / np.diag(self.R), axis=-1)

    def simulate(self, positions, rng: np.random.Generator, size: int | None = None) -> np.ndarray:
        """Noisy measurements ``Z`` (eq. 44) at true positions (T, 2): shape (T, 2N) or (size, T, 2N)."""
        positions = finite_array("positions", positions)
        if positions.ndim == 0 or positions.shape[-1] != 2:
            raise ValueError(f"positions: expected positions (..., T, 2), got {positions.shape}")
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
    check_elements("size", int(np.prod(shape)), what="the prior means")
    return x0 + rng.standard_normal(shape) @ L.T


def measurement_ok(z, dim_z: int, *, who: str = "update") -> np.ndarray | None:
    """``z`` as a float vector, or ``None`` (with a warning) if it is missing or holds NaN/inf.

    ``None`` means "missed epoch": the caller predicts only.
    """
    dim_z = integer("dim_z", dim_z, minimum=1)
    who = text("who", who)
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


# --- input checks of every estimator --------------------------------------------------------------


def check_prior(x0, P0) -> tuple[np.ndarray, np.ndarray]:
    """Copies of the prior mean ``x0`` (4,) and covariance ``P0`` (4, 4), checked: finite, ``P0``
    symmetric and positive definite."""
    x0 = finite_array("x0", x0, shape=(STATE_DIM,))
    P0 = finite_array("P0", P0, shape=(STATE_DIM, STATE_DIM))
    if not np.allclose(P0, P0.T, atol=1e-12 * max(1.0, np.abs(P0).max())):
        raise ValueError("P0: must be symmetric")
    if np.any(np.linalg.eigvalsh(P0) <= 0):
        raise ValueError("P0: must be positive definite")
    return x0.copy(), P0.copy()


def check_model(model) -> VsModel:
    """``model`` itself if it is a :class:`VsModel` (``TypeError`` naming ``model`` otherwise)."""
    if not isinstance(model, VsModel):
        raise TypeError(
            f"model: expected a VsModel (see model_from_scenario), got {type(model).__name__}"
        )
    return model
