"""Deciding a candidate array from what the system achieves: the criterion, the error quantile
with its bootstrap interval, the verdict per array and the recommendation.

Everything here works on plain arrays, so it is the same whether the errors come from the
bound-driven or the channel Monte-Carlo.

* **Counted epochs**: the settled epochs of the drive (:func:`tunnelkit.metrics.settled`, the
  first :data:`~tunnelkit.metrics.SETTLE_S` left out: the tracker's start-up from a coarse fix
  is not the array's accuracy); the whole route if it is shorter than that.
* **The criterion** says which epochs can count as met. ``"achievable"`` (the design's
  tracker, which models a reflection's wavefront on its virtual UE) scores every counted epoch;
  SR-NF validity is reported as information. ``"srnf"`` (a route that uses eq. 51, the
  wavefront centred on the reflection point) also requires SR-NF validity: an epoch where a
  used path breaks it counts as an infinite error (:func:`gate`).
* **The error quantile** (:func:`share_quantile`): the ``share``-quantile
  (``method="inverted_cdf"``, an observed value: it is <= the target exactly when the share of
  values <= the target is >= ``share``) of the per-epoch 2-D error, pooled over runs and over the
  counted epochs. A non-finite error (no estimate) counts as infinite. This is the ``*_p90_m`` of
  the report at the default ``share = 0.9``.
* **Its 95 % interval** (:func:`bootstrap_quantile_ci`): percentile bootstrap over runs (whole
  drives resampled with replacement, an explicit :class:`numpy.random.Generator`), since the
  epochs of one drive are correlated.
* **The pre-screen** (:func:`implied_quantile`): the error quantile an estimator *at* the
  achievable bound would have, each counted epoch's 2-D error a circular Gaussian whose RMS is
  the bound there. A bound's own quantile is not a lower bound of the error's quantile (a
  1-cm bound on 89 % of the route and 20 cm elsewhere still lets 90 % of the errors lie under
  5 cm); this one is the quantile of an estimator that attains the bound everywhere.
  Under impairments the screen takes the PEB with the achievable bound's impairments' part
  halved (:func:`screen_bound`): the tracker averages over the drive the share of a
  snapshot's calibration bias that does not repeat, so the implied quantile of the full bound
  would skip a candidate the tracker meets. Why one half, measured (28 GHz example, 4 x 4 ...
  32 x 32, 20 runs, seed 0, 0.5 and 2 deg phase error; ``q``: the implied 90 % quantile of the
  PEB with the impairments' part): the tracker's error p90 is 0.78-1.08 ``q`` and the lower
  end of its 95 % interval 0.58-0.91 ``q`` (the smallest, 0.58, 4 x 4 at 0.5 deg: p90 82.6 mm,
  interval [61.5, 112] mm, ``q`` 105.7 mm); the halved part puts the screen at 0.50-0.54 ``q``,
  below every interval's lower end, so no candidate whose interval can reach below the target
  is skipped (the full part would have skipped that 4 x 4, whose interval straddles 0.1 m).
  With no impairment the screen is the PEB (unchanged; the tracker's interval starts at 0.91
  ``q`` or above there).
* **The verdict** (:func:`judge`): ``"hopeless"`` when that implied quantile misses the target
  (its Monte-Carlo is skipped); ``"bound only"`` with no Monte-Carlo;
  ``"met"`` only when the interval's upper end is below the target; ``"not met"`` when its lower
  end is at or above it; ``"undecided"`` when it straddles the target or when fewer than
  :data:`MIN_RUNS_CI` runs stand behind it (a 2-run interval is not an answer).
* **The recommendation** (:func:`recommend`): the smallest candidate (fewest elements, then
  aperture) that is met; with bounds only, the smallest that passes the pre-screen, said to be
  a necessary condition, not an answer.
"""

from __future__ import annotations

import numpy as np

from .._checks import bound, bound_array, real_array
from .._validate import finite_array, integer, positive, probability, rng_or_error, sequence

__all__ = [
    "CRITERIA",
    "MIN_RUNS_CI",
    "STATUSES",
    "bootstrap_quantile_ci",
    "counted_epochs",
    "gate",
    "implied_quantile",
    "judge",
    "recommend",
    "screen_bound",
    "share_quantile",
]

#: the pass/fail criteria: the design's VUE-curvature tracker, or a route using eq. 51
CRITERIA = ("achievable", "srnf")
#: fewer runs than this: the interval is reported but never decides (a warning says so)
MIN_RUNS_CI = 10
#: verdicts of :func:`judge`, and ``"error"`` for a candidate that could not be evaluated
STATUSES = ("met", "undecided", "not met", "hopeless", "bound only", "error")


def counted_epochs(t) -> np.ndarray:
    """Indices of the epochs that count: the settled ones of ``t`` [s], all if none settle."""
    from ..metrics import settled

    t = finite_array("t", t, ndim=1)
    idx = settled(t)
    return idx if idx.size else np.arange(t.size)


def gate(values, srnf_valid, criterion: str) -> np.ndarray:
    """``values`` (..., T) with the criterion applied: for ``"srnf"`` an epoch where SR-NF does
    not hold (``srnf_valid`` (T,) False) becomes ``inf``; ``"achievable"`` leaves them."""
    if criterion not in CRITERIA:
        raise ValueError(f"criterion: expected one of {CRITERIA}, got {criterion!r}")
    real_array("values", values)
    v = np.asarray(values, float)
    ok = np.asarray(srnf_valid, bool)
    if ok.shape != v.shape[-1:]:
        raise ValueError(f"srnf_valid: expected shape {v.shape[-1:]}, got {ok.shape}")
    return v if criterion == "achievable" else np.where(ok, v, np.inf)


def share_quantile(values, share: float) -> float:
    """The ``share``-quantile of ``values`` (any shape, pooled), non-finite counted as ``inf``;
    ``method="inverted_cdf"``: the smallest observed ``q`` with at least ``share`` of the values
    <= ``q`` (so ``inf`` once fewer than ``share`` are finite)."""
    share = probability("share", share, open_interval=False)
    real_array("values", values)
    v = np.asarray(values, float).ravel()
    if not v.size:
        raise ValueError("values: expected at least one value")
    if np.any(v < 0):
        raise ValueError("values: errors and bounds are not negative")
    v = np.where(np.isfinite(v), v, np.inf)
    return float(np.quantile(v, share, method="inverted_cdf"))


def implied_quantile(bounds, share: float) -> float:
    """The ``share``-quantile of the 2-D error of an estimator that attains ``bounds`` (T,) [m]
    at every epoch: each epoch's error a circular Gaussian with ``E|e|^2 = bound^2``, so
    ``P(|e| <= x) = 1 - exp(-x^2 / bound^2)``, pooled over the epochs (a non-finite bound is an
    epoch never met). Solved by bisection on the pooled distribution function."""
    share = probability("share", share, open_interval=False)
    bound_array("bounds", bounds, ndim=1)
    b = np.asarray(bounds, float).ravel()
    if not b.size:
        raise ValueError("bounds: expected at least one value")
    if np.any(b < 0):
        raise ValueError("bounds: a bound is not negative")
    fin = np.isfinite(b)
    if fin.mean() < share:
        return float("inf")
    bf = b[fin]

    def cdf(x: float) -> float:
        with np.errstate(divide="ignore"):
            return float(np.sum(1.0 - np.exp(-(x**2) / np.where(bf > 0, bf**2, 1e-300)))) / b.size

    lo, hi = 0.0, max(float(bf.max()), 1e-12)
    while cdf(hi) < share:
        hi *= 2.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cdf(mid) < share else (lo, mid)
    return hi


def bootstrap_quantile_ci(
    errors, share: float, rng: np.random.Generator, *, n_boot: int = 2000, level: float = 0.95
) -> list[float]:
    """Percentile-bootstrap ``level`` interval of :func:`share_quantile` of ``errors``
    (runs, T): runs resampled with replacement (``n_boot`` resamples from ``rng``), the pooled
    quantile of each resample, and the ``(1 -+ level) / 2`` quantiles of those. One run gives
    the degenerate interval ``[q, q]`` (callers warn; :func:`judge` never decides on it)."""
    rng = rng_or_error("rng", rng)
    share = probability("share", share, open_interval=False)
    level = probability("level", level)
    n_boot = integer("n_boot", n_boot, minimum=1)
    real_array("errors", errors)
    e = np.asarray(errors, float)
    if e.ndim != 2 or not e.size:
        raise ValueError(f"errors: expected (runs, T) with runs, T >= 1, got shape {e.shape}")
    if np.any(e < 0):
        raise ValueError("errors: a position error is not negative")
    e = np.where(np.isfinite(e), e, np.inf)
    runs, T = e.shape
    draws = rng.integers(0, runs, size=(n_boot, runs))
    qs = np.empty(n_boot)
    step = max(1, 2_000_000 // (runs * T))  # bounded memory per chunk
    for i in range(0, n_boot, step):
        block = e[draws[i : i + step]].reshape(-1, runs * T)
        qs[i : i + step] = np.quantile(block, share, axis=1, method="inverted_cdf")
    p = [(1 - level) / 2, (1 + level) / 2]
    if np.all(np.isfinite(qs)):
        lo, hi = np.quantile(qs, p, method="linear")
    else:  # inf - inf has no interpolation: the bracketing order statistics
        lo, hi = np.quantile(qs, p[0], method="lower"), np.quantile(qs, p[1], method="higher")
    return [float(lo), float(hi)]


#: the share of the achievable bound's impairment part the pre-screen keeps (module docstring:
#: measured, the screen then lies below the lower end of every tracker interval, 0.58 of the
#: PEB-with-impairments quantile at the smallest)
SCREEN_IMPAIRMENT_SCALE = 0.5


def _bounds(name: str, v) -> np.ndarray:
    """A 1-D array of bounds [m]: real, >= 0, ``inf`` allowed, NaN refused."""
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected real numbers, got {type(v).__name__}") from None
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"{name}: expected a non-empty 1-D array, got shape {a.shape}")
    if np.isnan(a).any() or (a < 0).any():
        raise ValueError(f"{name}: expected bounds >= 0 (inf allowed), got NaN or a negative")
    return a


def screen_bound(peb, achievable) -> np.ndarray:
    """The per-epoch bound the pre-screen takes (module docstring):
    ``sqrt(peb^2 + s^2 (achievable^2 - peb^2))`` with ``s`` :data:`SCREEN_IMPAIRMENT_SCALE`
    (the PEB where the two are equal; ``inf`` where the achievable bound is). The design sweep
    passes as ``achievable`` the PEB with the achievable bound's impairments' part only (its
    noise part, the tracker's block-weighted fix, is not an impairment)."""
    p, a = _bounds("peb", peb), _bounds("achievable", achievable)
    if p.shape != a.shape:
        raise ValueError(f"achievable: expected shape {p.shape} like peb, got {a.shape}")
    with np.errstate(invalid="ignore"):
        extra = np.clip(a**2 - p**2, 0.0, None)
        out = np.sqrt(p**2 + SCREEN_IMPAIRMENT_SCALE**2 * extra)
    return np.where(np.isinf(a), np.inf, out)


def judge(
    target: float,
    bound_q: float,
    *,
    runs: int = 0,
    error_q: float | None = None,
    ci: list | None = None,
    share: float = 0.9,
) -> tuple[str, str]:
    """``(status, reason)`` of one candidate (module docstring): ``bound_q`` the error quantile
    implied by the achievable bound (:func:`implied_quantile`) over the counted epochs,
    ``error_q`` and ``ci`` the Monte-Carlo error's quantile and interval from ``runs`` drives
    (``runs = 0``: none)."""
    target = positive("target", target)
    runs = integer("runs", runs, minimum=0)
    share = probability("share", share, open_interval=False)
    bound("bound_q", bound_q)
    if error_q is not None:
        bound("error_q", error_q)
    if ci is not None and len(sequence("ci", ci)) != 2:
        raise ValueError(f"ci: expected a [lo, hi] interval, got {ci!r}")
    if ci is not None:
        bound("ci", ci[0]), bound("ci", ci[1])
    if np.isnan(bound_q) or bound_q < 0:
        raise ValueError(f"bound_q: expected a quantile >= 0 (inf allowed), got {bound_q!r}")
    pct = f"{100 * share:g} %"
    if not bound_q <= target:
        return "hopeless", (
            f"even an estimator at the achievable bound would err by more than {target:g} m on "
            f"{100 - 100 * share:g} % of the route or more (its {pct} quantile {_m(bound_q)}): "
            "Monte-Carlo skipped"
        )
    if runs == 0:
        return "bound only", (
            f"an estimator at the achievable bound would stay within {_m(bound_q)} <= {target:g} m"
            f" on {pct} of the route: a necessary condition only (no Monte-Carlo)"
        )
    if error_q is None or ci is None:
        raise ValueError("error_q: give the Monte-Carlo quantile and its interval when runs > 0")
    lo, hi = ci
    if not lo <= error_q <= hi:
        raise ValueError(f"ci: expected [lo, hi] around error_q = {error_q!r}, got {ci!r}")
    head = f"error on {pct} of the settled route {_m(error_q)}, 95 % CI [{_m(lo)}, {_m(hi)}]"
    if runs < MIN_RUNS_CI:
        return "undecided", (
            f"{head} from {runs} run{'s' * (runs != 1)}: too few for the interval to decide "
            f"(use >= {MIN_RUNS_CI})"
        )
    if hi < target:
        return "met", f"{head} below {target:g} m"
    if lo >= target:
        return "not met", f"{head} at or above {target:g} m"
    return "undecided", f"{head} straddles {target:g} m: add runs"


def recommend(rows, target: float, share: float, runs: int) -> dict:
    """The recommendation from candidates with ``.array``, ``.n_elements``,
    ``.aperture_diagonal_m``, ``.status``, ``.reason``: ``{array, reason, basis}``; ``basis``
    is ``"monte-carlo"`` or ``"bounds"`` (no runs: a necessary condition, not an answer)."""
    # no rows: every candidate failed (reported per array): "no candidate", not an error
    rows, target = sequence("rows", rows, empty=True), positive("target", target)
    share = probability("share", share, open_interval=False)
    runs = integer("runs", runs, minimum=0)
    pct = f"{100 * share:g} %"
    order = sorted(rows, key=lambda r: (r.n_elements, r.aperture_diagonal_m))
    if runs == 0:
        ok = [r for r in order if r.status == "bound only"]
        if ok:
            return {
                "array": ok[0].array,
                "basis": "bounds",
                "reason": (
                    f"rests on bounds only: {ok[0].array} is the smallest candidate whose "
                    f"achievable bound meets {target:g} m on {pct} of the route, a necessary "
                    "condition, not an answer; run the Monte-Carlo (--runs 20) to decide"
                ),
            }
        return {
            "array": None,
            "basis": "bounds",
            "reason": f"no candidate's achievable bound meets {target:g} m on {pct} of the route",
        }
    met = [r for r in order if r.status == "met"]
    smaller_open = [
        r.array
        for r in order
        if r.status == "undecided" and (not met or order.index(r) < order.index(met[0]))
    ]
    if met:
        best = met[0]
        why = f"smallest candidate met: {best.reason}"
        if smaller_open:
            why += f"; smaller {', '.join(smaller_open)} undecided (add runs)"
        return {"array": best.array, "basis": "monte-carlo", "reason": why}
    if smaller_open:
        why = f"none met yet; undecided: {', '.join(smaller_open)} (add runs)"
    else:
        why = f"no candidate meets {target:g} m on {pct} of the settled route"
    return {"array": None, "basis": "monte-carlo", "reason": why}


def _m(v: float) -> str:
    """A length for a sentence: ``inf`` or 3 significant digits in m."""
    return "inf" if not np.isfinite(v) else f"{v:.3g} m"
