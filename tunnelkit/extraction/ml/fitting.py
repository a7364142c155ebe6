"""The fit of the maximum-likelihood stage: Levenberg-Marquardt on the concentrated cost, the
stopping rule, the basin test and the SAGE-like re-seedings (docs/internals/extraction-ml.md),
in :func:`fit_problem` (on a :class:`~.model.Problem`; :func:`~.given_start.fit_ml` on a tensor,
the re-seedings on the residual energy in :mod:`.rho_reseed`); the result is an :class:`MLFit`."""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..._validate import integer, positive, record
from ...constants import C
from ..numerics import MIN_SIGNIFICANCE, spatial_phase_unchecked
from .lm import STEP_TOL, lm_fit, lm_with
from .model import W_MAX, Problem, project_feasible
from .residual import FALSE_ALARM, calibrated_threshold, residual_peak
from .resolution import (
    COUNTED_TWICE,
    PAIR_LLR,
    RESOLVE_Z,
    coherent_pair,
    pair_tests_at,
    separations,
    unresolved_partners,
)
from .resolution import significance as path_significance
from .search import SPLIT_STEPS, path_from_peak

__all__ = [
    "MAX_ITER",
    "RESOLVE_Z",
    "RHO_Z",
    "SCREEN_ITER",
    "SEARCHES",
    "STEP_TOL",
    "MLConvergenceWarning",
    "MLDetectionWarning",
    "MLFit",
    "fit_problem",
]

RHO_Z = 6.0  # basin test: sigmas of the chi-square statistic
#: cap on ``max_iter`` (Levenberg-Marquardt iterations per fit) and on ``n_reseed``: an iteration
#: is one pass over the tensor (~5-10 ms at M = 100, Nf = 410, Nt = 12); a fit that has not
#: converged in 1,000 is not converging, and more would take hours over a drive
MAX_ITER = 1000
#: the searches of :func:`fit_problem`
SEARCHES = ("residual", "basic")


_lm = lm_fit  # the fit's name for it


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
    ``converged`` the stopping rule was met; ``peak`` the largest peak of the residual's
    single-path periodogram in noise powers and ``peak_max`` its threshold at the false-alarm
    rate ``FALSE_ALARM`` (:mod:`.residual`, calibrated on noise-only tensors: the GLRT of one
    path more); ``detected`` (L,) each path's GLRT against that threshold (``significance >=
    peak_max``: the path would have been added from the noise with probability below
    ``FALSE_ALARM``); ``separation`` the smallest distance of two paths in standard deviations
    of their difference (:func:`~.resolved.pair_separation`), ``resolution`` (L,) each path's
    smallest distance to another (:func:`~.resolution.separations`; below ``RESOLVE_Z`` the path
    is in the threshold region of resolution); ``fit_ok`` the fit passed every test: the
    residual peak and ``rho`` below their thresholds, all ``L`` paths above the noise and every
    two paths resolved (``separation >= RESOLVE_Z``); ``reason`` the tests it failed
    (``"residual peak"``: a path missed or a wrong basin; ``"residual energy"``; ``"path below
    the noise"``; ``"unresolved pair"``: the threshold region of two paths closer than their
    bound can tell; ``"pair not resolved"``: the pair test), ``""`` when it passed; ``pairs``
    (P, 4) the pair test of each pair closer than ``PAIR_TEST_Z`` (rows ``(i, j, z, llr)``,
    :func:`~.resolved.pair_test`) and ``unresolved`` (L,) each path's partner in a pair whose
    ``llr`` is below ``PAIR_LLR`` (one path explains the two as well) or closer than
    ``RESOLVE_Z`` (:func:`~.resolution.unresolved_partners`: the CRLB of the two is not a bound
    the estimate can reach), ``-1`` when resolved."""

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
    peak: float = 0.0
    peak_max: float = np.inf
    fit_ok: bool = True
    detected: np.ndarray | None = field(default=None, repr=False)
    separation: float = np.inf
    reason: str = ""
    resolution: np.ndarray | None = field(default=None, repr=False)
    pairs: np.ndarray | None = field(default=None, repr=False)
    unresolved: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:  # theta inside the feasible set: the front half-space
        L = ("L",)
        record(self, shapes={"theta": (*L, 3), "mu_f": L, "mu_t": L, "alpha": L, "significance": L, "detected": L, "resolution": L, "pairs": (None, 4), "unresolved": L},
               nonnegative=("cost", "noise_power", "rho", "rho_max", "n_iter", "n_reseed", "peak", "peak_max", "separation", "resolution"),
               allow_inf=("peak_max", "separation", "resolution"), may_be_empty=("history", "reason"))  # fmt: skip
        r, w = np.hypot(self.theta[:, 0], self.theta[:, 1]), self.theta[:, 2]
        if np.any(r > 1) or np.any(w < 0) or np.any(w > W_MAX * (1 + 1e-9)):
            raise ValueError("theta: outside the front half-space |u| <= 1, 0 <= w <= W_MAX")


def _residual_of(prob: Problem, res):
    theta, mu_f, mu_t, ev = res[:4]
    return prob.H - prob.model(theta, mu_f, mu_t, ev["c"])


def _peak_of(prob: Problem, res, sigma2):
    fc = prob.k0 * C / (2 * np.pi)
    return residual_peak(_residual_of(prob, res), prob.pos, fc, sigma2)


#: Levenberg-Marquardt iterations each start of a re-initialisation gets before the starts are
#: ranked by their likelihood (the best one is then fitted to convergence)
RANK_ITER = 8
#: after the re-initialisation, a path below the noise starts the split move (:func:`_split_weak`)
SPLIT_WEAK = True
#: iterations of the first fit before the residual test screens it: a fit not converged by then
#: whose residual fails the test is re-initialised at once (the first fit goes on as one of the
#: ranked starts); one that passes goes on to ``max_iter`` exactly as without the screen
SCREEN_ITER = 16


def _peak_reseed(prob: Problem, best, sigma2, max_iter, peak, peak_max, n_moves, resume=None):
    """Re-initialisation on the residual (SAGE / RIMAX): while the residual's periodogram has a
    peak above ``peak_max``, a path is started there (its grid direction, delay and Doppler, a
    curvature scan and a single-source fit) and several starts are made from it: *birth and
    death* (all ``L + 1`` fitted, the least significant out) and *replace* (it takes the place
    of the path nearest to it in delay and Doppler, or of the least significant one). Each start
    gets ``RANK_ITER`` iterations; the most likely is fitted to convergence and kept if it beats
    the current fit. ``resume``: ``best`` is a fit stopped before convergence (its
    :func:`_lm` state): it goes on as one more start of the first move, and if it wins, that
    move is not counted. Returns the fit, its peak, the iterations spent and the kept moves."""
    n_it = kept = 0
    L = best[0].shape[0]
    short = min(RANK_ITER, max_iter)
    for _ in range(n_moves + (resume is not None)):
        if peak[0] <= peak_max:
            break
        theta, mu_f, mu_t, ev = best[:4]
        th_n, mf_n, mt_n = path_from_peak(prob, peak[1], peak[2])
        big = lm_with(prob, theta, mu_f, mu_t, (th_n, mf_n, mt_n), sigma2, short, _lm)
        n_it += big[4]
        keep = np.arange(L + 1) != int(np.argmin(path_significance(big[3], sigma2)))
        starts = [(big[0][keep], big[1][keep], big[2][keep])]
        near = _nearest_atom(prob, theta, mu_f, mu_t, th_n, mf_n, mt_n)
        out = _weakest(ev, sigma2)
        for worst in sorted({near, out}):  # the new path in place of the nearest, the weakest
            th2, mf2, mt2 = theta.copy(), mu_f.copy(), mu_t.copy()
            th2[worst], mf2[worst], mt2[worst] = th_n, mf_n, mt_n
            starts.append((th2, mf2, mt2))
        if near != out:  # the nearest split in two (a cluster fitted as one), the weakest out
            # halves an eighth of a beamwidth apart along each axis, and along the line from the
            # nearest path to the peak (a merged pair leaves its missing energy on that side)
            to_peak = np.asarray(peak[1][:2], float) - theta[near, :2]
            for du in (*SPLIT_STEPS, to_peak, 0.5 * to_peak):
                th2, mf2, mt2 = theta.copy(), mu_f.copy(), mu_t.copy()
                th2[out], mf2[out], mt2[out] = theta[near], mu_f[near], mu_t[near]
                th2[near, :2] += du
                th2[out, :2] -= du
                starts.append((project_feasible(th2), mf2, mt2))
        cands = [_lm(prob, *st, sigma2, short) for st in starts]
        if resume is not None:  # the first fit, stopped early, goes on as one more start
            cands.append(_lm(prob, theta, mu_f, mu_t, sigma2, short, resume))
        n_it += sum(c[4] for c in cands)
        i_best = min(range(len(cands)), key=lambda i: cands[i][3]["cost"])
        cand = cands[i_best]
        went_on = resume is not None and i_best == len(cands) - 1
        resume = None
        if not cand[5]:
            cand = _lm(prob, *cand[:3], sigma2, max_iter)
            n_it += cand[4]
        if not cand[3]["cost"] < ev["cost"]:
            break
        best, kept = cand, kept + (not went_on)
        peak = _peak_of(prob, best, sigma2)
    return best, peak, n_it, kept


#: :func:`_split_weak` on a pair: SPLIT_ROUNDS tries (kept at a cost fall of
#: :data:`~.split.PAIR_GAIN` sigma^2)
SPLIT_ROUNDS = 2


def _split_weak(prob: Problem, best, sigma2, max_iter, gain_min, flagged: bool = False):
    """The split move (:func:`~.split.split_weak`) when a path is below the noise
    (``MIN_SIGNIFICANCE``), two are closer than ``RESOLVE_Z`` or ``flagged`` (the residual test
    still fails after the re-initialisation on its peak); else ``best`` as it is. Returns the fit,
    the iterations and whether it was kept."""
    theta, mu_f, mu_t, ev = best[:4]
    L = theta.shape[0]
    if L < 2:
        return best, 0, False
    sig = path_significance(ev, sigma2)
    pair = sig.min() >= MIN_SIGNIFICANCE
    if pair:
        res = ev["resolution"] = separations(prob, theta, mu_f, mu_t, sigma2)  # kept with ev
        if res.min() >= RESOLVE_Z and not flagged:
            return best, 0, False
    from .split import split_weak  # loaded when a split is tried

    short = min(RANK_ITER, max_iter)
    return split_weak(prob, best, sigma2, sig, pair, gain_min, short, max_iter, fit=_lm)


def _nearest_atom(prob: Problem, theta, mu_f, mu_t, th_n, mf_n, mt_n) -> int:
    """The path whose atom is most like the new one ``(th_n, mf_n, mt_n)`` (normalised inner
    product, a product over the three modes)."""
    a = np.exp(1j * spatial_phase_unchecked(np.vstack([theta, th_n]), prob.pos, prob.k0)[0])
    ca = np.abs(a[:, :-1].conj().T @ a[:, -1]) / prob.M
    cf = np.abs(_dirichlet(mu_f - mf_n, prob.nf))
    ct = np.abs(_dirichlet(mu_t - mt_n, prob.nt))
    return int(np.argmax(ca * cf * ct))


def _dirichlet(dmu, n: int) -> np.ndarray:
    """``|sum_k e^{j k dmu}| / n`` for ``k = 0 .. n-1``."""
    k = np.arange(n)[:, None]
    return np.abs(np.sum(np.exp(1j * k * np.asarray(dmu)[None, :]), axis=0)) / n


def _weakest(ev, sigma2) -> int:
    """The weaker of the two most collinear atoms when two are nearly one (``|G_ij| / sqrt(G_ii
    G_jj) > COUNTED_TWICE``: a path counted twice), else the least significant path."""
    i, j, coh = coherent_pair(ev)
    if coh > COUNTED_TWICE:
        return int(j if abs(ev["c"][i]) >= abs(ev["c"][j]) else i)
    return int(np.argmin(path_significance(ev, sigma2)))


def fit_problem(
    prob: Problem,
    start,
    *,
    noise_power: float | None = None,
    max_iter: int = 60,
    n_reseed: int | None = None,
    search: str = "residual",
) -> MLFit:
    """:func:`~.given_start.fit_ml` on a :class:`~.model.Problem`, from ``start = (theta (L, 3),
    mu_f (L,), mu_t (L,))`` on the feasible set (:func:`~.given_start.check_start`,
    :func:`~.search.start_from_estimates` or :func:`~.rank_one.complete_paths` give one).

    ``search``: ``"residual"`` (default) — after the re-seedings on ``rho``, re-initialisation on
    the residual's periodogram peak while it fails the residual test (:func:`_peak_reseed`);
    ``"basic"`` — the re-seedings on ``rho`` alone (the route before the residual test existed,
    kept for comparison; the residual test is still computed for ``fit_ok``)."""
    if search not in SEARCHES:
        raise ValueError(f"search: expected one of {SEARCHES}, got {search!r}")
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
    max_iter = integer("max_iter", max_iter, minimum=1, maximum=MAX_ITER)
    n_reseed = L if n_reseed is None else integer("n_reseed", n_reseed, minimum=0, maximum=MAX_ITER)
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
    peak_max = calibrated_threshold(prob.pos, prob.k0 * C / (2 * np.pi), prob.H.shape, FALSE_ALARM)
    screen = bool(n_reseed) and search == "residual" and max_iter > SCREEN_ITER
    state: dict = {}
    if screen:
        best = _lm(prob, theta, mu_f, mu_t, sigma2, SCREEN_ITER, state)
    else:
        best = _lm(prob, theta, mu_f, mu_t, sigma2, max_iter)
    n_it, kept = best[4], 0
    resume = None
    if screen and not best[5]:
        # not converged after SCREEN_ITER iterations: a fit crawling in a wrong basin (clustered
        # paths merging) is re-initialised now, one on its way to the right optimum goes on
        peak = _peak_of(prob, best, sigma2)
        if peak[0] <= peak_max:
            more = _lm(prob, *best[:3], sigma2, max_iter - SCREEN_ITER, state)
            best = (*more[:4], best[4] + more[4], more[5])
            n_it = best[4]
        else:
            resume = state
    history = [best[3]["cost"] / (dof * sigma2)]
    if resume is None:
        peak = _peak_of(prob, best, sigma2)
    if n_reseed and search == "residual":
        best, peak, its, n_kept = _peak_reseed(
            prob, best, sigma2, max_iter, peak, peak_max, n_reseed, resume
        )
        n_it, kept = n_it + its, kept + n_kept
        history.append(best[3]["cost"] / (dof * sigma2))
    for _ in range(SPLIT_ROUNDS if n_reseed and search == "residual" and SPLIT_WEAK else 0):
        best, its, split = _split_weak(
            prob, best, sigma2, max_iter, peak_max * sigma2, flagged=peak[0] > peak_max
        )
        n_it, kept = n_it + its, kept + split
        if not split:
            break
        peak = _peak_of(prob, best, sigma2)
    if best[3]["cost"] / (dof * sigma2) > rho_max:
        from .rho_reseed import rho_reseed  # loaded when the basin test fails

        best, its, n_kept = rho_reseed(
            prob, best, sigma2, max_iter, n_reseed, rho_max * dof, history, dof, fit=_lm
        )
        n_it, kept = n_it + its, kept + n_kept
        if n_kept:
            peak = _peak_of(prob, best, sigma2)
    theta, mu_f, mu_t, ev, _, converged = best
    if not ev["cost"] < cost0 and not np.isclose(ev["cost"], cost0, rtol=1e-12, atol=0):
        warnings.warn(
            "fit_ml: the fit did not improve the likelihood of its start; the start is kept",
            MLConvergenceWarning,
            stacklevel=2,
        )
        theta, mu_f, mu_t, ev = (*start, ev0)
        peak = _peak_of(prob, (theta, mu_f, mu_t, ev), sigma2)
    if not np.all(np.isfinite(ev["c"])):
        raise FloatingPointError("fit_ml: non-finite gains (degenerate paths)")
    rho = float(ev["cost"] / (dof * sigma2))
    significance = path_significance(ev, sigma2)
    resolution = ev.get("resolution", None)  # at theta: ev is the evaluation there
    resolution = separations(prob, theta, mu_f, mu_t, sigma2) if resolution is None else resolution
    separation = float(np.min(resolution)) if resolution.size else float("inf")
    pairs, its = pair_tests_at(prob, theta, mu_f, mu_t, sigma2, ev, max_iter)
    n_it += its
    unresolved = unresolved_partners(pairs, L)
    failed = {
        "residual peak": peak[0] > peak_max,
        "residual energy": rho > rho_max,
        "path below the noise": not np.all(significance >= MIN_SIGNIFICANCE),
        "unresolved pair": not separation >= RESOLVE_Z,
        "pair not resolved": bool(np.any(pairs[:, 3] < PAIR_LLR)),
    }
    reason = ", ".join(k for k, v in failed.items() if v)
    fit_ok = not reason
    if peak[0] > peak_max:
        warnings.warn(
            f"fit_ml: the residual's periodogram peaks at {peak[0]:.0f} noise powers (test: "
            f"{peak_max:.1f} at false-alarm rate {FALSE_ALARM}): a path is missed or in a wrong "
            "basin (fit_ok = False)",
            MLConvergenceWarning,
            stacklevel=2,
        )
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
        significance,
        int(n_it),
        int(kept),
        bool(converged),
        history,
        float(peak[0]),
        float(peak_max),
        fit_ok,
        significance >= peak_max,
        float(separation),
        reason,
        resolution,
        pairs,
        unresolved,
    )
