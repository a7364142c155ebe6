"""Manufactured units: the design's Monte-Carlo as units x drives, and the unit yield.

A phase or gain calibration error is one fixed draw per manufactured array, not noise: every
drive of one unit sees the same draw. The design's Monte-Carlo therefore runs ``units`` units
of ``drives_per_unit`` drives each: unit ``u`` draws its calibration error from its own seed
(:func:`unit_seeds`, a stream apart from the drives'; every drive of the unit makes its own
generator from it, so all draw the same error), its drives ``d`` take the
drive streams ``u * drives_per_unit + d`` (:func:`drive_streams`), so a sweep extended by more
units reproduces the units it already ran.

What procurement asks is the share of units that meet the target on their own:

* **a unit's error quantile** (:func:`unit_quantiles`): the ``share``-quantile of its 2-D
  errors pooled over its drives and the counted epochs;
* **the unit yield** (:func:`unit_yield`): the share of units whose quantile is at or below the
  target, with the Wilson score interval over units (:func:`wilson_interval`; binomial, the
  units independent);
* **the verdict** (:func:`tunnelkit.design.verdict.judge`, by :func:`yield_verdict` here): met
  when the interval's lower end reaches the required yield, not met when its upper end is below
  it, undecided between (more units decide it); the recommendation the smallest array met
  (:func:`yield_recommendation`).
"""

from __future__ import annotations

import numpy as np

from .._checks import bound_array, real_array
from .._validate import finite_array, integer, positive, probability
from ..budget import check_elements

__all__ = [
    "drive_streams",
    "unit_quantiles",
    "unit_rmse",
    "unit_seeds",
    "unit_yield",
    "wilson_interval",
]

#: the spawn-key tag that sets the units' calibration streams apart from the drives'
_UNIT_TAG = 0x0417CA1


def unit_seeds(seed, first: int, n: int) -> list[np.random.SeedSequence]:
    """The calibration seeds of units ``first .. first + n - 1`` of ``seed`` (an int or a
    Generator, not advanced): unit ``u``'s seed is the same whatever batch it runs in. A seed,
    not a generator, is what a unit's drives share: each drive makes its own generator from it
    and draws the same calibration error (a generator shared in one process would hand its
    second drive the next draw)."""
    first = integer("first", first, minimum=0)
    n = integer("n", n, minimum=1)
    if isinstance(seed, np.random.Generator):
        ss = seed.bit_generator.seed_seq
        entropy, key = ss.entropy, tuple(ss.spawn_key)
    else:
        entropy, key = integer("seed", seed, minimum=0), ()
    return [
        np.random.SeedSequence(entropy, spawn_key=(*key, _UNIT_TAG, u))
        for u in range(first, first + n)
    ]


def drive_streams(first: int, units: int, drives_per_unit: int) -> list[int]:
    """The drive streams of units ``first .. first + units - 1``: drive ``d`` of unit ``u`` is
    stream ``u * drives_per_unit + d``, in unit order."""
    first = integer("first", first, minimum=0)
    units = integer("units", units, minimum=1)
    d = integer("drives_per_unit", drives_per_unit, minimum=1)
    check_elements("units, drives_per_unit", units * d, 64, f"{units} units x {d} drives' streams")
    return [u * d + i for u in range(first, first + units) for i in range(d)]


def wilson_interval(k: int, n: int, level: float = 0.95) -> list[float]:
    """The Wilson score interval ``[lo, hi]`` of a binomial share from ``k`` successes in ``n``
    trials at ``level`` (coverage close to nominal down to a few units, and never outside
    [0, 1], unlike the normal interval)."""
    from scipy.stats import norm

    n = integer("n", n, minimum=1)
    k = integer("k", k, minimum=0, maximum=n)
    level = probability("level", level)
    z = float(norm.ppf(0.5 + level / 2))
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    lo = 0.0 if k == 0 else max(0.0, mid - half)
    hi = 1.0 if k == n else min(1.0, mid + half)  # (exact at the ends, not 1 - 1e-16)
    return [float(lo), float(hi)]


def unit_quantiles(errors, drives_per_unit: int, counted, share: float) -> np.ndarray:
    """Each unit's ``share``-quantile (U,) [m] of ``errors`` (U * drives_per_unit, T) [m] (the
    drives in unit order, :func:`drive_streams`), pooled over its drives and the ``counted``
    epochs; a non-finite error (no estimate) counts as infinite
    (:func:`tunnelkit.design.verdict.share_quantile`)."""
    share = probability("share", share, open_interval=False)
    return np.quantile(_unit_rows(errors, drives_per_unit, counted), share, axis=1,
                       method="inverted_cdf")  # fmt: skip


def unit_rmse(errors, drives_per_unit: int, counted) -> np.ndarray:
    """Each unit's RMSE (U,) [m] over its drives and the ``counted`` epochs of ``errors`` (as
    :func:`unit_quantiles`; a non-finite error counts as infinite, and so does the unit's RMSE):
    what :func:`tunnelkit.design.intervals.paired_rmse_ratio` pairs across a sweep's rows."""
    return np.sqrt(np.mean(_unit_rows(errors, drives_per_unit, counted) ** 2, axis=1))


def _unit_rows(errors, drives_per_unit, counted) -> np.ndarray:
    """``errors`` (U * drives_per_unit, T) checked, non-finite as +inf, at the ``counted``
    epochs, one row per unit (U, drives_per_unit * len(counted))."""
    d = integer("drives_per_unit", drives_per_unit, minimum=1)
    e = real_array("errors", errors, ndim=2)
    if e.shape[0] % d or not e.size:
        raise ValueError(
            f"errors, drives_per_unit: expected (units x {d} drives, T), got shape {e.shape}"
        )
    if np.any(e < 0):
        raise ValueError("errors: a position error is not negative")
    k = finite_array("counted", counted, ndim=1)
    if not k.size or np.any(k != np.round(k)) or k.min() < 0 or k.max() >= e.shape[1]:
        raise ValueError(f"counted: expected epoch indices in [0, {e.shape[1]}), got {k!r}")
    k = k.astype(int)
    return np.where(np.isfinite(e), e, np.inf)[:, k].reshape(e.shape[0] // d, -1)


def unit_yield(unit_q, target: float, level: float = 0.95) -> tuple[float, list[float]]:
    """The share of units whose quantile ``unit_q`` (U,) is at or below ``target`` [m], and its
    Wilson interval at ``level``."""
    q = bound_array("unit_q", unit_q, ndim=1, empty=False)
    target = positive("target", target)
    k = int(np.sum(q <= target))
    return k / q.size, wilson_interval(k, q.size, level)


# the verdict and the recommendation by the unit yield (design.verdict's judge and recommend, on
# arguments they checked): not exported


def yield_verdict(target, units, yield_, ci, required, pct, cap, min_units) -> tuple[str, str]:
    """:func:`~tunnelkit.design.verdict.judge` once units ran: ``(status, reason)`` from the
    unit yield ``yield_`` and its interval ``ci = (lo, hi)`` over ``units`` units, ``pct`` the
    share in words, ``min_units`` the fewest units whose interval decides."""
    lo, hi = ci
    head = (
        f"{100 * yield_:.3g} % of {units} units meet {target:g} m on {pct} of the settled "
        f"route, 95 % CI [{100 * lo:.3g}, {100 * hi:.3g}] %"
    )
    need = f"the required {100 * required:g} %"
    if units < min_units:
        return "undecided", f"{head}: too few units for the interval to decide (>= {min_units})"
    if lo >= required:
        return "met", f"{head}: at least {need}"
    if hi < required:
        return "not met", f"{head}: below {need}"
    tail = f"the cap of {cap} units reached" if cap is not None and units >= cap else "add units"
    return "undecided", f"{head} straddles {need}: {tail}"


def yield_recommendation(order, target, pct, required) -> dict:
    """:func:`~tunnelkit.design.verdict.recommend` once units ran: the smallest of the
    candidates ``order`` (smallest first) whose unit yield reaches ``required``."""
    met = [r for r in order if r.status == "met"]
    smaller_open = [
        r.array
        for r in order
        if r.status == "undecided" and (not met or order.index(r) < order.index(met[0]))
    ]
    goal = f"{100 * required:g} % of units within {target:g} m on {pct} of the settled route"
    if met:
        best = met[0]
        why = f"the smallest candidate whose unit yield reaches {goal}: {best.reason}"
        if smaller_open:
            why += f"; smaller {', '.join(smaller_open)} undecided"
        return {"array": best.array, "basis": "unit-yield", "reason": why}
    if smaller_open:
        why = f"none met yet; undecided: {', '.join(smaller_open)}"
    else:
        why = f"no candidate's unit yield reaches {goal}"
    return {"array": None, "basis": "unit-yield", "reason": why}
