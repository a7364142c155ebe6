"""The statistical resolution limit of the maximum-likelihood stage (Smith 2005; Liu & Nehorai 2007)
and its threshold in SNR (the method of interval errors, Van Trees 2001 sec. 2.4).

Per path: its distance from the others in standard deviations of their difference
(:func:`separations`, :func:`~.resolved.pair_separation`), its significance
(:func:`significance`), the verdict :func:`~.resolved.resolvable` and the threshold region
:func:`below_threshold` (:func:`snr_threshold`, :func:`outlier_probability`). Per fit: the pair
test (:func:`pair_tests_at`; checked, :func:`~.resolved.pair_test`) and
:func:`unresolved_partners`. How it works: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import i0e

from ..._validate import finite_array, integer, positive
from .model import Problem

__all__ = [
    "OUTLIER_RATE",
    "PAIR_FALSE_ALARM",
    "PAIR_LLR",
    "PAIR_TEST_Z",
    "RESOLVE_Z",
    "below_threshold",
    "outlier_probability",
    "separations",
    "snr_threshold",
]

#: outlier (interval-error) probability of a path at the threshold SNR (docs/internals)
OUTLIER_RATE = 0.01
#: cap on ``n_cells``: a tensor of 10^11 samples (1.6 TB) is beyond any snapshot's memory budget
MAX_CELLS = 10**11

#: resolution test: two paths closer than this many standard deviations of their difference are
#: in the threshold region of resolution (docs/internals: non-centrality 25 of the 5-parameter test)
RESOLVE_Z = 5.0


def significance(ev, sigma2) -> np.ndarray:
    """Per path: the cost increase if it were removed (gains re-projected), over ``sigma2`` (its
    log-likelihood ratio against noise); ``ev`` an evaluation of :meth:`Problem.evaluate`."""
    Gi = np.linalg.pinv(ev["G"])
    return np.abs(ev["c"]) ** 2 / np.maximum(np.real(np.diag(Gi)), 1e-300) / sigma2


#: coherence ``|G_ij| / sqrt(G_ii G_jj)`` above which two atoms are one path counted twice
COUNTED_TWICE = 0.9


def coherent_pair(ev):
    """The two most collinear atoms ``i, j`` and their coherence ``|G_ij| / sqrt(G_ii G_jj)``."""
    dg = np.sqrt(np.maximum(np.real(np.diag(ev["G"])), 1e-300))
    coh = np.abs(ev["G"]) / np.outer(dg, dg)
    np.fill_diagonal(coh, 0.0)
    i, j = np.unravel_index(int(np.argmax(coh)), coh.shape)
    return i, j, coh[i, j]


def check_fit(prob, theta, mu_f, mu_t, noise_power):
    """``(theta, mu_f, mu_t, sigma2)`` checked, each error naming its parameter."""
    if not isinstance(prob, Problem):
        raise TypeError(f"prob: expected a Problem, got {type(prob).__name__}")
    sigma2 = positive("noise_power", noise_power)
    theta = finite_array("theta", theta, shape=(None, 3))
    L = theta.shape[0]
    mu_f = finite_array("mu_f", mu_f, shape=(L,))
    mu_t = finite_array("mu_t", mu_t, shape=(L,))
    return theta, mu_f, mu_t, sigma2


def separations_at(prob: Problem, theta, mu_f, mu_t, sigma2, ev=None) -> np.ndarray:
    """:func:`separations` on checked arguments (``ev`` the evaluation at the fit, if at hand)."""
    L = theta.shape[0]
    if L < 2:
        return np.full(L, np.inf)
    ev = prob.evaluate(theta, mu_f, mu_t) if ev is None else ev
    z = pair_z(prob, theta, mu_f, mu_t, sigma2, ev)
    i, j = np.triu_indices(L, 1)
    out = np.full(L, np.inf)
    np.minimum.at(out, i, z)
    np.minimum.at(out, j, z)
    return out


def separations(prob: Problem, theta, mu_f, mu_t, noise_power: float) -> np.ndarray:
    """Per path (L,): its smallest distance to another path in standard deviations of their
    difference (docs/internals; ``inf`` for a single path)."""
    theta, mu_f, mu_t, sigma2 = check_fit(prob, theta, mu_f, mu_t, noise_power)
    return separations_at(prob, theta, mu_f, mu_t, sigma2)


#: the pair test (docs/internals): rate at which one path is reported as two resolved ones
PAIR_FALSE_ALARM = 0.01
#: pairs fewer than this many standard deviations of their difference apart are tested; further
#: apart the log-likelihood ratio of the two against one, about ``z^2 / 2`` (50 here), is far
#: above ``PAIR_LLR``
PAIR_TEST_Z = 10.0
#: the pair test's threshold on ``(cost_merged - cost) / sigma^2``: the ``1 - PAIR_FALSE_ALARM``
#: quantile of its null distribution (one path fitted as a close pair; docs/internals)
PAIR_LLR = 13.0


def pair_test_rows(prob, theta, mu_f, mu_t, sigma2, ev, z, max_iter, z_max=PAIR_TEST_Z):
    """(P, 4) rows ``(i, j, z_ij, llr_ij)`` for the pairs closer than ``PAIR_TEST_Z``, and the
    iterations spent."""
    L = theta.shape[0]
    rows, n_it = [], 0
    if L < 2:
        return np.zeros((0, 4)), 0
    i, j = np.triu_indices(L, 1)
    for a, b, zab in zip(i, j, z, strict=True):
        if not zab < z_max:
            continue
        from .merged import merged_fit  # loaded when a pair is close enough to test

        merged, its = merged_fit(prob, theta, mu_f, mu_t, ev["c"], sigma2, a, b, max_iter)
        n_it += its
        rows.append((a, b, zab, (merged[3]["cost"] - ev["cost"]) / sigma2))
    return np.array(rows, float).reshape(-1, 4), n_it


def pair_tests_at(prob: Problem, theta, mu_f, mu_t, sigma2: float, ev: dict, max_iter: int):
    """:func:`~.resolved.pair_test` at a fit whose evaluation ``ev`` (with derivatives) is at hand, inputs
    unchecked (the fit's own call); returns the rows and the iterations spent."""
    if theta.shape[0] < 2:
        return np.zeros((0, 4)), 0
    ev = ev if "A" in ev else prob.evaluate(theta, mu_f, mu_t)
    z = pair_z(prob, theta, mu_f, mu_t, sigma2, ev)
    return pair_test_rows(prob, theta, mu_f, mu_t, sigma2, ev, z, max_iter)


def pair_z(prob: Problem, theta, mu_f, mu_t, sigma2, ev) -> np.ndarray:
    """Per pair ``(i < j)`` in ``np.triu_indices`` order: their distance in standard deviations
    of their difference (docs/internals)."""
    L = theta.shape[0]
    cov = (0.5 * sigma2) * np.linalg.pinv(ev["A"])
    C5 = cov.reshape(L, 5, L, 5).transpose(0, 2, 1, 3)
    x = np.column_stack([theta, mu_f, mu_t])
    i, j = np.triu_indices(L, 1)
    S = C5[i, i] + C5[j, j] - C5[i, j] - C5[j, i]
    D = x[i] - x[j]
    q = np.einsum("pa,pa->p", D, np.linalg.solve(S + 1e-300 * np.eye(5), D[..., None])[..., 0])
    return np.sqrt(np.maximum(q, 0.0))


def unresolved_partners(tests: np.ndarray, L: int) -> np.ndarray:
    """Per path (L,): the path it is not resolved from (docs/internals: the pair test's ``llr``
    below ``PAIR_LLR``, one path explains the two, or their separation ``z`` below
    ``RESOLVE_Z``, two paths whose difference the data cannot estimate to the bound; of several,
    the one with the lowest ``llr``), ``-1`` when resolved from all."""
    out = np.full(L, -1, int)
    best = np.full(L, np.inf)
    for a, b, z, llr in np.asarray(tests, float).reshape(-1, 4):
        if llr < PAIR_LLR or z < RESOLVE_Z:
            for p, q in ((int(a), int(b)), (int(b), int(a))):
                if llr < best[p]:
                    out[p], best[p] = q, llr
    return out


def _outlier(gamma: float, K: int) -> float:
    """``P(max of K unit exponentials > |sqrt(gamma) + n_0|^2)`` by quadrature over the path
    cell's non-central chi-square density ``e^{-(x + gamma)} I_0(2 sqrt(gamma x))``."""
    if K == 0:
        return 0.0
    rg = np.sqrt(gamma)

    def f(x):
        s = np.sqrt(x)
        with np.errstate(divide="ignore"):
            beat = -np.expm1(K * np.log1p(-np.exp(-x)))  # 1 - (1 - e^{-x})^K
        return i0e(2.0 * rg * s) * np.exp(-((s - rg) ** 2)) * beat

    hi = (rg + 12.0) ** 2
    pts = sorted({min(gamma, hi), min(np.log(K), hi)})
    return float(min(max(quad(f, 0.0, hi, points=pts, limit=200, epsabs=1e-14)[0], 0.0), 1.0))


def outlier_probability(snr, n_cells: int) -> np.ndarray:
    """The probability that the maximum-likelihood search puts a path of post-integration SNR
    ``snr`` (``E / sigma^2``, linear; array) in a wrong one of ``n_cells`` orthogonal cells
    (docs/internals): ``P(max of n_cells - 1 unit exponentials > |sqrt(snr) + n_0|^2)``, ``n_0 ~
    CN(0, 1)``, by quadrature (the union bound ``(n_cells - 1) e^{-snr / 2} / 2`` is its first
    term)."""
    snr = finite_array("snr", snr)
    if np.any(snr < 0):
        raise ValueError("snr: expected non-negative signal-to-noise ratios (linear)")
    n = integer("n_cells", n_cells, minimum=1, maximum=MAX_CELLS)
    return np.reshape([_outlier(float(g), n - 1) for g in snr.ravel()], snr.shape)


@lru_cache(maxsize=32)
def _threshold(n: int, outlier: float) -> float:
    if n == 1 or _outlier(0.0, n - 1) <= outlier:
        return 0.0  # even a path at zero SNR is confused less often than that
    hi = 2.0 * np.log(0.5 * (n - 1) / outlier) + 40.0  # the union bound's root, and margin
    return float(brentq(lambda g: _outlier(g, n - 1) - outlier, 0.0, hi, xtol=1e-6))


def snr_threshold(n_cells: int, outlier: float = OUTLIER_RATE) -> float:
    """The post-integration SNR (linear) at which :func:`outlier_probability` over ``n_cells``
    equals ``outlier`` (0 when ``n_cells = 1``: nothing to confuse the path with); close to the
    union bound's ``2 ln((n_cells - 1) / (2 outlier))`` when ``outlier`` is small."""
    n = integer("n_cells", n_cells, minimum=1, maximum=MAX_CELLS)
    outlier = positive("outlier", outlier)
    if outlier >= 1:
        raise ValueError(f"outlier: expected a probability below 1, got {outlier}")
    return _threshold(n, float(outlier))


def below_threshold(significance, resolution, n_cells: int) -> np.ndarray:
    """Per path (L,) bool: in the estimator's threshold region (docs/internals), its SNR
    ``significance`` (L,) below :func:`snr_threshold` of ``n_cells`` (the tensor's ``M Nf
    Nt``) or its ``resolution`` (L,, :func:`separations`; ``inf`` alone) below ``RESOLVE_Z``."""
    sig = finite_array("significance", significance, shape=(None,))
    if isinstance(resolution, str | bytes) or np.shape(resolution) != sig.shape:
        raise ValueError(
            f"significance, resolution: expected one of each per path, got shapes {sig.shape} "
            f"and {np.shape(resolution)}"
        )
    res = np.asarray(resolution)
    if res.dtype.kind not in "iuf" or np.any(np.isnan(res)) or np.any(res < 0):
        raise ValueError("resolution: expected non-negative separations (inf for a path alone)")
    return (sig < snr_threshold(n_cells)) | (res < RESOLVE_Z)
