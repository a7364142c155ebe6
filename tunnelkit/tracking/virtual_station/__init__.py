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
:mod:`tunnelkit.tracking.reopening`); a rejected vector (a gross range or bearing outlier) is a
missed epoch, counted in ``n_rejected``; ``gate=None`` gives the paper's filters.

The package holds three parts: :mod:`.model` (the measurement model, priors and input checks),
:mod:`.filters` (the registered estimators, :func:`track`, :func:`run_estimator`) and
:mod:`.experiment` (scenario experiments and Monte-Carlo runs).
"""

from .experiment import VsExperiment, experiment, monte_carlo
from .filters import EstimatorBase, VsEKF, VsTSWLS, VsUKF, run_estimator, track
from .model import (
    FAMILY,
    VsModel,
    check_model,
    check_prior,
    initial_states,
    measurement_ok,
    model_from_scenario,
    regularized_cholesky,
)

__all__ = [
    "FAMILY",
    "EstimatorBase",
    "VsEKF",
    "VsExperiment",
    "VsModel",
    "VsTSWLS",
    "VsUKF",
    "check_model",
    "check_prior",
    "experiment",
    "initial_states",
    "measurement_ok",
    "model_from_scenario",
    "monte_carlo",
    "regularized_cholesky",
    "run_estimator",
    "track",
]
