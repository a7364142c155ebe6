"""The filters' gate (EKF, UKF, UPF, Doppler KF): an outlier becomes a missed epoch, and the
gate reopens.

A measurement ``z`` with innovation ``y = z - h(x_prior)`` (bearings wrapped) and innovation
covariance ``S`` (``H P H^T + R`` for the (E)KF, the unscented ``S`` for the UKF and UPF) passes
when its squared Mahalanobis distance ``d2 = y^T S^-1 y`` is below the chi-square quantile
``chi2_m(p)``, ``m`` the length of ``z`` (the degrees of freedom of ``d2`` for a consistent filter).
A rejected measurement is treated as a missed epoch (the filter predicts only) and counted in
``n_rejected``. With ``p = 0.999`` a consistent filter loses one good measurement in a thousand.

**Reopening.** While measurements are rejected the covariance grows with ``Q``, so a real change
(a manoeuvre, a clock step) usually passes again once ``S`` has grown. Not always: an unmodelled
acceleration ``a`` makes the position innovation grow like ``a t^2 / 2``, faster than
``sqrt(S) ~ sqrt(q t^3 / 3)``, and such a gate would never reopen. So after ``reopen_after``
consecutive rejections the gate takes the next measurement anyway, with the prior covariance
inflated by the factor ``alpha`` that makes the innovation consistent: with ``A = S - R`` (the
state's share of ``S``), ``alpha = (d2 tr(S) / chi2_m(p) - tr(R)) / tr(A)``, which solves
``y^2 = chi2_1(p) (alpha A + R)`` exactly for one measurement (at least 1); ``n_reopened``
counts these. An isolated outlier costs one
predict-only epoch; a burst of more than ``reopen_after`` outliers gets through (probability
``p_out^(reopen_after + 1)`` for independent outliers) and is then corrected the same way.
"""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, instance, integer, text
from .._validate import probability as check_probability
from ..budget import check_elements
from .gating import DEFAULT_GATE, ChiSquareGate, squared_distances

__all__ = [
    "ACCEPT",
    "DEFAULT_GATE",
    "DEFAULT_REOPEN_AFTER",
    "REJECT",
    "REOPEN",
    "InnovationGate",
    "gated_filterpy_update",
]

#: consecutive rejections after which the next measurement is taken with an inflated covariance
DEFAULT_REOPEN_AFTER = 5

#: the verdicts of :meth:`InnovationGate.judge`
ACCEPT, REJECT, REOPEN = 0, 1, 2


class InnovationGate:
    """:class:`ChiSquareGate` on ``d2 = y^T S^-1 y`` with reopening, for the filters;
    ``probability=None`` switches it off.

    ``batch`` (None for one filter) keeps one set of counters per independent run (the batched
    UPF). ``n_rejected`` and ``n_reopened`` are ints, or arrays of shape (batch,).
    """

    def __init__(
        self,
        probability: float | None = DEFAULT_GATE,
        *,
        reopen_after: int = DEFAULT_REOPEN_AFTER,
        batch: int | None = None,
        name: str = "gate",
    ) -> None:
        name = text("name", name)
        self.probability = (
            None
            if probability is None
            else check_probability(f"{name} (the gate probability)", probability)
        )
        self.test = None if probability is None else ChiSquareGate(self.probability)
        self.reopen_after = integer("reopen_after", reopen_after, minimum=1)
        shape = () if batch is None else (integer("batch", batch, minimum=1),)
        check_elements("batch", 8 * int(np.prod(shape)), what="the gate's batch")
        self._rejected = np.zeros(shape, dtype=int)
        self._reopened = np.zeros(shape, dtype=int)
        self._streak = np.zeros(shape, dtype=int)

    @property
    def enabled(self) -> bool:
        return self.probability is not None

    @property
    def n_rejected(self):
        """Measurements rejected so far (predicted only)."""
        return int(self._rejected) if self._rejected.ndim == 0 else self._rejected.copy()

    @property
    def n_reopened(self):
        """Measurements taken with an inflated covariance after ``reopen_after`` rejections."""
        return int(self._reopened) if self._reopened.ndim == 0 else self._reopened.copy()

    def threshold(self, dof: int) -> float:
        """``chi2_dof(p)``: 10.83 for one degree of freedom at p = 0.999, 18.47 for four."""
        if self.test is None:
            return np.inf
        return self.test.threshold(dof)

    def judge(self, d2, dof: int, rows=None) -> np.ndarray:
        """Verdict per measurement (``ACCEPT``, ``REJECT`` or ``REOPEN``) and update the counters.

        ``d2`` is a scalar for one filter, or (len(rows),) for the batch rows ``rows`` (all rows
        when None). A non-finite ``d2`` is rejected.
        """
        d2 = squared_distances(d2)
        if type(dof) is not int or dof < 1:  # plain ints pass without the general check
            dof = integer("dof", dof, minimum=1)
        if rows is not None and (
            isinstance(rows, str | bytes) or np.asarray(rows).dtype.kind not in "iub"
        ):
            raise TypeError(
                f"rows: expected batch row indices (integers or a mask), got {rows!r:.40}"
            )
        idx = ... if rows is None else rows
        if self.probability is None:
            return np.zeros(d2.shape, dtype=int)
        out = ~(np.isfinite(d2) & (d2 <= self.threshold(dof)))
        streak = self._streak[idx]
        reopen = out & (streak >= self.reopen_after) & np.isfinite(d2)
        reject = out & ~reopen
        self._rejected[idx] = self._rejected[idx] + reject
        self._reopened[idx] = self._reopened[idx] + reopen
        self._streak[idx] = np.where(reject, streak + 1, 0)
        return np.where(reopen, REOPEN, np.where(reject, REJECT, ACCEPT))

    def inflation(self, d2, dof: int, S, R) -> np.ndarray:
        """Covariance factor of a reopened measurement (module docstring), at least 1.

        ``S`` (..., m, m) is the innovation covariance, ``R`` (m, m) the measurement noise.
        """
        S = finite_array("S", S)
        if S.ndim < 2 or S.shape[-1] != S.shape[-2]:
            raise ValueError(f"S: expected square matrices (..., m, m), got shape {S.shape}")
        R = finite_array("R", R, shape=S.shape[-2:])
        d2 = squared_distances(d2)
        if not np.isfinite(d2).all():
            raise ValueError("d2: a reopened measurement has a finite distance, got NaN or inf")
        dof = integer("dof", dof, minimum=1)
        trS = np.trace(S, axis1=-2, axis2=-1)
        trR = float(np.trace(R))
        trA = np.maximum(trS - trR, 1e-12 * np.maximum(trS, 1e-300))
        return np.maximum(1.0, (d2 * trS / self.threshold(dof) - trR) / trA)


def gated_filterpy_update(f, update, gate: InnovationGate, *, redraw=None) -> int:
    """Run ``update()`` (a filterpy ``update`` call on filter ``f``) behind ``gate``; the verdict.

    filterpy computes the innovation ``f.y`` and ``f.SI = S^-1`` at the prior inside ``update``,
    so the update is made, ``d2 = y^T S^-1 y`` read from it, and undone if the gate rejects: the
    prior becomes the posterior, as for ``update(None)``. On ``REOPEN`` the prior covariance is
    scaled by :meth:`InnovationGate.inflation` (``redraw()`` then rebuilds whatever depends on it,
    e.g. a UKF's sigma points) and the update is made again.
    """
    instance("gate", gate, InnovationGate)
    if redraw is not None and not callable(redraw):
        raise TypeError(f"redraw: expected a callable or None, got {type(redraw).__name__}")
    if not (hasattr(f, "x") and hasattr(f, "P")):
        raise TypeError(f"f: expected a filterpy filter (with x and P), got {type(f).__name__}")
    if not callable(update):
        raise TypeError(f"update: expected a callable, got {type(update).__name__}")
    if not gate.enabled:
        update()
        return ACCEPT
    x, P = f.x.copy(), f.P.copy()
    update()
    y = np.ravel(f.y)
    d2 = float(y @ np.asarray(f.SI) @ y)
    verdict = int(gate.judge(d2, y.size))
    if verdict == ACCEPT:
        return verdict
    f.x, f.P = x, P
    if verdict == REJECT:
        f.x_post, f.P_post = x.copy(), P.copy()
        f.z = np.array([[None] * y.size]).T
        return verdict
    f.P = float(gate.inflation(d2, y.size, f.S, f.R)) * P
    if redraw is not None:
        redraw()
    update()
    return verdict
