"""The re-seedings on the residual energy (docs/internals/extraction-ml.md): when a fit's cost
stays above the basin test's (``rho > rho_max``), :func:`rho_reseed` merges a path counted twice
and splits another, adds a path from the residual and drops the least significant (birth and
death), or seeks the weakest path again, each move kept if the likelihood rises."""

from __future__ import annotations

import numpy as np

from .lm import lm_with
from .model import Problem, project_feasible
from .rank_one import search_path
from .resolution import COUNTED_TWICE, coherent_pair
from .resolution import significance as path_significance
from .search import SPLIT_STEPS

#: nothing exported: a step of the fit, on the fit's own checked arrays
__all__: list[str] = []


def _birth_death(prob: Problem, theta, mu_f, mu_t, ev, sigma2, max_iter, fit):
    """One path more, sought in the pure residual; all ``L + 1`` fitted jointly; the least
    significant one out and the ``L`` fitted again (a path missed while another was counted
    twice, or two paths merged, leave a structured residual that this move picks up)."""
    r = prob.H - prob.model(theta, mu_f, mu_t, ev["c"])
    big = lm_with(prob, theta, mu_f, mu_t, search_path(r, prob), sigma2, max_iter, fit)
    keep = np.arange(theta.shape[0] + 1) != int(np.argmin(path_significance(big[3], sigma2)))
    res = fit(prob, big[0][keep], big[1][keep], big[2][keep], sigma2, max_iter)
    return res, big[4] + res[4]


def _merge_and_split(
    prob, theta, mu_f, mu_t, ev, sigma2, max_iter, cost_ok, fit, coherence=COUNTED_TWICE
):
    """If two atoms are nearly collinear (one path counted twice, ``|G_ij| / sqrt(G_ii G_jj) >
    coherence``): drop the weaker, fit the ``L - 1``, then split one of them into two halves
    ``u -+ SPLIT_STEPS`` (two sources closer than a beamwidth fitted as one) and fit all ``L``;
    the first split whose cost is below ``cost_ok`` (the basin test), else the best. ``None``
    when no two atoms are that alike."""
    i, j, coh = coherent_pair(ev)
    if coh < coherence:
        return None
    drop = j if abs(ev["c"][i]) >= abs(ev["c"][j]) else i
    keep = np.arange(theta.shape[0]) != drop
    th, mf, mt, ev_s, its, _ = fit(prob, theta[keep], mu_f[keep], mu_t[keep], sigma2, max_iter)
    best = None
    for l_ in np.argsort(-np.abs(ev_s["c"])):
        for du in SPLIT_STEPS:
            t2 = np.vstack([th, th[l_]])
            t2[l_, :2] += du
            t2[-1, :2] -= du
            mf2, mt2 = np.append(mf, mf[l_]), np.append(mt, mt[l_])
            res = fit(prob, project_feasible(t2), mf2, mt2, sigma2, max_iter)
            its += res[4]
            if best is None or res[3]["cost"] < best[3]["cost"]:
                best = res
            if best[3]["cost"] <= cost_ok:
                return best, its
    return best, its


def rho_reseed(prob: Problem, best, sigma2, max_iter, n_reseed, cost_ok, history, dof, fit):
    """The re-seedings on the residual energy (docs/internals/extraction-ml.md): while the cost is
    above ``cost_ok`` (the ``rho`` test), merge and split (once), then alternately birth and death
    and the weakest path re-sought, each kept if the likelihood rises. Returns the fit, the
    iterations spent and the number of kept moves."""
    tried: set = set()
    n_it = kept = 0
    H, L = prob.H, best[0].shape[0]
    split_tried = False
    for attempt in range(n_reseed):
        theta, mu_f, mu_t, ev = best[:4]
        if ev["cost"] <= cost_ok:
            break
        merged = None
        if not split_tried:  # one path counted twice: merge it, split another (once)
            merged = _merge_and_split(prob, theta, mu_f, mu_t, ev, sigma2, max_iter, cost_ok, fit)
        if merged is not None:
            cand, its = merged
            split_tried = True
        elif attempt % 2 == 0:  # birth and death: a path from the residual, the weakest out
            cand, its = _birth_death(prob, theta, mu_f, mu_t, ev, sigma2, max_iter, fit)
        else:  # the weakest path re-sought in the residual plus its own contribution
            sig = path_significance(ev, sigma2)
            order = [int(i) for i in np.argsort(sig) if int(i) not in tried]
            if not order:
                continue
            worst = order[0]
            tried.add(worst)
            keep = np.arange(L) != worst
            R = H - prob.model(theta[keep], mu_f[keep], mu_t[keep], ev["c"][keep])
            th_n, mf_n, mt_n = search_path(R, prob)
            th2, mf2, mt2 = theta.copy(), mu_f.copy(), mu_t.copy()
            th2[worst], mf2[worst], mt2[worst] = th_n, mf_n, mt_n
            cand = fit(prob, th2, mf2, mt2, sigma2, max_iter)
            its = cand[4]
        n_it += its
        history.append(cand[3]["cost"] / (dof * sigma2))
        if cand[3]["cost"] < ev["cost"]:
            best, kept = cand, kept + 1
            tried = set()
    return best, n_it, kept
