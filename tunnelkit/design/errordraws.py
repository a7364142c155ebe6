"""Drives drawn from a path error model (:class:`~tunnelkit.design.errormodel.PathErrorModel`):
one manufactured unit's calibration error (:func:`draw_calibration`) and the bias it gives
(:func:`calibration_bias`), one drive's measurements (:func:`draw`, its noise through
:func:`noise_sqrt`, the matrix square root :func:`psd_sqrt`) and the share of the error budget a
drive repeats (:func:`split`, what the bound route's tracker is told).

How it works: docs/internals/design.md.
"""

from __future__ import annotations

import numpy as np

from .._checks import square_matrices
from .._validate import finite_array, instance, rng_or_error
from .errormodel import PathErrorModel

__all__ = ["calibration_bias", "draw", "draw_calibration", "noise_sqrt", "psd_sqrt", "split"]


def psd_sqrt(S: np.ndarray) -> np.ndarray:
    """A square root ``L`` with ``L L^T = S`` of a stack of symmetric positive semi-definite
    matrices (..., n, n), through the eigendecomposition (round-off negatives set to 0)."""
    S = square_matrices("S", S)
    S = 0.5 * (S + np.swapaxes(S, -1, -2))
    w, V = np.linalg.eigh(S)
    return V * np.sqrt(np.clip(w, 0.0, None))[..., None, :]


def calibration_bias(model, phase_rad=None, gain_db=None) -> np.ndarray:
    """The bias (T, P, 4) one array's calibration error gives (linearised)."""
    instance("model", model, PathErrorModel)
    T, P = model.exists.shape
    out = np.zeros((T, P, 4))
    if phase_rad is not None and model.k_phase is not None:
        out += model.k_phase @ finite_array("phase_rad", phase_rad, shape=(model.n_elements,))
    if gain_db is not None and model.k_gain is not None:
        out += model.k_gain @ finite_array("gain_db", gain_db, shape=(model.n_elements,))
    return out


def noise_sqrt(model) -> np.ndarray:
    """A square root (T, 4P, 4P) of ``cov`` over the existing paths (absent slots zero):
    what :func:`draw` multiplies its standard normals by. It depends on the model only, so
    a Monte-Carlo computes it once per array and hands it to every :func:`draw`."""
    instance("model", model, PathErrorModel)
    return _cov_root(model)


def _cov_root(model) -> np.ndarray:
    """:func:`noise_sqrt` of a model already checked."""
    m = np.repeat(model.exists, 4, axis=1)
    return psd_sqrt(np.where(m[:, :, None] & m[:, None, :], model.cov, 0.0))


def _repetition(exists: np.ndarray, k: np.ndarray, normalise: bool = True) -> np.ndarray:
    """``rho`` (P, 4) in [0, 1]: the mean correlation, over every pair of distinct epochs of
    the drive where the path exists, of a calibration sensitivity ``k`` (T, P, 4, M)
    (:func:`split`; 1 for a path seen at one epoch only); ``normalise=False`` for a bias
    (``M = 1``): ``sum_{t != s} b_t b_s / ((n - 1) sum_t b_t^2)``, its magnitude counted."""
    k = np.asarray(k, float)
    u = k
    if normalise:
        nrm = np.linalg.norm(k, axis=-1, keepdims=True)
        u = np.where(nrm > 0, k / np.where(nrm > 0, nrm, 1.0), 0.0)
    u = np.where(exists[..., None, None], u, 0.0)
    n = exists.sum(axis=0).astype(float)[:, None]  # (P, 1)
    tot = np.sum(u, axis=0)  # (P, 4, M)
    self_ = np.sum(np.sum(u * u, axis=-1), axis=0)  # (P, 4): n for unit vectors
    pairs = (n - 1) * self_
    rho = np.where(
        pairs > 0, (np.sum(tot * tot, axis=-1) - self_) / np.where(pairs > 0, pairs, 1.0), 1.0
    )
    return np.clip(rho, 0.0, 1.0)


def split(model) -> tuple[np.ndarray, np.ndarray]:
    """The per-path error budget split into what one drive repeats and what it draws afresh
    every epoch, ``(white, repeating)``, each (T, P, 4, 4) and positive semi-definite.

    The calibration bias of path ``p``, component ``c`` at epoch ``t`` is ``K_t e`` for one
    draw ``e`` of the array; between two epochs it correlates as the sensitivities do,
    ``rho_pc = mean_{t != s} k_t . k_s / (|k_t| |k_s|)`` (``_repetition``: about
    0.4-0.9 for the angles and the curvature, about 0 for the delay, whose sensitivity turns
    with the path's phase every epoch). The repeating share is
    ``diag(sqrt(rho)) Sigma_cal diag(sqrt(rho))``, the rest of each variance,
    ``(1 - rho_pc) Sigma_cal,cc``, counts as drawn afresh (its cross terms dropped: the
    split keeps every variance of :meth:`PathErrorModel.budget` and both shares positive semi-definite).
    The deterministic bias ``b_t`` (the wideband term) is split alike with ``k_t = b_t``
    (one element: ``rho`` the mean product of its signs over pairs of epochs; the
    curvature's flips sign from one epoch to the next). ``cov`` is white. A tracker that
    counts the repeating share once per epoch averages it down
    (:class:`tunnelkit.tracking.javelin.ConsiderNoise` carries it as a consider parameter
    instead)."""
    instance("model", model, PathErrorModel)
    T, P = model.exists.shape
    idx = np.arange(P)
    white = np.asarray(model.cov).reshape(T, P, 4, P, 4)[:, idx, :, idx, :]
    white = np.moveaxis(white, 0, 1).copy()
    rep = np.zeros((T, P, 4, 4))
    terms = [
        (np.asarray(k), sig)
        for k, sig in ((model.k_phase, model.phase_sigma_rad), (model.k_gain, model.gain_sigma_db))
        if k is not None and sig > 0
    ]
    terms.append((np.asarray(model.bias)[..., None], 1.0))
    for i, (k, sig) in enumerate(terms):
        rho = _repetition(model.exists, k, normalise=i < len(terms) - 1)  # (P, 4)
        # one share for the direction and curvature (their errors stay correlated as the
        # sensitivities are), one for the delay
        rho = np.concatenate(
            [np.repeat(rho[:, :3].mean(axis=1, keepdims=True), 3, 1), rho[:, 3:]], 1
        )[None]
        kk = np.sqrt(rho)[..., None] * k
        rep += sig**2 * (kk @ np.swapaxes(kk, -1, -2))
        S = sig**2 * (k @ np.swapaxes(k, -1, -2))
        S[..., :3, 3] = S[..., 3, :3] = 0.0
        white += (1.0 - rho)[..., :, None] ** 0.5 * S * (1.0 - rho)[..., None, :] ** 0.5
    m = model.exists[..., None, None]
    return np.where(m, white, 0.0), np.where(m, rep, 0.0)


def draw_calibration(model, rng: np.random.Generator) -> tuple:
    """One manufactured array's calibration error ``(phase_rad, gain_db)``, each (M,) or
    ``None`` where the model has none: drawn once per unit, shared by all its drives."""
    instance("model", model, PathErrorModel)
    rng = rng_or_error("rng", rng)
    M = model.n_elements
    phase = gain = None
    if M is not None and model.phase_sigma_rad > 0:
        phase = model.phase_sigma_rad * rng.standard_normal(M)
    if M is not None and model.gain_sigma_db > 0:
        gain = model.gain_sigma_db * rng.standard_normal(M)
    return phase, gain


def draw(
    model,
    rng: np.random.Generator,
    *,
    noise_sqrt: np.ndarray | None = None,
    calibration: tuple | None = None,
) -> np.ndarray:
    """One drive's measured ``z`` (T, P, 4): the truth plus the deterministic bias, one
    array's calibration bias and a Gaussian error with covariance ``cov`` per epoch; NaN
    where a path does not exist. ``calibration``: the unit's ``(phase_rad, gain_db)``
    (:func:`draw_calibration`, shared by every drive of one unit); ``None`` draws it from
    ``rng`` first (a unit of its own). ``noise_sqrt``: :func:`noise_sqrt` computed once
    (the same draw, without its cost)."""
    instance("model", model, PathErrorModel)
    rng = rng_or_error("rng", rng)
    T, P = model.exists.shape
    if noise_sqrt is None:
        noise_sqrt = _cov_root(model)
    elif np.shape(noise_sqrt) != (T, 4 * P, 4 * P):
        raise ValueError(
            f"noise_sqrt: expected shape {(T, 4 * P, 4 * P)} (errordraws.noise_sqrt(model)), "
            f"got {np.shape(noise_sqrt)}"
        )
    if calibration is None:
        phase, gain = draw_calibration(model, rng)
    elif not isinstance(calibration, tuple) or len(calibration) != 2:
        raise TypeError("calibration: expected (phase_rad, gain_db) from draw_calibration()")
    else:
        phase, gain = calibration
    noise = (noise_sqrt @ rng.standard_normal((T, 4 * P, 1)))[..., 0].reshape(T, P, 4)
    z = model.truth + model.bias + calibration_bias(model, phase, gain) + noise
    return np.where(model.exists[..., None], z, np.nan)
