"""The one path a close pair is merged into, the pair test's alternative
(:func:`~.resolved.pair_test`): :func:`merged_fit`, the ``L - 1`` paths with the two replaced by
one started at their centroid and at each of the two, and the phases' weighted mean on the circle
(:func:`circular_mean`, also the merged pair of :func:`~tunnelkit.extraction.bounds.merged_path`)."""

from __future__ import annotations

import numpy as np

from ..._validate import finite_array
from .lm import best_of_starts, lm_fit
from .model import Problem, project_feasible

__all__ = ["circular_mean"]

#: Levenberg-Marquardt iterations each start of the merged fit gets before they are ranked
_MERGE_RANK_ITER = 8


def merged_fit(prob: Problem, theta, mu_f, mu_t, c, sigma2, i: int, j: int, max_iter: int):
    """The ``L - 1`` paths with ``i`` and ``j`` replaced by one: started at their centroid
    (weights ``|c|^2``, circular means of ``mu``) and at each of the two, every start given a few
    iterations, the most likely fitted to convergence; returns the fit and the iterations."""
    L = theta.shape[0]
    w = np.abs(c[[i, j]]) ** 2
    w = w / max(w.sum(), 1e-300)
    keep = np.arange(L) != j
    starts = []
    for wi in (w[0], 1.0, 0.0):
        th, mf, mt = theta.copy(), mu_f.copy(), mu_t.copy()
        th[i] = wi * theta[i] + (1 - wi) * theta[j]
        mf[i] = circular_mean([wi, 1 - wi], mu_f[[i, j]])
        mt[i] = circular_mean([wi, 1 - wi], mu_t[[i, j]])
        starts.append((project_feasible(th[keep]), mf[keep], mt[keep]))
    return best_of_starts(lm_fit, prob, starts, sigma2, min(_MERGE_RANK_ITER, max_iter), max_iter)


def circular_mean(weights, angles) -> float:
    """The weighted mean of phases on the circle, ``angle(sum_k w_k exp(j a_k))`` [rad], in
    ``[-pi, pi]``: the ``mu_f`` / ``mu_t`` of a pair of paths merged into one (an arithmetic mean
    of ``3.1`` and ``-3.1`` gives ``0``, the opposite side of the circle; this gives ``pi``).
    ``weights`` (K,) non-negative, not all zero; ``angles`` (K,) [rad]. When the weighted
    phasors cancel the result is the angle of the heaviest one."""
    a = finite_array("angles", angles, ndim=1)
    w = finite_array("weights", weights, shape=(a.size,))
    if a.size == 0:
        raise ValueError("angles: expected at least one angle")
    if np.any(w < 0) or not w.max() > 0:
        raise ValueError("weights: expected non-negative weights, not all zero")
    w = np.ldexp(w, -int(np.frexp(w.max())[1]))  # by a power of 2: exact, no overflow
    z = w @ np.exp(1j * a)
    if not abs(z) > 1e-12 * w.sum():
        return float(np.angle(np.exp(1j * a[int(np.argmax(w))])))
    return float(np.angle(z))
