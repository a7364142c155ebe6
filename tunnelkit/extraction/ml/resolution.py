"""The statistical resolution limit of the maximum-likelihood stage: how far each path lies from
the others in standard deviations of their difference (:func:`separations`,
:func:`pair_separation`), each path's log-likelihood ratio against noise (:func:`significance`),
and the per-path verdict :func:`resolvable` that defines the estimator's threshold region.

Criterion (Smith 2005; Liu & Nehorai 2007): two paths ``i, j`` with parameters ``x = (u_x, u_y,
w, mu_f, mu_t)`` are resolvable when the test of ``Delta = x_i - x_j = 0`` (one path) against
``Delta != 0`` (two) has power: its statistic ``Delta^T S^-1 Delta`` with ``S = Sigma_ii +
Sigma_jj - Sigma_ij - Sigma_ji`` (``Sigma`` the inverse Fisher information of the concentrated
model, ``(sigma^2 / 2) (Re J^H J)^-1``) is a non-central chi-square with 5 degrees of freedom
and non-centrality ``z^2 = Delta^T S^-1 Delta``. ``z >= RESOLVE_Z = 5`` (non-centrality 25)
detects the pair at a 1 % false-alarm rate with probability 0.87; below it the likelihood has no
separate peak for each path and the errors leave the local bound however well the search does.
A path is resolvable when it is that far from every other and its own log-likelihood ratio
against noise passes the detection test of one path (the residual test's threshold at its
false-alarm rate, :func:`~.residual.calibrated_threshold`). Evaluated at the truth this is a
property of the snapshot (its geometry, gains and noise power), not of the search: the
threshold region is the set of snapshots with a path not resolvable there.
"""

from __future__ import annotations

import numpy as np

from ..._validate import finite_array, positive
from .model import Problem

__all__ = ["RESOLVE_Z", "pair_separation", "resolvable", "separations"]

#: resolution test: two paths closer than this many standard deviations of their difference are
#: in the threshold region of resolution (module text: non-centrality 25 of the 5-parameter test)
RESOLVE_Z = 5.0


def significance(ev, sigma2) -> np.ndarray:
    """Per path: the cost increase if it were removed (gains re-projected), over ``sigma2`` (its
    log-likelihood ratio against noise); ``ev`` an evaluation of :meth:`Problem.evaluate`."""
    Gi = np.linalg.pinv(ev["G"])
    return np.abs(ev["c"]) ** 2 / np.maximum(np.real(np.diag(Gi)), 1e-300) / sigma2


def _checked(prob, theta, mu_f, mu_t, noise_power):
    if not isinstance(prob, Problem):
        raise TypeError(f"prob: expected a Problem, got {type(prob).__name__}")
    sigma2 = positive("noise_power", noise_power)
    theta = finite_array("theta", theta, shape=(None, 3))
    L = theta.shape[0]
    mu_f = finite_array("mu_f", mu_f, shape=(L,))
    mu_t = finite_array("mu_t", mu_t, shape=(L,))
    return theta, mu_f, mu_t, sigma2


def _separations(prob: Problem, theta, mu_f, mu_t, sigma2, ev=None) -> np.ndarray:
    L = theta.shape[0]
    if L < 2:
        return np.full(L, np.inf)
    ev = prob.evaluate(theta, mu_f, mu_t) if ev is None else ev
    cov = (0.5 * sigma2) * np.linalg.pinv(ev["A"])
    C5 = cov.reshape(L, 5, L, 5).transpose(0, 2, 1, 3)  # (L, L, 5, 5) blocks
    x = np.column_stack([theta, mu_f, mu_t])
    i, j = np.triu_indices(L, 1)
    S = C5[i, i] + C5[j, j] - C5[i, j] - C5[j, i]  # (P, 5, 5)
    D = x[i] - x[j]
    q = np.einsum("pa,pa->p", D, np.linalg.solve(S + 1e-300 * np.eye(5), D[..., None])[..., 0])
    z = np.sqrt(np.maximum(q, 0.0))
    out = np.full(L, np.inf)
    np.minimum.at(out, i, z)
    np.minimum.at(out, j, z)
    return out


def separations(prob: Problem, theta, mu_f, mu_t, noise_power: float) -> np.ndarray:
    """Per path (L,): its smallest distance to another path in standard deviations of their
    difference (module text; ``inf`` for a single path)."""
    theta, mu_f, mu_t, sigma2 = _checked(prob, theta, mu_f, mu_t, noise_power)
    return _separations(prob, theta, mu_f, mu_t, sigma2)


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
    outside the estimator's threshold region (module text)."""
    theta, mu_f, mu_t, sigma2 = _checked(prob, theta, mu_f, mu_t, noise_power)
    detect = positive("detect", detect)
    ev = prob.evaluate(theta, mu_f, mu_t)
    z = _separations(prob, theta, mu_f, mu_t, sigma2, ev)
    return (z >= RESOLVE_Z) & (significance(ev, sigma2) >= detect)
