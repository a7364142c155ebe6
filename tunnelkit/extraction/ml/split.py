"""The split move of the fit (docs/internals/extraction-ml.md): a path below the noise, or two
too close, taken for two sources merged elsewhere while the weak path sits on nothing; it is
dropped and each other path in turn split in two (:func:`split_weak`, what
:func:`~.fitting.fit_problem` tries after the re-initialisation), the starts ranked by their
likelihood (:func:`~.lm.best_of_starts`)."""

from __future__ import annotations

import numpy as np

from .lm import best_of_starts
from .model import Problem, project_feasible
from .resolution import COUNTED_TWICE, coherent_pair
from .resolved import closest_pair
from .search import SPLIT_STEPS

#: nothing exported: a step of the fit, on the fit's own checked arrays
__all__: list[str] = []

#: split steps of :func:`split_weak`: ``SPLIT_STEPS`` and the same 2.5 times longer (long-range
#: images lie 1-5 deg, 0.02-0.09 in direction cosine, from the path they merge with)
WEAK_SPLITS = (*SPLIT_STEPS, *(tuple(2.5 * v for v in du) for du in SPLIT_STEPS))
#: :func:`split_weak` on a pair: kept at a cost fall of PAIR_GAIN sigma^2
PAIR_GAIN = 1.0


def split_weak(
    prob: Problem, best, sigma2, sig, pair: bool, gain_min, short: int, max_iter: int, fit
):
    """A path below the noise (``MIN_SIGNIFICANCE``) or two closer than ``RESOLVE_Z``: one path
    too few elsewhere (two sources merged) while the weak path, or the less significant of the
    pair (a path counted twice), sits on nothing. It is dropped and each other path in turn split
    in two (halves ``u -+ WEAK_SPLITS``, same delay and Doppler); each start gets ``short``
    (``RANK_ITER``) iterations, the most likely is fitted to convergence and kept if the cost
    falls by more than ``gain_min`` (a path's detection threshold: structure, not noise) or, for
    a pair (same model order), ``PAIR_GAIN`` noise powers. Returns the fit, the iterations and
    whether it was kept. ``sig`` the paths' significance, ``pair`` no path is below the noise.

    A flagged fit (:func:`~.fitting._split_weak`: the residual test still fails after the
    re-initialisation on its peak, a wrong basin the far-field periodogram cannot locate: two
    paths of a cluster fitted with the wrong curvature, each on a mixture of two sources, leave
    near-field structure whose grid peak lies nowhere near them) comes here with its pairs
    resolved: the closest pair is then tried as above whatever its separation; with the most
    coherent pair's starts ranked beside it (:func:`_split_pairs`)."""
    theta, mu_f, mu_t, ev = best[:4]
    weaks = [int(np.argmin(sig))]
    if pair:
        pairs = _split_pairs(prob, theta, mu_f, mu_t, sigma2, ev)
        weaks = list(dict.fromkeys(int(p[np.argmin(sig[p])]) for p in pairs))
        gain_min = PAIR_GAIN * sigma2
    starts = []
    for weak in weaks:
        for l_ in np.argsort(-np.abs(ev["c"])):
            if l_ == weak:
                continue
            for du in WEAK_SPLITS:
                th2, mf2, mt2 = theta.copy(), mu_f.copy(), mu_t.copy()
                th2[weak], mf2[weak], mt2[weak] = theta[l_], mu_f[l_], mu_t[l_]
                th2[l_, :2] += du
                th2[weak, :2] -= du
                starts.append((project_feasible(th2), mf2, mt2))
    cand, n_it = best_of_starts(fit, prob, starts, sigma2, short, max_iter)
    if cand[3]["cost"] < ev["cost"] - gain_min:
        return cand, n_it, True
    return best, n_it, False


def _split_pairs(prob: Problem, theta, mu_f, mu_t, sigma2, ev) -> list[np.ndarray]:
    """The pairs :func:`split_weak` takes apart: the closest in standard deviations of its
    difference (:func:`~.resolved.closest_pair`) and, when another pair, the two atoms more
    coherent than :data:`COUNTED_TWICE` (one path counted twice: its large, cancelling gains can
    leave an unrelated pair 0 sd apart, and real paths can be that coherent too)."""
    a, b, _ = closest_pair(prob, theta, mu_f, mu_t, sigma2)
    out = [np.array([a, b])]
    i, j, coh = coherent_pair(ev)
    if coh > COUNTED_TWICE and {int(i), int(j)} != {a, b}:
        out.append(np.array([i, j]))
    return out
