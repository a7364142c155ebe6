"""How the design's tracker weighs the paths, and the position error that weighting gives.

A drive on the bound route (:mod:`tunnelkit.design.fastroute`) hands the tracker per-path
covariances; :func:`tracker_weights` gives them for a :class:`BoundRoute` or, epoch by epoch, for
a :class:`~tunnelkit.design.errormodel.PathErrorModel`. The weighted least-squares fix of each
epoch with those weights (UE's horizontal position and the clock bias ``c b``) maps the model's
error into the position: :func:`position_noise_cov` (its random part),
:func:`position_error_parts` (each term of the model, as :func:`tunnelkit.design.predicted_error`
reports it) and :func:`fix_identifiable` (the epochs where the paths fix the position at all).
The bounds over the whole drive built on the same rows are :mod:`tunnelkit.design.drivebound`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import choice, instance, positive, record
from ..geometry import spherical_jacobian
from .errormodel import PathErrorModel
from .geometry import RouteGeometry

__all__ = [
    "KAPPA_RESOLVED",
    "MODES",
    "REPORTS",
    "START_SIGMA_M",
    "BoundRoute",
    "fix_identifiable",
    "position_error_parts",
    "position_noise_cov",
    "tracker_weights",
]

#: the design's measurement routes: this one (``"bound"``) and the channel route (``"channel"``),
#: what :func:`tunnelkit.design.montecarlo.sweep_montecarlo` runs the tracker on
MODES = ("bound", "channel")

#: a curvature is reported only where its reported standard deviation is below this share of the
#: path's range (otherwise the path goes on as far field, as a plane-wave fit would report it)
KAPPA_RESOLVED = 0.1

#: what the bound route reports to the tracker (:func:`bound_drive`)
REPORTS = ("auto", "crlb", "budget")

#: the open-sky fix's standard deviation per axis [m], the design's default entry fix
#: (``start_sigma`` of :func:`tunnelkit.design.montecarlo.sweep_montecarlo`): the tracker's
#: ``sigma_p0_ue`` and the prior of the bounds over the drive (:func:`drive_pcrlb`)
START_SIGMA_M = 1.0


@dataclass(frozen=True)
class BoundRoute:
    """What every drive of one array on the bound route shares (:func:`bound_route`): the
    ``model``, the ``report`` it hands the tracker, the reported per-path blocks (T, P, 4, 4),
    the square root of the model's ``cov`` (T, 4P, 4P) the draws multiply, the array's
    reference antenna per epoch ``origin`` (T, 3), Algorithm 1's ``min_d`` and ``repeating``
    (T, P, 4, 4): the share of the reported blocks that repeats every epoch (``None`` for the
    CRLB report; :func:`~tunnelkit.design.errordraws.split` for the budget, whose two shares the blocks
    add). Computed once
    per array, so a drive costs its random draws and nothing else."""

    model: PathErrorModel
    label: str
    report: str
    blocks: np.ndarray
    noise_sqrt: np.ndarray
    origin: np.ndarray
    min_d: float
    repeating: np.ndarray | None = None

    def __post_init__(self) -> None:
        blocks = ("T", "P", 4, 4)
        record(self, shapes={"blocks": blocks, "noise_sqrt": ("T", None, None),
                             "origin": ("T", 3), "repeating": blocks})  # fmt: skip
        choice("report", self.report, REPORTS)


def _snapshot_blocks(model: PathErrorModel) -> np.ndarray:
    """The per-path blocks (T, P, 4, 4) of each epoch on its own: the CRLB for an ideal model,
    the error budget (:meth:`PathErrorModel.budget`) otherwise."""
    T, P = model.exists.shape
    ideal = model.phase_sigma_rad == 0 and model.gain_sigma_db == 0
    if ideal and not np.any(model.bias) and np.array_equal(model.cov, model.crlb):
        idx = np.arange(P)
        return np.moveaxis(model.crlb.reshape(T, P, 4, P, 4)[:, idx, :, idx, :], 0, 1)
    return model.budget()


def tracker_weights(route) -> np.ndarray:
    """The per-path covariances (T, P, 4, 4) the tracker is told on the bound route: ``route``
    a :class:`BoundRoute` (its ``blocks``) or a :class:`PathErrorModel` (each epoch on its own:
    the CRLB for an ideal model, the error budget :meth:`PathErrorModel.budget` otherwise, not
    the drive's split, whose repeating share is a correlation over the whole route), with the variance of a curvature
    :func:`bound_drive` does not hand on (reported standard deviation above
    :data:`KAPPA_RESOLVED` of the range) infinite and its covariances zero: the weights of
    :func:`position_error_parts` for the tracker that is run."""
    if isinstance(route, PathErrorModel):
        # the budget of each epoch alone: the report of a drive (its split into white and
        # repeating shares) weighs every epoch by correlations over the whole route, so a
        # snapshot fix at one position would depend on the rest of the route
        model, blocks = route, _snapshot_blocks(route)
    elif isinstance(route, BoundRoute):
        model, blocks = route.model, route.blocks
    else:
        raise TypeError(
            f"route: expected a design.BoundRoute or PathErrorModel, got {type(route).__name__}"
        )
    b = np.array(blocks, float)
    drop = np.sqrt(b[..., 2, 2]) > KAPPA_RESOLVED * np.abs(model.truth[..., 3])
    b[..., 2, :] = np.where(drop[..., None], 0.0, b[..., 2, :])
    b[..., :, 2] = np.where(drop[..., None], 0.0, b[..., :, 2])
    b[..., 2, 2] = np.where(drop, np.inf, b[..., 2, 2])
    return b


def position_rows(model: PathErrorModel, geometry, k: int):
    """Epoch ``k``: the rows of the existing paths in ``z`` and ``H`` (4n, 3), the map of the
    UE's horizontal position and ``c b`` into them (``None`` without a path)."""
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


def check_geometry(model, geometry) -> None:
    instance("geometry", geometry, RouteGeometry)
    if not isinstance(model, PathErrorModel):
        raise TypeError(f"model: expected a design.PathErrorModel, got {type(model).__name__}")
    if geometry.exists.shape != model.exists.shape:
        raise ValueError(
            f"geometry: expected {model.exists.shape[0]} epochs and {model.exists.shape[1]} "
            "path slots like the model"
        )


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
    rows, H, j = position_rows(model, geometry, k)
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
    check_geometry(model, geometry)
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
    covariances the tracker is told (:func:`tracker_weights`; an
    unresolved curvature as an infinite variance gets no weight). ``W = crlb^-1`` would give
    the PEB's covariance; any other weight gives more (Gauss-Markov), and the tracker that is
    run weighs its paths block by block. Zero at an epoch without a path."""
    check_geometry(model, geometry)
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
    (:func:`tracker_weights`: its error budget, an unresolved
    curvature as an infinite variance), ``W`` then block-diagonal over the paths as the tracker
    weighs them. Under a calibration error the ``crlb^-1`` fix trusts the micrometre curvatures
    of a large array, whose calibration bias is centimetres: its bias is up to 40 times the
    tracker's (28 GHz example, 32 x 32, wideband term and 0.2 dB gain error). Zero for an ideal
    model."""
    check_geometry(model, geometry)
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
