"""Bounds over a design's drive: what the position information of each epoch gives a tracker.

:func:`position_information` maps a :class:`~tunnelkit.design.errormodel.PathErrorModel`'s
reported per-path bound into the UE's horizontal position (the clock bias ``c b`` eliminated, as
the PEB does); :func:`drive_pcrlb` runs the posterior CRLB of JAVELIN's motion model over the
drive with it (Tichavsky et al. 1998); :func:`position_bias_rms` is the position bias of the
array's one calibration draw and of the wideband term, which no number of epochs averages down,
and :func:`drive_bound` sets the two together: a first-order **prediction** of the tracker's
error, not a bound (the tracker beats it). The **bounds** over the drive are
:func:`unit_pcrlb`'s: every unit's posterior CRLB, and the one pooled over units with the
calibration draw a fixed unknown of the drive (a hybrid bound). The Monte-Carlo of
:mod:`tunnelkit.design.montecarlo` is set beside both.
"""

from __future__ import annotations

import numpy as np

from .._checks import bound_array
from .._physical import start_spread
from .._validate import boolean, finite_array, instance, integer, positive
from ..odometry import Odometry
from ..reckoning import posterior_bound
from ..tracking.pcrlb import pcrlb, pcrlb_position_rmse
from .errormodel import PathErrorModel
from .setup import DesignSetup
from .trackerfix import (
    START_SIGMA_M,
    check_geometry,
    position_error_parts,
    position_noise_cov,
    position_rows,
)

__all__ = [
    "drive_bound",
    "drive_motion",
    "drive_pcrlb",
    "position_bias_rms",
    "position_information",
    "unit_pcrlb",
]


def position_information(
    model: PathErrorModel, geometry, weights=None, *, drawn: bool = False
) -> np.ndarray:
    """Fisher information (T, 2, 2) [1/m^2] of the UE's horizontal position (height known, as
    JAVELIN and the PEB) in what the extraction reports: ``H^T crlb^-1 H`` over the existing
    paths' ``z = [phi, psi, kappa, d]``, with the clock bias (common to every ``d``) a nuisance
    removed by the Schur complement. ``H`` maps the UE position through each path's wave origin
    (the UE, or its mirror image in the known surface: ``geometry.mirror``).

    ``weights`` (T, P, 4, 4): the per-path covariances a tracker is told
    (:func:`tunnelkit.design.trackerfix.tracker_weights`); the information is then the inverse
    of the covariance of the fix that weighs the paths by them (:func:`position_noise_cov`):
    a tracker told one block per path cannot use the correlation of the joint CRLB between
    paths (at 4 x 4 in the paper's tunnel up to 0.9 between the LoS and the ceiling path,
    which the joint bound turns into half the position error).

    ``drawn``: the information of what the model draws, its ``cov`` (diffuse power included)
    instead of the reported ``crlb`` (the noise of :func:`unit_pcrlb`; no ``weights``)."""
    check_geometry(model, geometry)
    if boolean("drawn", drawn) and weights is not None:
        raise ValueError("weights: the information of the drawn noise takes no weights")
    T = model.exists.shape[0]
    out = np.zeros((T, 2, 2))
    if weights is not None:
        cov = position_noise_cov(model, geometry, weights)
        for k in range(T):
            if np.any(cov[k]):
                out[k] = np.linalg.pinv(cov[k], rcond=1e-15, hermitian=True)
                out[k] = 0.5 * (out[k] + out[k].T)
        return out
    for k in range(T):
        rows, H, _ = position_rows(model, geometry, k)
        if rows is None:
            continue
        R = np.asarray(model.cov[k] if drawn else model.crlb[k])[np.ix_(rows, rows)]
        J = H.T @ np.linalg.pinv(0.5 * (R + R.T), rcond=1e-15, hermitian=True) @ H
        J = 0.5 * (J + J.T)
        if J[2, 2] > 0:
            J = J[:2, :2] - np.outer(J[:2, 2], J[2, :2]) / J[2, 2]
        else:
            J = J[:2, :2]
        out[k] = 0.5 * (J + J.T)
    return out


def position_bias_rms(model: PathErrorModel, geometry, weights=None) -> np.ndarray:
    """RMS (T,) [m] of the horizontal position bias of the weighted least-squares snapshot fix
    of :func:`position_error_parts` (``weights`` as there) under the model's deterministic
    ``bias`` and calibration error, over the calibration draw: ``sqrt(|G b|^2 + sigma_phi^2
    ||G K_phase||_F^2 + sigma_g^2 ||G K_gain||_F^2)``. A bias that does not average down over
    the drive: one array's calibration error is drawn once, the wideband bias is deterministic
    (:func:`drive_bound`). Zero for an ideal model."""
    parts = position_error_parts(model, geometry, weights)
    return np.hypot(parts[:, 0], parts[:, 1])


def drive_bound(pcrlb: np.ndarray, bias_rms: np.ndarray) -> np.ndarray:
    """The predicted error over the drive (T,) [m] (a prediction, not a bound): the posterior CRLB of the noise
    (:func:`drive_pcrlb`, which averages down along the drive) and the position bias that does
    not average down (:func:`position_bias_rms`, the array's one calibration draw and the
    deterministic wideband bias) added in quadrature, ``sqrt(pcrlb^2 + bias_rms^2)``. The bias
    part is that of a snapshot fix weighted as the tracker weighs its paths (the design's
    sweep passes :func:`tunnelkit.design.trackerfix.tracker_weights`), not minimised over the
    drive: the error of the tracker that is run, not a strict lower bound."""
    p = bound_array("pcrlb", pcrlb)
    b = bound_array("bias_rms", bias_rms)
    if p.shape != b.shape:
        raise ValueError(f"bias_rms: expected shape {p.shape} like pcrlb, got {b.shape}")
    return np.sqrt(p**2 + b**2)


def drive_pcrlb(
    setup: DesignSetup,
    info: np.ndarray,
    *,
    sigma_p0: float = START_SIGMA_M,
    sigma_speed: float | None = None,
    sigma_heading: float | None = None,
    odometry: Odometry | None = None,
) -> np.ndarray:
    """Posterior CRLB (T,) [m] of the 2-D position along ``setup``'s drive
    (:func:`tunnelkit.tracking.pcrlb.pcrlb`, Tichavsky et al. 1998): JAVELIN's motion model
    (``x_k = x_{k-1} + dt nu (cos theta, sin theta)`` driven by the V2X speed and heading with
    noise ``sigma_speed`` / ``sigma_heading``, default the white noise of the drive's messages,
    ``setup.trajectory.odometry``: 0.2 m/s, 1 deg unless the scenario says otherwise), the
    start from an open-sky fix of ``sigma_p0`` [m] (as the studies start JAVELIN), and ``info``
    (T, 2, 2) the position information per epoch (:func:`position_information`).

    ``odometry`` (:class:`tunnelkit.odometry.Odometry`, instead of the two sigmas): the messages'
    model with its repeating errors, the scale factor and the heading biases as states of the
    bound beside the position (:func:`tunnelkit.reckoning.posterior_bound`, its message schedule
    without losses); the paper's white model gives the bound of the two sigmas. Without
    ``odometry`` and the sigmas, a drive whose messages have repeating errors (the scenario's
    ``[odometry]``) is bounded with them as states."""
    own = instance("setup", setup, DesignSetup).trajectory.odometry
    perfect = own.speed_noise == 0.0 or own.heading_noise == 0.0  # no white noise of one kind
    if odometry is None and sigma_speed is None and sigma_heading is None:
        if not own.is_white or perfect:
            odometry = own
    if odometry is not None:
        instance("odometry", odometry, Odometry)
        if sigma_speed is not None or sigma_heading is not None:
            raise ValueError("sigma_speed, sigma_heading: give an odometry model or the sigmas")
        info = finite_array("info", info, shape=(None, 2, 2))
        t, nu, th = _drive_truth(setup, info.shape[0])
        sigma_p0 = start_spread("sigma_p0", sigma_p0)
        return posterior_bound(t, nu, th, odometry, info, sigma_start=sigma_p0)
    sig_nu = positive("sigma_speed", own.speed_noise if sigma_speed is None else sigma_speed)
    sig_th = positive(
        "sigma_heading", own.heading_noise if sigma_heading is None else sigma_heading
    )
    sigma_p0 = start_spread("sigma_p0", sigma_p0)
    info = finite_array("info", info, shape=(None, 2, 2))
    Q = _motion_noise(setup, info.shape[0], sig_nu, sig_th)
    B = pcrlb(np.eye(2), Q, sigma_p0**2 * np.eye(2), info)
    return pcrlb_position_rmse(B)


def _drive_truth(setup: DesignSetup, T: int):
    """Times (T,) [s], true speed [m/s] and heading [rad] (T,) of ``setup``'s first ``T``
    epochs."""
    traj = instance("setup", setup, DesignSetup).trajectory
    T = integer("T", T, minimum=1, maximum=len(traj.t))
    vel = traj.velocity[:T]
    return traj.t[:T], np.linalg.norm(vel[:, :2], axis=1), np.arctan2(vel[:, 1], vel[:, 0])


def _motion_noise(setup: DesignSetup, T: int, sig_nu: float, sig_th: float) -> np.ndarray:
    """The position's process noise (T, 2, 2) of JAVELIN's motion model (:func:`drive_motion`);
    a standing vehicle has none, kept a valid recursion by 1e-12 m^2."""
    G, Qn, _ = drive_motion(setup, T, sig_nu, sig_th)
    return G @ Qn @ np.swapaxes(G, 1, 2) + 1e-12 * np.eye(2)


def drive_motion(setup: DesignSetup, T: int, sig_nu: float, sig_th: float):
    """JAVELIN's motion model along ``setup``'s drive for its first ``T`` epochs: per epoch the
    Jacobian ``G`` (T, 2, 2) of the 2-D position increment ``dt nu (cos theta, sin theta)`` with
    respect to (speed, heading), the noise covariance of (speed, heading) from ``sig_nu`` [m/s]
    and ``sig_th`` [rad], and ``dt`` (T,) [s]. The message of epoch ``k-1`` drives the
    prediction into epoch ``k`` (Algorithm 4, line 7; eq. 62's held step, the step the array
    design's tracker takes, not the midpoint of :func:`~tunnelkit.tracking.javelin.designs.ours`)."""
    setup = instance("setup", setup, DesignSetup)
    traj = setup.trajectory
    T = integer("T", T, minimum=1, maximum=len(traj.t))
    sig_nu = positive("sig_nu", sig_nu)
    sig_th = positive("sig_th", sig_th)
    vel = traj.velocity[:T]
    nu = np.linalg.norm(vel[:, :2], axis=1)
    th = np.arctan2(vel[:, 1], vel[:, 0])
    dt = np.diff(traj.t[:T], prepend=traj.t[0])
    dt[0] = dt[1] if T > 1 else 0.1
    nu_p, th_p = np.roll(nu, 1), np.roll(th, 1)
    G = dt[:, None, None] * np.stack(
        [
            np.stack([np.cos(th_p), -nu_p * np.sin(th_p)], axis=-1),
            np.stack([np.sin(th_p), nu_p * np.cos(th_p)], axis=-1),
        ],
        axis=1,
    )
    return G, np.diag([sig_nu**2, sig_th**2]), dt


def unit_pcrlb(
    setup: DesignSetup,
    model: PathErrorModel,
    geometry,
    *,
    sigma_p0: float = START_SIGMA_M,
    calibration: bool = True,
) -> np.ndarray:
    """Posterior CRLB (T,) [m] of the 2-D position along the drive for the measurements the
    model draws, ``z_k = h(x_k) + b_k + K_k e + n_k`` with ``n_k ~ N(0, cov_k)`` and ``e`` the
    array's calibration error (phase [rad] and gain [dB] per element):

    * ``calibration=True``: ``e`` a **fixed unknown of the drive** with its prior ``N(0,
      diag(sigma_phase^2 I, sigma_gain^2 I))`` (one draw per manufactured unit), carried as a
      static state beside the position (a hybrid / consider bound, Van Trees over the drive and
      the unit): a lower bound of the MSE **pooled over units** of any tracker (nearly) unbiased
      for the route (the route is fixed: an oracle that knew it could go below);
    * ``calibration=False``: ``e`` known to the bound (conditioned on the unit's draw, whose
      bias ``K e`` then carries no information and only shifts the mean): the bound of **every
      unit**, the same for every draw (the model is linear in ``e``).

    The noise is the model's ``cov`` (what is drawn, diffuse power included), not the reported
    ``crlb``; the clock bias is eliminated per epoch with a flat prior (as the PEB), the
    motion is JAVELIN's driven by the V2X messages' white noise (:func:`drive_pcrlb`, which this
    equals for ``calibration=False`` on white messages; the repeating errors of a scenario's
    ``[odometry]`` are no states here, which leaves it lower than the bound with them, still a
    bound), the start an open-sky fix of ``sigma_p0`` [m]. Computed in
    covariance form, each epoch a low-rank update (Woodbury), so the cost grows as ``M^2`` per
    epoch, not ``M^3``."""
    odo = instance("setup", setup, DesignSetup).trajectory.odometry
    check_geometry(model, geometry)
    sigma_p0 = start_spread("sigma_p0", sigma_p0)
    calibration = boolean("calibration", calibration)
    T, P = model.exists.shape
    ks = []
    if calibration:
        ks = [
            (np.asarray(K).reshape(T, 4 * P, -1), sig)
            for K, sig in (
                (model.k_phase, model.phase_sigma_rad),
                (model.k_gain, model.gain_sigma_db),
            )
            if K is not None and sig > 0
        ]
    m = sum(K.shape[-1] for K, _ in ks)
    # the messages' white noise: their repeating terms, no states here, would only raise it
    Q = _motion_noise(setup, T, odo.speed_noise, odo.heading_noise)
    Pm = np.zeros((2 + m, 2 + m))
    Pm[:2, :2] = sigma_p0**2 * np.eye(2)
    if m:
        Pm[2:, 2:] = np.diag(np.concatenate([np.full(K.shape[-1], s**2) for K, s in ks]))
    out = np.empty(T)
    for k in range(T):
        if k:
            Pm[:2, :2] += Q[k]
        rows, H, _ = position_rows(model, geometry, k)
        if rows is not None:
            R = np.asarray(model.cov[k])[np.ix_(rows, rows)]
            A = np.concatenate([H[:, :2], *(K[k, rows] for K, _ in ks)], axis=1)
            # whiten, then remove the clock bias' direction (flat prior): unit-noise rows
            w, V = np.linalg.eigh(0.5 * (R + R.T))
            on = w > w.max() * 1e-15
            L = (V[:, on] / np.sqrt(w[on])).T
            Lh = L @ H[:, 2]
            if Lh @ Lh > 0:
                u = Lh / np.linalg.norm(Lh)
                L = L - np.outer(u, u @ L)
            B = L @ A
            S = np.eye(B.shape[0]) + B @ Pm @ B.T
            PB = Pm @ B.T
            Pm = Pm - PB @ np.linalg.solve(S, PB.T)
            Pm = 0.5 * (Pm + Pm.T)
        out[k] = np.sqrt(max(Pm[0, 0] + Pm[1, 1], 0.0))
    return out
