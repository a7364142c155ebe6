"""The estimators of family ``"jiang2023"`` (Jiang et al. 2023, section 4.2) and their drivers.

:class:`EstimatorBase` is the call protocol every member follows (construct with
``(model, x0, P0, rng=...)``, ``predict``/``update``/``step`` per epoch, ``run`` over a batch of
runs); :class:`VsTSWLS`, :class:`VsEKF` and :class:`VsUKF` are registered here, the UPF in
:mod:`tunnelkit.tracking.upf`. :func:`track` runs one estimator over one run,
:func:`run_estimator` a registry member over many.
"""

from __future__ import annotations

import warnings

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter, MerweScaledSigmaPoints, UnscentedKalmanFilter

from ... import positioning
from ..._validate import finite_array, nonnegative, positive, real, rng_or_error
from ..cv import STATE_DIM
from ..registry import get, register
from ..reopening import DEFAULT_GATE, DEFAULT_REOPEN_AFTER, InnovationGate, gated_filterpy_update
from .model import FAMILY, VsModel, check_model, check_prior, measurement_ok, regularized_cholesky


def _measurements(Z, dim_z: int, runs: bool = True) -> np.ndarray:
    """Measurement runs ``Z`` (R, T, dim_z) (or one run (T, dim_z)): real numbers, NaN rows for
    missed epochs (so not a finite check), the shape named."""
    if isinstance(Z, str | bytes) or np.asarray(Z).dtype.kind not in "iuf":
        raise TypeError(f"Z: expected real measurements, got {type(Z).__name__}")
    Z = np.asarray(Z, dtype=float)
    want = (None, None, dim_z) if runs else (None, dim_z)
    if Z.ndim != len(want) or Z.shape[-1] != dim_z:
        shape = "(runs, epochs, " if runs else "(epochs, "
        raise ValueError(f"Z: expected shape {shape}{dim_z}), got {Z.shape}")
    return Z


def _rng(rng) -> None:
    """Every estimator takes ``rng`` (a Generator or None), used or not."""
    if rng is not None:
        rng_or_error("rng", rng)


__all__ = ["EstimatorBase", "VsEKF", "VsTSWLS", "VsUKF", "run_estimator", "track"]


def _upper_sqrt(P):
    """filterpy's ``sqrt_method`` convention: upper-triangular ``U`` with ``U^T U = P``."""
    return regularized_cholesky(P, name="UKF sigma-point covariance").T


# --- estimators -----------------------------------------------------------------------------------


class EstimatorBase:
    """Common surface: ``x`` (4,), ``P`` (4, 4), ``position``, ``predict()``, ``update(z)``.

    The call protocol of family ``"jiang2023"`` (:mod:`tunnelkit.tracking.registry`).
    """

    name = "base"
    model: VsModel

    @property
    def position(self) -> np.ndarray:
        return np.asarray(self.x, dtype=float)[:2].copy()

    def step(self, z, *, first: bool = False) -> np.ndarray:
        """``predict()`` (unless ``first``) then ``update(z)``; returns the state estimate."""
        if not isinstance(first, bool):
            raise TypeError(f"first: expected True or False, got {first!r}")
        if z is not None:  # checked before the state moves (update warns of a NaN epoch)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                self._check_z(z)
        if not first:
            self.predict()
        self.update(z)
        return np.asarray(self.x, dtype=float).copy()

    def _check_z(self, z) -> None:
        """Refuse a measurement ``update`` would refuse (before ``step`` predicts)."""
        measurement_ok(z, self.model.dim_z, who=self.name)

    @classmethod
    def run(
        cls, model: VsModel, Z, x0, P0, *, rng: np.random.Generator | None = None, **options
    ) -> np.ndarray:
        """Estimates (R, T, 4) for measurement runs ``Z`` (R, T, 2N) and priors ``x0`` (R, 4).

        The default loops over runs; vectorised estimators override it. A row of NaN in ``Z``
        is a missed epoch.
        """
        Z = _measurements(Z, check_model(model).dim_z)
        x0 = finite_array("x0", x0, shape=(Z.shape[0], STATE_DIM))
        if len(x0):
            check_prior(x0[0], P0)
        _rng(rng)
        out = np.empty((*Z.shape[:2], STATE_DIM))
        for r in range(Z.shape[0]):
            est = cls(model, x0[r], P0, rng=rng, **options)
            out[r] = track(est, Z[r])
        return out


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
        self.model = check_model(model)
        self.x, self.P = check_prior(x0, P0)
        _rng(rng)
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
        model = check_model(model)
        Z = _measurements(Z, model.dim_z)
        x0 = finite_array("x0", x0)
        if x0.ndim != 2 or x0.shape[-1] != STATE_DIM:
            raise ValueError(
                f"x0: expected one prior state per run (runs, {STATE_DIM}), got {x0.shape}"
            )
        check_prior(x0[0], P0)
        _rng(rng)
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
    bearing residuals; ``gate``/``reopen_after`` as in :mod:`tunnelkit.tracking.reopening`."""

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
        self.model = check_model(model)
        self.gate = InnovationGate(gate, reopen_after=reopen_after)
        x0, P0 = check_prior(x0, P0)
        _rng(rng)
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
            f.update(None, m.jacobian, m._h)
            return
        # filterpy updates P in Joseph form; symmetrise to remove rounding asymmetry
        gated_filterpy_update(
            f, lambda: f.update(z, m.jacobian, m._h, residual=m._residual), self.gate
        )
        self._symmetrize()


@register(FAMILY, "UKF")
class VsUKF(_FilterpyEstimator):
    """filterpy ``UnscentedKalmanFilter`` with ``MerweScaledSigmaPoints`` (eq. 46-58).

    ``alpha, beta, kappa`` are the scaling parameters of eq. 47-50. The square root of the
    sigma-point covariance is a regularised Cholesky factor (warns instead of failing). Bearings
    use the wrapped residual and reference-based mean of :class:`VsModel`. ``gate`` and
    ``reopen_after`` as in :mod:`tunnelkit.tracking.reopening` (a reopened measurement redraws the
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
        self.model = check_model(model)
        self.gate = InnovationGate(gate, reopen_after=reopen_after)
        x0, P0 = check_prior(x0, P0)
        _rng(rng)
        kappa = real("kappa", kappa)
        if STATE_DIM + kappa <= 0:  # eq. 47: lambda + n = alpha^2 (n + kappa) must be > 0
            raise ValueError(f"kappa: must be > -{STATE_DIM} (n + kappa > 0), got {kappa:g}")
        pts = MerweScaledSigmaPoints(
            STATE_DIM,
            alpha=positive("alpha", alpha),
            beta=nonnegative("beta", beta),
            kappa=kappa,
            sqrt_method=_upper_sqrt,
        )
        f = UnscentedKalmanFilter(
            dim_x=STATE_DIM,
            dim_z=model.dim_z,
            dt=model.period,
            hx=model._h,  # the unchecked twins: filterpy calls them once per sigma point
            fx=lambda x, dt: model.F @ x,
            points=pts,
            z_mean_fn=model.z_mean,
            residual_z=model._residual,
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
    if not callable(getattr(estimator, "step", None)):
        raise TypeError(
            f"estimator: expected a filter with a step() method, got {type(estimator).__name__}"
        )
    model = getattr(estimator, "model", None)
    if isinstance(model, VsModel) and (
        isinstance(Z, np.ndarray) or not isinstance(Z, list | tuple)
    ):
        Z = _measurements(Z, model.dim_z, runs=False)
    out = np.empty((len(Z), STATE_DIM))
    for k, z in enumerate(Z):
        z = None if z is None or not np.all(np.isfinite(np.asarray(z, dtype=float))) else z
        out[k] = estimator.step(z, first=(k == 0))
    return out


def run_estimator(
    name: str, model: VsModel, Z, x0, P0, *, rng: np.random.Generator | None = None, **options
) -> np.ndarray:
    """Estimates (R, T, 4) of registry member ``name`` over measurement runs ``Z`` (R, T, 2N)."""
    cls = get(FAMILY, name)
    model = check_model(model)
    Z = _measurements(Z, model.dim_z)
    x0 = finite_array("x0", x0, shape=(Z.shape[0], STATE_DIM))
    check_prior(x0[0], P0)
    if rng is not None:
        rng_or_error("rng", rng)
    return cls.run(model, Z, x0, P0, rng=rng, **options)
