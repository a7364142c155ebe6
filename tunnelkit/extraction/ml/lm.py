"""Levenberg-Marquardt on the concentrated cost of a :class:`~.model.Problem`
(docs/internals/extraction-ml.md: the damped Gauss-Newton step, the stopping rule on the Newton
decrement), shared by the fit (:mod:`.fitting`) and the resolution test (:mod:`.resolution`)."""

from __future__ import annotations

import numpy as np

from ..._validate import finite_array, integer, positive
from ..numerics import damped_solve_unchecked, damped_system_unchecked, free_newton_unchecked
from .model import W_MAX, Problem, project_feasible

__all__ = ["STEP_TOL", "best_of_starts", "lm_fit"]

STEP_TOL = 1e-4  # Newton decrement in units of sigma^2 (0.01 standard deviations)
#: cap on ``max_iter`` (``fitting.MAX_ITER``: a fit not converged in 1,000 is not converging)
MAX_LM_ITER = 1000


def lm_fit(prob: Problem, theta, mu_f, mu_t, sigma2, max_iter: int, state: dict | None = None):
    """Levenberg-Marquardt on the concentrated cost; returns the best point and its evaluation.

    ``state`` (a dict, optional) makes the iteration resumable: read at the start (``"lam"`` the
    damping, ``"ev"`` the evaluation at the start point, if present) and written at the end
    (the damping reached and the evaluation of the returned point), so ``m`` iterations and
    then ``n`` more from the point returned run exactly the ``m + n`` iterations of one call."""
    if not isinstance(prob, Problem):
        raise TypeError(f"prob: expected a Problem, got {type(prob).__name__}")
    theta = finite_array("theta", theta, shape=(None, 3))
    L = theta.shape[0]
    mu_f = finite_array("mu_f", mu_f, shape=(L,))
    mu_t = finite_array("mu_t", mu_t, shape=(L,))
    sigma2 = positive("sigma2", sigma2)
    max_iter = integer("max_iter", max_iter, minimum=1, maximum=MAX_LM_ITER)
    if state is not None and not isinstance(state, dict):
        raise TypeError(f"state: expected a dict or None, got {type(state).__name__}")
    state = {} if state is None else state
    ev = state.get("ev") or prob.evaluate(theta, mu_f, mu_t)
    lam, it, converged = state.get("lam", 1e-3), 0, False
    # the damped system at the current point (free set and decrement passed), kept while a
    # rejected step leaves the point where it is (the same arrays give the same numbers)
    newton = None
    for it in range(1, max_iter + 1):  # noqa: B007
        if newton is None:
            lower = np.zeros((L, 5), bool)
            lower[:, 2] = theta[:, 2] <= 0.0
            upper = np.zeros((L, 5), bool)
            upper[:, 2] = theta[:, 2] >= W_MAX
            # Newton decrement: the cost decrease a full Gauss-Newton step promises, in sigma^2
            free, dec = free_newton_unchecked(ev["A"], ev["g"], lower.ravel(), upper.ravel())
            if dec < STEP_TOL * sigma2:
                converged = True
                break
            newton = damped_system_unchecked(ev["A"], ev["g"], free)
        step = damped_solve_unchecked(newton, lam)
        if step is None:
            lam *= 4.0
            continue
        st = step.reshape(L, 5)
        th_new = project_feasible(theta + st[:, :3])
        mf_new, mt_new = mu_f + st[:, 3], mu_t + st[:, 4]
        ev_new = prob.evaluate(th_new, mf_new, mt_new)
        if ev_new["cost"] < ev["cost"]:
            theta, mu_f, mu_t, ev = th_new, mf_new, mt_new, ev_new
            lam = max(lam / 3.0, 1e-9)
            newton = None
        else:
            lam *= 4.0
            if lam > 1e10:
                converged = True  # no descent direction left at working precision
                break
    state["lam"], state["ev"] = lam, ev
    return theta, mu_f, mu_t, ev, it, converged


def lm_with(prob: Problem, theta, mu_f, mu_t, new, sigma2, max_iter, fit):
    """``fit`` (the caller's ``lm_fit``) on the ``L`` paths plus one more, ``new = (theta, mu_f,
    mu_t)``."""
    th, mf, mt = np.vstack([theta, new[0]]), np.append(mu_f, new[1]), np.append(mu_t, new[2])
    return fit(prob, th, mf, mt, sigma2, max_iter)


def best_of_starts(fit, prob: Problem, starts, sigma2, short: int, max_iter: int):
    """Several starts ranked by their likelihood: each ``(theta, mu_f, mu_t)`` of ``starts`` gets
    ``short`` iterations of ``fit`` (:func:`lm_fit`'s signature), the lowest cost is run on to
    ``max_iter`` unless already converged. Returns that fit and the iterations spent in all."""
    if not callable(fit):
        raise TypeError(f"fit: expected a function like lm_fit, got {type(fit).__name__}")
    if not isinstance(prob, Problem):
        raise TypeError(f"prob: expected a Problem, got {type(prob).__name__}")
    if not isinstance(starts, (list, tuple)) or not starts:
        raise ValueError("starts: expected a non-empty list of (theta, mu_f, mu_t)")
    if any(not isinstance(st, (list, tuple)) or len(st) != 3 for st in starts):
        raise ValueError("starts: every start must be a (theta, mu_f, mu_t) triple")
    sigma2 = positive("sigma2", sigma2)
    max_iter = integer("max_iter", max_iter, minimum=1, maximum=MAX_LM_ITER)
    short = integer("short", short, minimum=1, maximum=max_iter)
    cands = [fit(prob, *st, sigma2, short) for st in starts]
    n_it = sum(c[4] for c in cands)
    best = min(cands, key=lambda c: c[3]["cost"])
    if not best[5]:
        best = fit(prob, *best[:3], sigma2, max_iter)
        n_it += best[4]
    return best, n_it
