"""Doppler and ToA Kalman tracking from one roadside unit (Halili et al. 2022, sections 4-5).

Three interchangeable trackers, registered in family ``"halili2022"``:

* ``"EKF DS"`` - :class:`DopplerEKF`: constant-velocity state ``[x, y, v_x, v_y]`` (eq. 1-3,
  spectral density ``q``), Doppler measurement eq. 4-5 with the sign pinned (approach positive),
  the EKF recursion eq. 6-12 (filterpy's ``ExtendedKalmanFilter``), optionally the adaptive
  measurement covariance of eq. 13-15.
* ``"KF DS and ToA"`` - a KF on Doppler for the speed (:class:`SpeedKF`, ``H = f_c / c``) feeds a
  KF on ToA for the distance (:class:`RangeKF`, eq. 17-21, ``H = 1 / c``) as control input; the
  position follows eq. 16 with the heading from past estimates (:class:`HeadingDeadReckoning`).
* ``"EKF DS and KF ToA"`` - as before, with the speed taken from the EKF DS.

Every tracker has ``step(doppler, toa) -> position`` and ``run(measurements) -> Track``; a NaN or
``None`` measurement is a dropped epoch (predict only, with a :class:`MeasurementWarning`).

Not in the paper, on by default: every Kalman filter here gates its measurement
(:mod:`tunnelkit.tracking.reopening`, chi-square with one degree of freedom at ``gate = 0.999``): a
Doppler locked on a moving scatterer or a ToA off by a gross NLOS excess is a missed epoch,
counted in ``n_rejected``. ``gate=None`` gives the paper's filters. The KF on ToA calibrates the
clock offset on a robust statistic of its first ToAs (not on one sample), and eq. 16 keeps the
sign of the range change (a correction that is later undone cancels instead of adding up).

Corrections to the paper, each shown in notebook 06:

* eq. 5 ``h = v . (s - T) f / (c |s - T|)`` is positive when *receding*; the text (and Fig. 2)
  has the approaching vehicle at positive Doppler. We use ``h = -(f_c/c) v . (p - T) / r``.
* eq. 17 ``d_k = d_{k-1} + B u`` "when approaching" would make the distance grow while the
  vehicle closes in. With ``u`` the approach speed (positive when approaching, Doppler-signed)
  the distance model is ``d_k = d_{k-1} - dt u``.
* eq. 14-15 add ``H P_check H^T`` (the *prior* covariance) to the post-fit residual power; the
  residual ``e_k = y_k - h(s_hat_k)`` has covariance ``R - H P_hat H^T`` (posterior), so the
  consistent estimate uses the posterior ``P_hat`` (Akhlaghi et al. 2017). ``adaptive_form``
  selects ``"posterior"`` (default) or ``"paper"``.

The package holds three parts: :mod:`.filters` (setup, measurement model, the Kalman filters),
:mod:`.approaches` (the three registered approaches and their runs on drives) and :mod:`.bounds`
(what one transmitter can observe: Fisher information and posterior CRLB).
"""

from .approaches import (
    APPROACHES,
    DEAD_RECKONING,
    SIGMAS,
    EkfDS,
    EkfDSKfToA,
    KfDSToA,
    Track,
    dead_reckoning,
    error_study,
    mean_errors,
    run_approaches,
)
from .bounds import posterior_crlb, snapshot_fim
from .filters import (
    DopplerEKF,
    DopplerSetup,
    HeadingDeadReckoning,
    MeasurementWarning,
    RangeKF,
    SpeedKF,
    cv_model,
    doppler_jacobian,
    doppler_model,
    scalar_measurement,
)

__all__ = [
    "APPROACHES",
    "DEAD_RECKONING",
    "SIGMAS",
    "DopplerEKF",
    "DopplerSetup",
    "EkfDS",
    "EkfDSKfToA",
    "HeadingDeadReckoning",
    "KfDSToA",
    "MeasurementWarning",
    "RangeKF",
    "SpeedKF",
    "Track",
    "cv_model",
    "dead_reckoning",
    "doppler_jacobian",
    "doppler_model",
    "error_study",
    "mean_errors",
    "posterior_crlb",
    "run_approaches",
    "scalar_measurement",
    "snapshot_fim",
]
