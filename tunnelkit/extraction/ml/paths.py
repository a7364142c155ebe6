"""The front of the maximum-likelihood stage: :func:`ml_paths` (start, fit, estimates) and
:func:`estimates_from_fit` (an :class:`~.fitting.MLFit` read as :class:`PathEstimates`)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from ..._validate import boolean, integer, nonnegative, positive
from ...budget import check_elements
from ...constants import C
from ..coherent import resolve_coherent
from ..decomposition import check_rank, check_tensor
from ..estimates import PathEstimates, path_estimates
from ..numerics import MIN_SIGNIFICANCE, spatial_phase
from ..paper import angles_from_solution, paper_route
from ..radio import check_array, check_srs
from .fitting import MAX_ITER, SEARCHES, MLDetectionWarning, MLFit, fit_problem
from .model import W_FAR, W_MAX, Problem
from .resolution import below_threshold
from .search import start_from_estimates

__all__ = ["estimates_from_fit", "ml_paths", "physical"]


def estimates_from_fit(fit: MLFit, array, srs, nf: int, nt: int, rel_error: float) -> PathEstimates:
    """:class:`PathEstimates` of a fit to a tensor with ``nf`` tones and ``nt`` symbols, at
    ``array`` with ``srs`` (as in :func:`~tunnelkit.extraction.extract_paths`); ``rel_error`` is
    reported as is (:func:`ml_paths` gives ``||r||^2 / ||H||^2``). See :func:`ml_paths` for what
    each field means."""
    if not isinstance(fit, MLFit):
        raise TypeError(f"fit: expected an MLFit, got {type(fit).__name__}")
    element_positions = check_array(array)
    srs = check_srs(srs)
    fc, subcarrier_spacing, symbol_period = srs.fc, srs.tone_spacing, srs.symbol_period
    nf = integer("nf", nf, minimum=1)
    nt = integer("nt", nt, minimum=1)
    check_elements("nf", nf), check_elements("nt", nt)
    rel_error = nonnegative("rel_error", rel_error)
    th = fit.theta
    w = th[:, 2]
    near = w > W_FAR
    uz = np.sqrt(np.clip(1.0 - th[:, 0] ** 2 - th[:, 1] ** 2, 0.0, None))
    kap = np.where(w > 0, 1.0 / np.where(w > 0, w, 1.0), np.inf)
    ff = angles_from_solution(np.zeros((len(w), 3)), th[:, :2])  # angles of u (eq. 19 convention)
    ang = {
        f"{key}_{side}": ff[f"{key}_ff"] for key in ("dir", "phi", "psi") for side in ("nf", "ff")
    }
    ang["dir_nf"] = ang["dir_ff"] = np.column_stack([th[:, 0], th[:, 1], uz])
    ang["kappa_nf"] = kap
    k0 = 2 * np.pi * fc / C
    psi = spatial_phase(th, element_positions, k0)[0]
    A = np.exp(1j * psi)
    F = np.exp(1j * np.arange(nf)[:, None] * fit.mu_f[None, :])
    T = np.exp(1j * np.arange(nt)[:, None] * fit.mu_t[None, :])
    d = -C / (2 * np.pi * subcarrier_spacing) * fit.mu_f  # eq. 14
    v = C / (2 * np.pi * fc * symbol_period) * fit.mu_t  # eq. 15
    est = path_estimates(
        fit.alpha,
        d,
        v,
        ang,
        near,
        (psi / k0).T,
        fit.mu_f,
        fit.mu_t,
        (A, F, T),
        rel_error,
        fit.n_iter,
        fit.converged,
    )
    o = np.argsort(d)
    signif = fit.significance[o]
    res = None if fit.resolution is None else np.asarray(fit.resolution, float)[o]
    n_cells = element_positions.shape[0] * nf * nt
    unres = None
    if fit.unresolved is not None:  # partners in the sorted order
        rank = np.empty(len(o), int)
        rank[o] = np.arange(len(o))
        part = np.asarray(fit.unresolved, int)[o]
        unres = np.where(part >= 0, rank[np.maximum(part, 0)], -1)
    return replace(
        est,
        valid=est.valid & (signif >= MIN_SIGNIFICANCE) & physical(est, srs),
        fit=fit,
        significance=signif,
        fit_ok=bool(fit.fit_ok),
        resolution=res,
        below_threshold=below_threshold(
            signif, np.full(len(o), np.inf) if res is None else res, n_cells
        ),
        unresolved=unres,
    )


def physical(est: PathEstimates, srs) -> np.ndarray:
    """Per path: the estimate is physically possible — finite, ``|v| < c``, ``|d|`` within the
    unambiguous range ``c / (2 Delta f)``, a unit direction in the front half-space (``u_z >=
    0``) and a curvature radius, where near-field, at least ``1 / W_MAX``."""
    if not isinstance(est, PathEstimates):
        raise TypeError(f"est: expected extraction.PathEstimates, got {type(est).__name__}")
    srs = check_srs(srs)
    u = np.asarray(est.direction, float)
    kap = np.asarray(est.kappa, float)
    ok = np.isfinite(est.d) & np.isfinite(est.v) & np.all(np.isfinite(u), axis=1)
    ok &= np.abs(est.v) < C
    ok &= np.abs(est.d) <= C / (2 * srs.tone_spacing) * (1 + 1e-9)
    ok &= (u[:, 2] >= 0) & np.isclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-9)
    ok &= np.where(np.isfinite(kap), kap >= 1.0 / W_MAX * (1 - 1e-9), True)
    return ok


def ml_paths(
    H,
    n_paths: int,
    array,
    srs,
    *,
    start: PathEstimates | tuple | None = None,
    noise_power: float | None = None,
    max_iter: int = 60,
    n_reseed: int | None = None,
    search: str = "residual",
    wideband: bool = False,
) -> PathEstimates:
    """Joint maximum-likelihood extraction (docs/internals/extraction-ml.md); the
    default route of :func:`~tunnelkit.extraction.extract_paths`.

    ``search``: ``"residual"`` (default) or ``"basic"`` (:func:`~.fitting.fit_problem`).
    ``start``: a :class:`PathEstimates` (any route; projected onto the front half-space), a tuple
    ``(theta (L, 3), mu_f, mu_t)`` (checked: ``ValueError`` outside the front half-space), or
    ``None`` — the CPD, the paper's roots and the coherent split (:func:`resolve_coherent`).
    ``array`` and ``srs`` as in :func:`~tunnelkit.extraction.extract_paths`.

    The returned :class:`PathEstimates` reads like the other routes': ``alpha`` the gains
    (``sqrt(P_t) alpha_l``), ``d``, ``v``, ``direction`` (unit, local frame), ``kappa`` the
    distance of the wave origin (``1/w``; NaN where ``w <= W_FAR``, i.e. beyond 1 km: far field),
    ``near_field = kappa`` finite, ``phi``/``psi`` the local angles, ``kappa_nf`` = ``1/w``
    (``inf`` at ``w = 0``), ``delta`` (L, M) the model's path-length offsets
    ``||q - p_m|| - ||q||``, ``factors`` the model's unit-gain mode vectors ``(a, f, t)``,
    ``rel_error`` = ``||r||^2 / ||H||^2``, ``valid`` = ``d >= 0`` (Algorithm 1: with a
    negative clock bias a near vehicle can have ``d < 0``) and significant against the noise
    (``significance >= MIN_SIGNIFICANCE``), ``significance`` each path's log-likelihood ratio,
    ``fit`` the :class:`MLFit` (noise power, basin test), ``fit_ok`` its verdict
    (:attr:`MLFit.fit_ok`; ``False``: the snapshot is in the threshold region or the search
    missed the likelihood's basin: a path missed, merged or off by many standard deviations).
    A path marked ``valid`` is physically possible (:func:`physical`).

    ``wideband``: the model carries the spatial-wideband term (:mod:`.wideband`: element ``m``
    delayed by its path-length offset, the tones around ``srs.fc``); the eq. 1 fit (search and
    re-seedings as above) is refined on it by Levenberg-Marquardt, and the estimates, ``fit`` and
    ``fit_ok`` are the refined fit's (``factors`` and ``delta`` stay eq. 1's mode vectors at the
    refined parameters). Off by default: eq. 1 exactly.
    """
    H = check_tensor(H)
    M, nf, nt = H.shape
    L = check_rank(H.shape, n_paths)
    pos = check_array(array, m=M)
    srs = check_srs(srs)
    noise_power = positive("noise_power", noise_power, none=True)
    if search not in SEARCHES:
        raise ValueError(f"search: expected one of {SEARCHES}, got {search!r}")
    wideband = boolean("wideband", wideband)
    if start is not None and not isinstance(start, PathEstimates):
        from .given_start import check_start  # a start given as a tuple

        start = check_start(start, L)
    if L >= M:
        raise ValueError(
            f"n_paths: at most {M - 1} paths can be told apart by {M} antennas, got {L}"
        )
    max_iter = integer("max_iter", max_iter, minimum=1, maximum=MAX_ITER)
    n_reseed = L if n_reseed is None else integer("n_reseed", n_reseed, minimum=0, maximum=MAX_ITER)
    prob = Problem(H, pos, srs.fc)
    if start is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            est0 = paper_route(H, L, pos, srs, refine="column")
            est0 = resolve_coherent(H, est0, pos, srs, L)
        start = start_from_estimates(est0)
        if len(est0) < L:  # the split found fewer distinct paths: seed the rest from the residual
            from .rank_one import complete_paths  # loaded when the split falls short

            start = complete_paths(prob, start, L)
    elif isinstance(start, PathEstimates):
        if len(start) != L:
            raise ValueError(f"start: has {len(start)} paths, n_paths = {L}")
        start = start_from_estimates(start)
    if search not in SEARCHES:
        raise ValueError(f"search: expected one of {SEARCHES}, got {search!r}")
    wideband = boolean("wideband", wideband)
    fit = fit_problem(
        prob, start, noise_power=noise_power, max_iter=max_iter, n_reseed=n_reseed, search=search
    )
    if wideband:  # the eq. 1 fit refined on the model with the spatial-wideband term
        from .wideband import WidebandProblem  # the model loaded when asked for

        prob = WidebandProblem(H, pos, srs.fc, srs.tone_spacing)
        fit = fit_problem(
            prob,
            (fit.theta, fit.mu_f, fit.mu_t),
            noise_power=noise_power,
            max_iter=max_iter,
            n_reseed=0,
            search="basic",
        )
    n_sig = int(np.sum(fit.significance >= MIN_SIGNIFICANCE))
    if n_sig < L:
        warnings.warn(
            f"ml_paths: {n_sig} of n_paths = {L} paths stand above the noise; the others are "
            "returned with valid = False",
            MLDetectionWarning,
            stacklevel=2,
        )
    return estimates_from_fit(fit, pos, srs, nf, nt, fit.cost / max(prob.h2, 1e-300))
