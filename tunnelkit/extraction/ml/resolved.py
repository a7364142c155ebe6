"""The resolution tests of a fit the caller gives (checked; docs/internals/extraction-ml.md):
the closest pair (:func:`closest_pair`) and its distance (:func:`pair_separation`) in standard
deviations of their difference, the per-path verdict :func:`resolvable` and the pair test of each
close pair, one path against two (:func:`pair_test`). The fit computes the same statistics on its
own arrays (:mod:`.resolution`)."""

from __future__ import annotations

import numpy as np

from ..._validate import integer, positive
from .model import Problem
from .resolution import (
    PAIR_TEST_Z,
    RESOLVE_Z,
    check_fit,
    pair_test_rows,
    pair_z,
    separations,
    separations_at,
    significance,
)

__all__ = ["closest_pair", "pair_separation", "pair_test", "resolvable"]


def closest_pair(prob: Problem, theta, mu_f, mu_t, noise_power: float) -> tuple[int, int, float]:
    """The two paths fewest standard deviations of their difference apart (the pairwise distances
    of :func:`separations`): ``(i, j, z)`` with ``i < j``; ``(-1, -1, inf)`` for one path."""
    theta, mu_f, mu_t, sigma2 = check_fit(prob, theta, mu_f, mu_t, noise_power)
    L = theta.shape[0]
    if L < 2:
        return -1, -1, float("inf")
    z = pair_z(prob, theta, mu_f, mu_t, sigma2, prob.evaluate(theta, mu_f, mu_t))
    a, b = np.triu_indices(L, 1)
    k = int(np.argmin(z))
    return int(a[k]), int(b[k]), float(z[k])


def pair_separation(prob: Problem, theta, mu_f, mu_t, noise_power: float) -> float:
    """The smallest distance between two paths in standard deviations of their difference: for
    each pair ``(i, j)`` the Mahalanobis length of ``Delta = (u_x, u_y, w, mu_f, mu_t)_i - (...)_j``
    under the covariance of that difference, ``Sigma_ii + Sigma_jj - Sigma_ij - Sigma_ji``,
    ``Sigma = (sigma^2 / 2) (Re J^H J)^+`` (the inverse Fisher information of the concentrated
    model at the fit). ``inf`` for one path. A pair a few standard deviations apart is below the
    statistical resolution limit: the likelihood has no single peak for it to sit on."""
    z = separations(prob, theta, mu_f, mu_t, noise_power)
    return float(np.min(z)) if z.size else float("inf")


def resolvable(prob: Problem, theta, mu_f, mu_t, noise_power: float, detect: float) -> np.ndarray:
    """Per path (L,) bool: at least ``RESOLVE_Z`` standard deviations from every other path and
    its log-likelihood ratio against noise at least ``detect`` (the detection threshold of one
    path, e.g. :func:`~.residual.calibrated_threshold`). At the true parameters: the path is
    outside the estimator's threshold region (docs/internals)."""
    theta, mu_f, mu_t, sigma2 = check_fit(prob, theta, mu_f, mu_t, noise_power)
    detect = positive("detect", detect)
    ev = prob.evaluate(theta, mu_f, mu_t)
    z = separations_at(prob, theta, mu_f, mu_t, sigma2, ev)
    return (z >= RESOLVE_Z) & (significance(ev, sigma2) >= detect)


def pair_test(
    prob: Problem,
    theta,
    mu_f,
    mu_t,
    noise_power: float,
    *,
    max_iter: int = 60,
    z_max: float = PAIR_TEST_Z,
) -> np.ndarray:
    """The resolution test of each close pair of a fit (docs/internals): for every two paths fewer
    than ``z_max`` (default ``PAIR_TEST_Z``) standard deviations of their difference apart, the generalised
    likelihood-ratio test of one path (the two merged, all ``L - 1`` fitted again) against two:
    rows ``(i, j, z_ij, llr_ij)``, ``llr = (cost_merged - cost) / sigma^2``; the pair is resolved
    when ``llr >= PAIR_LLR`` (false-alarm rate ``PAIR_FALSE_ALARM``). ``theta, mu_f, mu_t``
    should be a converged fit (the statistic compares two maxima of the likelihood)."""
    theta, mu_f, mu_t, sigma2 = check_fit(prob, theta, mu_f, mu_t, noise_power)
    max_iter = integer("max_iter", max_iter, minimum=1, maximum=1000)
    if not (isinstance(z_max, float) and z_max == np.inf):  # inf: every pair tested
        z_max = positive("z_max", z_max)
    ev = prob.evaluate(theta, mu_f, mu_t)
    z = pair_z(prob, theta, mu_f, mu_t, sigma2, ev) if theta.shape[0] > 1 else np.zeros(0)
    return pair_test_rows(prob, theta, mu_f, mu_t, sigma2, ev, z, max_iter, z_max)[0]
