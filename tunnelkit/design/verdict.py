"""Deciding a candidate array from what the system achieves, on plain arrays of errors (the same
for the bound-driven and the channel Monte-Carlo).

The counted epochs (:func:`counted_epochs`), the criterion (:data:`CRITERIA`, :func:`gate`), the
error quantile (:func:`share_quantile`; its 95 % interval: :mod:`tunnelkit.design.intervals`),
the verdict per array by the unit yield (:func:`judge`, the sequential rule's defaults
:data:`REQUIRED_YIELD`, :data:`DRIVES_PER_UNIT`, :data:`MAX_UNITS`) and the recommendation
(:func:`recommend`). Bounds and predictions never decide.

How it works: docs/internals/design.md.
"""

from __future__ import annotations

import numpy as np

from .._checks import real_array
from .._validate import (
    finite_array,
    integer,
    nonnegative,
    positive,
    probability,
    sequence,
)
from ..settling import SETTLE_S

__all__ = [
    "CRITERIA",
    "DRIVES_PER_UNIT",
    "MAX_UNITS",
    "MIN_RUNS_CI",
    "REQUIRED_YIELD",
    "STATUSES",
    "counted_epochs",
    "gate",
    "judge",
    "recommend",
    "share_quantile",
]

#: the pass/fail criteria: the design's VUE-curvature tracker, or a route using eq. 51
CRITERIA = ("achievable", "srnf")
#: fewer units than this: the interval is reported but never decides (a warning says so)
MIN_RUNS_CI = 10
#: verdicts of :func:`judge`, and ``"error"`` for a candidate that could not be evaluated
STATUSES = ("met", "undecided", "not met", "bound only", "error")
#: the default share of manufactured units that must meet the target on their own
REQUIRED_YIELD = 0.95
#: the default cap of the sequential rule: units per array at most
MAX_UNITS = 200
#: the default drives per unit (a unit's own quantile pools its drives' settled epochs)
DRIVES_PER_UNIT = 2


def counted_epochs(t, settle: float = SETTLE_S) -> np.ndarray:
    """Indices of the epochs that count: those of ``t`` [s] at least ``settle`` [s] after its
    start (the tracker's start-up from the entry fix left out); refused when none is left."""
    t = finite_array("t", t, ndim=1)
    settle = nonnegative("settle", settle)
    if not t.size:
        raise ValueError("t: expected at least one epoch time")
    idx = np.flatnonzero(t - t[0] >= settle - 1e-9)
    if not idx.size:
        raise ValueError(
            f"settle: {settle:g} s leaves no epoch of a {t[-1] - t[0]:.3g} s drive to count; "
            "give a shorter settle window or a longer route"
        )
    return idx


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


def judge(
    target: float,
    *,
    units: int = 0,
    yield_: float | None = None,
    ci: list | None = None,
    required: float = REQUIRED_YIELD,
    share: float = 0.9,
    cap: int | None = None,
) -> tuple[str, str]:
    """``(status, reason)`` of one candidate (docs/internals) from its unit yield ``yield_``
    and the yield's 95 % interval ``ci`` over ``units`` units (``units = 0``: no Monte-Carlo,
    ``"bound only"``); ``cap`` the sequential rule's cap (``None``: no cap stated)."""
    target = positive("target", target)
    units = integer("units", units, minimum=0)
    share = probability("share", share, open_interval=False)
    required = probability("required", required)
    if cap is not None:
        cap = integer("cap", cap, minimum=1)
    if yield_ is not None:
        yield_ = probability("yield_", yield_, open_interval=False)
    if ci is not None:
        if len(sequence("ci", ci)) != 2:
            raise ValueError(f"ci: expected a [lo, hi] interval, got {ci!r}")
        lo = probability("ci", ci[0], open_interval=False)
        hi = probability("ci", ci[1], open_interval=False)
        if yield_ is not None and not lo <= yield_ <= hi:
            raise ValueError(f"ci: expected [lo, hi] around yield_ = {yield_!r}, got {ci!r}")
    pct = f"{100 * share:g} %"
    if units == 0:
        return "bound only", (
            "no Monte-Carlo: bounds and predictions only, which decide nothing (give --units)"
        )
    if yield_ is None or ci is None:
        raise ValueError("ci: give the unit yield and its [lo, hi] interval when units > 0")
    from .units import yield_verdict  # the verdict by the unit yield, loaded when units ran

    return yield_verdict(target, units, yield_, (lo, hi), required, pct, cap, MIN_RUNS_CI)


def recommend(
    rows, target: float, share: float, units: int, required: float = REQUIRED_YIELD
) -> dict:
    """The recommendation from candidates with ``.array``, ``.n_elements``,
    ``.aperture_diagonal_m``, ``.status``, ``.reason``: ``{array, reason, basis}``; ``basis``
    is ``"unit-yield"`` (the smallest candidate whose unit yield's interval reaches
    ``required``) or ``"none"`` (no Monte-Carlo: no recommendation)."""
    # no rows: every candidate failed (reported per array): "no candidate", not an error
    rows, target = sequence("rows", rows, empty=True), positive("target", target)
    share = probability("share", share, open_interval=False)
    units = integer("units", units, minimum=0)
    required = probability("required", required)
    pct = f"{100 * share:g} %"
    order = sorted(rows, key=lambda r: (r.n_elements, r.aperture_diagonal_m))
    if units == 0:
        return {
            "array": None,
            "basis": "none",
            "reason": (
                "no Monte-Carlo (units 0): the bounds and predictions decide nothing; give "
                "--units to decide by the unit yield"
            ),
        }
    from .units import yield_recommendation  # the choice by the unit yield, when units ran

    return yield_recommendation(order, target, pct, required)
