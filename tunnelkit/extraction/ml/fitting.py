"""The fit of the maximum-likelihood stage: Levenberg-Marquardt on the concentrated cost, the
stopping rule, the basin test and the SAGE-like re-seedings (package text of
:mod:`tunnelkit.extraction.ml`), in :func:`fit_problem` (on a :class:`~.model.Problem`) and
:func:`fit_ml` (on a tensor); the result is an :class:`MLFit`."""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..._validate import integer, positive
from ..decomposition import check_tensor
from ..numerics import damped_step, free_newton
from ..radio import check_array, check_srs
from .model import W_MAX, Problem, project_feasible
from .search import check_start, search_path

__all__ = [
    "RHO_Z",
    "SPLIT_STEPS",
    "STEP_TOL",
    "MLConvergenceWarning",
    "MLDetectionWarning",
    "MLFit",
    "fit_ml",
    "fit_problem",
]

STEP_TOL = 1e-4  # Newton decrement in units of sigma^2 (0.01 standard deviations)
RHO_Z = 6.0  # basin test: sigmas of the chi-square statistic


class MLConvergenceWarning(RuntimeWarning):
    """The maximum-likelihood stage could not improve on its start (the start is returned), or
    its residual stays above the noise floor after the re-seedings (basin test failed)."""


class MLDetectionWarning(RuntimeWarning):
    """Fewer paths than ``n_paths`` stand above the noise (the rest have ``valid = False``)."""


@dataclass(frozen=True)
class MLFit:
    """The joint fit: ``theta`` (L, 3) = ``(u_x, u_y, w = 1/kappa)``, ``mu_f``, ``mu_t`` (rad),
    ``alpha`` the gains, ``cost = ||r||^2``, ``noise_power`` (estimated or given), ``rho`` the
    residual over the noise floor (1 at the right optimum), ``rho_max`` the basin test's
    threshold, ``significance`` (L,) each path's log-likelihood ratio against noise,
    ``n_iter`` Levenberg-Marquardt iterations in all, ``n_reseed`` kept re-seedings,
    ``converged`` the stopping rule was met."""

    theta: np.ndarray
    mu_f: np.ndarray
    mu_t: np.ndarray
    alpha: np.ndarray
    cost: float
    noise_power: float
    rho: float
    rho_max: float
    significance: np.ndarray
    n_iter: int
    n_reseed: int
    converged: bool
    history: list = field(default_factory=list, repr=False)


def _lm(prob: Problem, theta, mu_f, mu_t, sigma2, max_iter: int):
    """Levenberg-Marquardt on the concentrated cost; returns the best point and its evaluation."""
    L = theta.shape[0]
    ev = prob.evaluate(theta, mu_f, mu_t)
    lam, it, converged = 1e-3, 0, False
    for it in range(1, max_iter + 1):  # noqa: B007
        lower = np.zeros((L, 5), bool)
        lower[:, 2] = theta[:, 2] <= 0.0
        upper = np.zeros((L, 5), bool)
        upper[:, 2] = theta[:, 2] >= W_MAX
        # Newton decrement: the cost decrease a full Gauss-Newton step promises, in sigma^2
        free, dec = free_newton(ev["A"], ev["g"], lower.ravel(), upper.ravel())
        if dec < STEP_TOL * sigma2:
            converged = True
            break
        step = damped_step(ev["A"], ev["g"], free, lam)
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
        else:
            lam *= 4.0
            if lam > 1e10:
                converged = True  # no descent direction left at working precision
                break
    return theta, mu_f, mu_t, ev, it, converged


def _birth_death(prob: Problem, theta, mu_f, mu_t, ev, sigma2, max_iter):
    """One path more, sought in the pure residual; all ``L + 1`` fitted jointly; the least
    significant one out and the ``L`` fitted again (a path missed while another was counted
    twice, or two paths merged, leave a structured residual that this move picks up)."""
    r = prob.H - prob.model(theta, mu_f, mu_t, ev["c"])
    th_n, mf_n, mt_n = search_path(r, prob)
    big = _lm(
        prob,
        np.vstack([theta, th_n]),
        np.append(mu_f, mf_n),
        np.append(mu_t, mt_n),
        sigma2,
        max_iter,
    )
    keep = np.arange(theta.shape[0] + 1) != int(np.argmin(_significance(big[3], sigma2)))
    res = _lm(prob, big[0][keep], big[1][keep], big[2][keep], sigma2, max_iter)
    return res, big[4] + res[4]


#: offsets in (u_x, u_y) of the two halves of a split path (an eighth of a 10 x 10 beamwidth)
SPLIT_STEPS = ((0.012, 0.0), (0.0, 0.012))


def _merge_and_split(prob, theta, mu_f, mu_t, ev, sigma2, max_iter, cost_ok, coherence=0.9):
    """If two atoms are nearly collinear (one path counted twice, ``|G_ij| / sqrt(G_ii G_jj) >
    coherence``): drop the weaker, fit the ``L - 1``, then split one of them into two halves
    ``u -+ SPLIT_STEPS`` (two sources closer than a beamwidth fitted as one) and fit all ``L``;
    the first split whose cost is below ``cost_ok`` (the basin test), else the best. ``None``
    when no two atoms are that alike."""
    G = ev["G"]
    dg = np.sqrt(np.maximum(np.real(np.diag(G)), 1e-300))
    coh = np.abs(G) / np.outer(dg, dg)
    np.fill_diagonal(coh, 0.0)
    i, j = np.unravel_index(int(np.argmax(coh)), coh.shape)
    if coh[i, j] < coherence:
        return None
    drop = j if abs(ev["c"][i]) >= abs(ev["c"][j]) else i
    keep = np.arange(theta.shape[0]) != drop
    th, mf, mt, ev_s, its, _ = _lm(prob, theta[keep], mu_f[keep], mu_t[keep], sigma2, max_iter)
    best = None
    for l_ in np.argsort(-np.abs(ev_s["c"])):
        for du in SPLIT_STEPS:
            t2 = np.vstack([th, th[l_]])
            t2[l_, :2] += du
            t2[-1, :2] -= du
            mf2, mt2 = np.append(mf, mf[l_]), np.append(mt, mt[l_])
            res = _lm(prob, project_feasible(t2), mf2, mt2, sigma2, max_iter)
            its += res[4]
            if best is None or res[3]["cost"] < best[3]["cost"]:
                best = res
            if best[3]["cost"] <= cost_ok:
                return best, its
    return best, its


def _significance(ev, sigma2) -> np.ndarray:
    """Per path: the cost increase if it were removed (gains re-projected), over ``sigma2``."""
    Gi = np.linalg.pinv(ev["G"])
    return np.abs(ev["c"]) ** 2 / np.maximum(np.real(np.diag(Gi)), 1e-300) / sigma2


def fit_ml(
    H,
    start,
    array,
    srs,
    *,
    noise_power: float | None = None,
    max_iter: int = 60,
    n_reseed: int | None = None,
) -> MLFit:
    """Joint maximum-likelihood fit of ``L`` paths started at ``start = (theta, mu_f, mu_t)``.

    ``theta`` (L, 3) is ``(u_x, u_y, 1/kappa)`` per path (local frame, ``|u| < 1``, ``w >= 0``);
    ``mu_f``, ``mu_t`` (L,) the Vandermonde frequencies. ``noise_power`` per sample (default:
    estimated, :func:`~.model.noise_floor`). ``n_reseed`` bounds the SAGE-like re-seedings (default
    ``L``; 0 = local fit only). ``array`` and ``srs`` as in
    :func:`~tunnelkit.extraction.extract_paths` (only the carrier of ``srs`` enters). See the
    package text for the algorithm.
    """
    H = check_tensor(H)
    pos = check_array(array, m=H.shape[0])
    srs = check_srs(srs)
    L = np.atleast_2d(np.asarray(start[0])).shape[0]
    start = check_start(start, L)
    return fit_problem(
        Problem(H, pos, srs.fc),
        start,
        noise_power=noise_power,
        max_iter=max_iter,
        n_reseed=n_reseed,
    )


def fit_problem(
    prob: Problem,
    start,
    *,
    noise_power: float | None = None,
    max_iter: int = 60,
    n_reseed: int | None = None,
) -> MLFit:
    """:func:`fit_ml` on a :class:`~.model.Problem`, from ``start = (theta (L, 3), mu_f (L,),
    mu_t (L,))`` on the feasible set (:func:`~.search.check_start`,
    :func:`~.search.start_from_estimates` or :func:`~.search.complete_paths` give one)."""
    if not isinstance(prob, Problem):
        raise TypeError(f"prob: expected a Problem, got {type(prob).__name__}")
    try:
        theta, mu_f, mu_t = start
    except (TypeError, ValueError) as exc:
        raise ValueError("start: expected a tuple (theta, mu_f, mu_t)") from exc
    theta, mu_f, mu_t = (np.asarray(v) for v in (theta, mu_f, mu_t))
    L = theta.shape[0] if theta.ndim == 2 else -1
    if theta.shape != (L, 3) or mu_f.shape != (L,) or mu_t.shape != (L,):
        raise ValueError(
            f"start: expected theta (L, 3), mu_f (L,), mu_t (L,); got "
            f"{theta.shape}, {mu_f.shape}, {mu_t.shape}"
        )
    max_iter = integer("max_iter", max_iter, minimum=1)
    n_reseed = L if n_reseed is None else integer("n_reseed", n_reseed, minimum=0)
    H = prob.H
    M, L = H.shape[0], theta.shape[0]
    start = (theta, mu_f, mu_t)
    bias = 0.0
    if noise_power is None:
        sigma2 = prob.noise_floor(L)
        nt, rest = (H.shape[2], M * H.shape[1]) if L < H.shape[2] else (M, H.shape[1] * H.shape[2])
        n_sigma = (nt - L) * (rest - L)
        # the L largest eigenvalues also take the largest noise eigenvalues of the directions
        # the signal barely occupies (paths sharing a Doppler bin): up to ~ L sqrt(nt/rest)/(nt-L)
        bias = 0.5 * L * np.sqrt(nt / rest) / (nt - L)
    else:
        sigma2 = positive("noise_power", noise_power)
        n_sigma = np.inf
    sigma2 = max(sigma2, 1e-300 * max(prob.h2, 1e-300))
    dof = prob.N - 2.5 * L
    rho_max = 1.0 + RHO_Z * np.sqrt(1.0 / prob.N + 1.0 / n_sigma) + bias

    ev0 = prob.evaluate(theta, mu_f, mu_t, derivatives=False)
    cost0 = ev0["cost"]
    best = _lm(prob, theta, mu_f, mu_t, sigma2, max_iter)
    n_it, kept = best[4], 0
    history = [best[3]["cost"] / (dof * sigma2)]
    tried: set = set()
    split_tried = False
    for attempt in range(n_reseed):
        theta, mu_f, mu_t, ev = best[:4]
        if ev["cost"] / (dof * sigma2) <= rho_max:
            break
        merged = None
        if not split_tried:  # one path counted twice: merge it, split another (once)
            merged = _merge_and_split(prob, theta, mu_f, mu_t, ev, sigma2, max_iter, rho_max * dof)
        if merged is not None:
            cand, its = merged
            split_tried = True
        elif attempt % 2 == 0:  # birth and death: a path from the residual, the weakest out
            cand, its = _birth_death(prob, theta, mu_f, mu_t, ev, sigma2, max_iter)
        else:  # the weakest path re-sought in the residual plus its own contribution
            sig = _significance(ev, sigma2)
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
            cand = _lm(prob, th2, mf2, mt2, sigma2, max_iter)
            its = cand[4]
        n_it += its
        history.append(cand[3]["cost"] / (dof * sigma2))
        if cand[3]["cost"] < ev["cost"]:
            best, kept = cand, kept + 1
            tried = set()
    theta, mu_f, mu_t, ev, _, converged = best
    if not ev["cost"] < cost0 and not np.isclose(ev["cost"], cost0, rtol=1e-12, atol=0):
        warnings.warn(
            "fit_ml: the fit did not improve the likelihood of its start; the start is kept",
            MLConvergenceWarning,
            stacklevel=2,
        )
        theta, mu_f, mu_t, ev = (*start, ev0)
    if not np.all(np.isfinite(ev["c"])):
        raise FloatingPointError("fit_ml: non-finite gains (degenerate paths)")
    rho = float(ev["cost"] / (dof * sigma2))
    if rho > rho_max:
        warnings.warn(
            f"fit_ml: the residual stays {rho:.4f} times the noise floor (test: {rho_max:.4f}) "
            "after the re-seedings: a path may be missed or merged, or n_paths is too small",
            MLConvergenceWarning,
            stacklevel=2,
        )
    return MLFit(
        theta,
        np.angle(np.exp(1j * mu_f)),
        np.angle(np.exp(1j * mu_t)),
        ev["c"],
        float(ev["cost"]),
        float(sigma2),
        rho,
        float(rho_max),
        _significance(ev, sigma2),
        int(n_it),
        int(kept),
        bool(converged),
        history,
    )
