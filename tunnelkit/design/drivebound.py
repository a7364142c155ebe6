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
from .._validate import finite_array, instance
from .errormodel import PathErrorModel
from .setup import DesignSetup

__all__ = [
    "START_SIGMA_M",
    "drive_bound",
    "drive_motion",
    "drive_pcrlb",
    "fix_identifiable",
    "position_bias_rms",
    "position_error_parts",
    "position_information",
    "position_noise_cov",
    "unit_pcrlb",
]

#: the open-sky fix's standard deviation per axis [m], the design's default entry fix
#: (``start_sigma`` of :func:`tunnelkit.design.montecarlo.sweep_montecarlo`): the tracker's
#: ``sigma_p0_ue`` and the prior of the bounds over the drive (:func:`drive_pcrlb`)
START_SIGMA_M = 1.0


def _position_rows(model: PathErrorModel, geometry, k: int):
    """Epoch ``k``: the rows of the existing paths in ``z`` and ``H`` (4n, 3), the map of the
    UE's horizontal position and ``c b`` into them (``None`` without a path)."""
    from ..geometry import spherical_jacobian

    j = np.flatnonzero(model.exists[k] & geometry.exists[k])
    if not j.size:
        return None, None, j
    rel = geometry.source[k, j] - geometry.origin[k]
    Js = spherical_jacobian(rel) @ geometry.mirror[j]  # (n, 3, 3) d(phi,psi,r)/d UE
    H = np.zeros((j.size, 4, 3))
    H[:, :3, :2] = Js[:, :, :2]
    H[:, 3, :2] = Js[:, 2, :2]
    H[:, 3, 2] = 1.0  # c b in every delay distance
    rows = (4 * j[:, None] + np.arange(4)).ravel()
    return rows, H.reshape(-1, 3), j


def _check_geometry(model, geometry) -> None:
    from .geometry import RouteGeometry

    instance("geometry", geometry, RouteGeometry)
    if not isinstance(model, PathErrorModel):
        raise TypeError(f"model: expected a design.PathErrorModel, got {type(model).__name__}")
    if geometry.exists.shape != model.exists.shape:
        raise ValueError(
            f"geometry: expected {model.exists.shape[0]} epochs and {model.exists.shape[1]} "
            "path slots like the model"
        )


def position_information(model: PathErrorModel, geometry, weights=None) -> np.ndarray:
    """Fisher information (T, 2, 2) [1/m^2] of the UE's horizontal position (height known, as
    JAVELIN and the PEB) in what the extraction reports: ``H^T crlb^-1 H`` over the existing
    paths' ``z = [phi, psi, kappa, d]``, with the clock bias (common to every ``d``) a nuisance
    removed by the Schur complement. ``H`` maps the UE position through each path's wave origin
    (the UE, or its mirror image in the known surface: ``geometry.mirror``).

    ``weights`` (T, P, 4, 4): the per-path covariances a tracker is told
    (:func:`tunnelkit.design.fastroute.tracker_weights`); the information is then the inverse
    of the covariance of the fix that weighs the paths by them (:func:`position_noise_cov`):
    a tracker told one block per path cannot use the correlation of the joint CRLB between
    paths (at 4 x 4 in the paper's tunnel up to 0.9 between the LoS and the ceiling path,
    which the joint bound turns into half the position error)."""
    _check_geometry(model, geometry)
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
        rows, H, _ = _position_rows(model, geometry, k)
        if rows is None:
            continue
        R = model.crlb[k][np.ix_(rows, rows)]
        J = H.T @ np.linalg.pinv(0.5 * (R + R.T), rcond=1e-15, hermitian=True) @ H
        J = 0.5 * (J + J.T)
        if J[2, 2] > 0:
            J = J[:2, :2] - np.outer(J[:2, 2], J[2, :2]) / J[2, 2]
        else:
            J = J[:2, :2]
        out[k] = 0.5 * (J + J.T)
    return out


def _block_weights(blocks: np.ndarray) -> np.ndarray:
    """Block-diagonal weight ``W`` (4n, 4n) from per-path covariances (n, 4, 4); a row whose
    variance is infinite (a quantity the tracker is not handed, e.g. an unresolved curvature)
    gets no weight."""
    n = blocks.shape[0]
    W = np.zeros((4 * n, 4 * n))
    for i in range(n):
        B = blocks[i]
        on = np.isfinite(np.diag(B))
        Bi = 0.5 * (B[np.ix_(on, on)] + B[np.ix_(on, on)].T)
        w = np.zeros((4, 4))
        w[np.ix_(on, on)] = np.linalg.pinv(Bi, rcond=1e-15, hermitian=True)
        W[4 * i : 4 * i + 4, 4 * i : 4 * i + 4] = w
    return W


def _check_weights(model: PathErrorModel, weights) -> np.ndarray:
    """Per-path covariances (T, P, 4, 4): numbers, ``inf`` allowed (a quantity not handed on)."""
    T, P = model.exists.shape
    if isinstance(weights, str | bytes):
        raise TypeError("weights: expected per-path covariances (T, P, 4, 4), got text")
    try:
        weights = np.asarray(weights, float)
    except (TypeError, ValueError):
        raise TypeError(f"weights: expected numbers, got {type(weights).__name__}") from None
    if weights.shape != (T, P, 4, 4):
        raise ValueError(f"weights: expected shape {(T, P, 4, 4)}, got {weights.shape}")
    if np.isnan(weights).any():
        raise ValueError("weights: NaN (an infinite variance marks a quantity not handed on)")
    return weights


def _fix_weights(model, geometry, k: int, weights):
    """Epoch ``k``: the rows, ``H`` (4n, 3) and the weight ``W`` of the weighted least-squares
    fix (the inverse of the ideal CRLB, or block-diagonal from ``weights``); ``(None, None,
    None)`` without a path."""
    rows, H, j = _position_rows(model, geometry, k)
    if rows is None:
        return None, None, None
    if weights is None:
        R = model.crlb[k][np.ix_(rows, rows)]
        return rows, H, np.linalg.pinv(0.5 * (R + R.T), rcond=1e-15, hermitian=True)
    return rows, H, _block_weights(weights[k, j])


def _weighted_gain(model, geometry, k: int, weights):
    """Epoch ``k``: the rows, the position rows ``G`` (2, 4n) of the weighted least-squares
    fix ``(H^T W H)^-1 H^T W`` (clock bias estimated; ``W`` the inverse of the ideal CRLB or
    block-diagonal from ``weights``), or ``(None, None)`` without a path."""
    rows, H, W = _fix_weights(model, geometry, k, weights)
    if rows is None:
        return None, None
    J = H.T @ W @ H
    G = (np.linalg.pinv(0.5 * (J + J.T), rcond=1e-15, hermitian=True) @ H.T @ W)[:2]
    return rows, G


def fix_identifiable(model: PathErrorModel, geometry, weights=None, rcond: float = 1e-12):
    """Per epoch (T,) bool: the weighted least-squares fix of :func:`position_noise_cov`
    (``weights`` as there) determines the horizontal position and the clock bias, i.e.
    ``H^T W H`` is regular (Jacobi-scaled smallest eigenvalue above ``rcond`` times the
    largest). False at an epoch without a path, or where the paths left (e.g. one path whose
    curvature is not handed on) fix a direction but not a range: there the pseudo-inverse the
    fix is computed with would report a finite, meaningless covariance."""
    from .._validate import positive

    _check_geometry(model, geometry)
    rcond = positive("rcond", rcond)
    if weights is not None:
        weights = _check_weights(model, weights)
    T = model.exists.shape[0]
    out = np.zeros(T, bool)
    for k in range(T):
        rows, H, W = _fix_weights(model, geometry, k, weights)
        if rows is None:
            continue
        J = H.T @ W @ H
        d = np.diag(J)
        if np.any(d <= 0) or not np.all(np.isfinite(J)):
            continue
        w = np.linalg.eigvalsh(J / np.sqrt(np.outer(d, d)))
        out[k] = w[0] > rcond * w[-1]
    return out


def position_noise_cov(model: PathErrorModel, geometry, weights) -> np.ndarray:
    """Per epoch (T, 2, 2) [m^2] the covariance of the horizontal position of the weighted
    least-squares snapshot fix (clock bias estimated) under the model's ideal noise, the joint
    CRLB ``crlb`` of every path: ``G crlb G^T`` with ``G`` the position rows of ``(H^T W H)^-1
    H^T W`` and ``W`` block-diagonal over the paths from ``weights`` (T, P, 4, 4), the
    covariances the tracker is told (:func:`tunnelkit.design.fastroute.tracker_weights`; an
    unresolved curvature as an infinite variance gets no weight). ``W = crlb^-1`` would give
    the PEB's covariance; any other weight gives more (Gauss-Markov), and the tracker that is
    run weighs its paths block by block. Zero at an epoch without a path."""
    _check_geometry(model, geometry)
    weights = _check_weights(model, weights)
    T = model.exists.shape[0]
    out = np.zeros((T, 2, 2))
    for k in range(T):
        rows, G = _weighted_gain(model, geometry, k, weights)
        if rows is None:
            continue
        C = G @ model.crlb[k][np.ix_(rows, rows)] @ G.T
        out[k] = 0.5 * (C + C.T)
    return out


def position_error_parts(model: PathErrorModel, geometry, weights=None) -> np.ndarray:
    """Per epoch (T, 3) [m] the horizontal position error a weighted least-squares snapshot fix
    (clock bias estimated) takes from the model's impairments: the RMS over the calibration
    draw of its calibration bias ``sqrt(sigma_phi^2 ||G K_phase||_F^2 + sigma_g^2
    ||G K_gain||_F^2)``, the norm of its deterministic bias ``|G b|`` (the wideband term) and
    the standard deviation the diffuse multipath adds, ``sqrt(tr G (cov - crlb) G^T)``, with
    ``G`` the position rows of ``(H^T W H)^-1 H^T W``. ``weights``: ``None`` for ``W =
    crlb^-1`` (the estimator of :func:`position_information`, which trusts the ideal bound), or
    the per-path covariances (T, P, 4, 4) the tracker is told
    (:func:`tunnelkit.design.fastroute.tracker_weights`: its error budget, an unresolved
    curvature as an infinite variance), ``W`` then block-diagonal over the paths as the tracker
    weighs them. Under a calibration error the ``crlb^-1`` fix trusts the micrometre curvatures
    of a large array, whose calibration bias is centimetres: its bias is up to 40 times the
    tracker's (28 GHz example, 32 x 32, wideband term and 0.2 dB gain error). Zero for an ideal
    model."""
    _check_geometry(model, geometry)
    T, P = model.exists.shape
    if weights is not None:
        weights = _check_weights(model, weights)
    out = np.zeros((T, 3))
    b_all = np.asarray(model.bias).reshape(T, 4 * P)
    ks = [
        (np.asarray(K).reshape(T, 4 * P, -1), sig)
        for K, sig in ((model.k_phase, model.phase_sigma_rad), (model.k_gain, model.gain_sigma_db))
        if K is not None and sig > 0
    ]
    excess = np.asarray(model.cov) - np.asarray(model.crlb)
    diffuse = bool(np.any(excess))
    for k in range(T):
        rows, G = _weighted_gain(model, geometry, k, weights)
        if rows is None:
            continue
        cal = sum(sig**2 * float(np.sum((G @ K[k, rows]) ** 2)) for K, sig in ks)
        out[k, 0] = np.sqrt(cal)
        out[k, 1] = np.linalg.norm(G @ b_all[k, rows])
        if diffuse:
            E = excess[k][np.ix_(rows, rows)]
            out[k, 2] = np.sqrt(max(float(np.trace(G @ E @ G.T)), 0.0))
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
    sweep passes :func:`tunnelkit.design.fastroute.tracker_weights`), not minimised over the
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
) -> np.ndarray:
    """Posterior CRLB (T,) [m] of the 2-D position along ``setup``'s drive
    (:func:`tunnelkit.tracking.pcrlb.pcrlb`, Tichavsky et al. 1998): JAVELIN's motion model
    (``x_k = x_{k-1} + dt nu (cos theta, sin theta)`` driven by the V2X speed and heading with
    noise ``sigma_speed`` / ``sigma_heading``, default the messages' own: 0.2 m/s, 1 deg), the
    start from an open-sky fix of ``sigma_p0`` [m] (as the studies start JAVELIN), and ``info``
    (T, 2, 2) the position information per epoch (:func:`position_information`)."""
    from .._validate import positive
    from ..simulation.drives import SIGMA_HEADING, SIGMA_SPEED
    from ..tracking.pcrlb import pcrlb, pcrlb_position_rmse

    sig_nu = positive("sigma_speed", SIGMA_SPEED if sigma_speed is None else sigma_speed)
    sig_th = positive("sigma_heading", SIGMA_HEADING if sigma_heading is None else sigma_heading)
    sigma_p0 = start_spread("sigma_p0", sigma_p0)
    info = finite_array("info", info, shape=(None, 2, 2))
    Q = _motion_noise(setup, info.shape[0], sig_nu, sig_th)
    B = pcrlb(np.eye(2), Q, sigma_p0**2 * np.eye(2), info)
    return pcrlb_position_rmse(B)


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
    prediction into epoch ``k`` (Algorithm 4, line 7)."""
    from .._validate import instance, integer, positive

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
      the unit): a lower bound of the MSE **pooled over units** of any tracker;
    * ``calibration=False``: ``e`` known to the bound (conditioned on the unit's draw, whose
      bias ``K e`` then carries no information and only shifts the mean): the bound of **every
      unit**, the same for every draw (the model is linear in ``e``).

    The noise is the model's ``cov`` (what is drawn, diffuse power included), not the reported
    ``crlb``; the clock bias is eliminated per epoch with a flat prior (as the PEB), the
    motion is JAVELIN's driven by the V2X messages (:func:`drive_pcrlb`, which this equals for
    ``calibration=False``), the start an open-sky fix of ``sigma_p0`` [m]. Computed in
    covariance form, each epoch a low-rank update (Woodbury), so the cost grows as ``M^2`` per
    epoch, not ``M^3``."""
    from .._validate import boolean
    from ..simulation.drives import SIGMA_HEADING, SIGMA_SPEED

    _check_geometry(model, geometry)
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
    Q = _motion_noise(setup, T, SIGMA_SPEED, SIGMA_HEADING)
    Pm = np.zeros((2 + m, 2 + m))
    Pm[:2, :2] = sigma_p0**2 * np.eye(2)
    if m:
        Pm[2:, 2:] = np.diag(np.concatenate([np.full(K.shape[-1], s**2) for K, s in ks]))
    out = np.empty(T)
    for k in range(T):
        if k:
            Pm[:2, :2] += Q[k]
        rows, H, _ = _position_rows(model, geometry, k)
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
