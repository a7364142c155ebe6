"""Data association of Algorithm 2: gated costs, greedy nearest neighbour and a global variant.

For every (track i, path j) pair the three rows ``(phi, psi, kappa)`` of the Jacobian give the
innovation covariance ``S_ij = H_i P H_i^T + R`` (eq. 56), the innovation ``y_ij`` (eq. 57) and
``eta^2`` (eq. 58). A far-field path (no curvature) uses its two angular rows only. The paper
then picks, among gated pairs, the one with the smallest distance, removes its track and path,
and repeats (:func:`greedy_nearest_neighbour`). :func:`global_nearest_neighbour` instead minimises
the sum of distances over all one-to-one assignments (scipy's ``linear_sum_assignment``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..._checks import unchecked
from ..._validate import finite_array, instance, record
from ...angles import wrap_angle
from ..gating import ChiSquareGate, mahalanobis2
from .measurement import PathMeasurements, check_track_model

__all__ = [
    "AssociationCosts",
    "Associator",
    "association_costs",
    "global_nearest_neighbour",
    "greedy_nearest_neighbour",
]


@dataclass
class AssociationCosts:
    """``eta2`` (n_tracks, n_paths), ``dof`` (n_paths,), ``gated`` (n_tracks, n_paths) bool;
    ``cost`` what the associators minimise (``eta2`` unless set: see :func:`association_costs`)."""

    eta2: np.ndarray
    dof: np.ndarray
    gated: np.ndarray
    threshold: np.ndarray
    cost: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.cost is None:
            self.cost = self.eta2
        ln = ("L", "n")
        record(self, shapes={"eta2": ln, "dof": ("n",), "gated": ln, "threshold": ("n",),
                             "cost": ln},
               nonnegative=("eta2", "dof", "threshold"), allow_inf=("eta2", "cost"))  # fmt: skip


def association_costs(
    pred: np.ndarray,
    J: np.ndarray,
    P: np.ndarray,
    meas: PathMeasurements,
    R3: np.ndarray,
    gate: ChiSquareGate,
    cost: str = "mahalanobis",
) -> AssociationCosts:
    """Squared Mahalanobis distance of every track-path pair (Algorithm 2, lines 2-9).

    ``pred`` (L, 4) and ``J`` (L, 4, D) come from :func:`measurement.track_model`; ``R3`` is the
    3x3 covariance of ``(phi, psi, kappa)``, or (n, 3, 3), one per path. Vectorised over pairs: a missing curvature is
    handled by zeroing its innovation and setting its row/column of ``S`` to the identity, which
    leaves ``eta^2`` equal to the 2-component distance.

    ``cost="mahalanobis"`` (the paper, section 3.3) ranks pairs by ``eta^2``;
    ``cost="likelihood"`` (ours) by the negative log-likelihood ``eta^2 + ln det S_angles``
    (``S_angles`` the ``(phi, psi)`` block, which every path carries, so pairs with and without
    a curvature are ranked on the same terms). The second
    stops a wide new track (``P = sigma_P^2 I`` at birth) from taking a path that an established
    track predicts well: its large ``S`` makes ``eta^2`` small, but ``ln det S`` large.
    """
    pred, J = check_track_model(pred, J)
    instance("meas", meas, PathMeasurements)
    instance("gate", gate, ChiSquareGate)
    if isinstance(P, str) or np.ndim(P) != 2 or np.shape(P) != (J.shape[-1], J.shape[-1]):
        raise ValueError(
            f"P: expected the ({J.shape[-1]}, {J.shape[-1]}) state covariance, got shape {np.shape(P)}"
        )
    finite_array("P", P)
    if finite_array("R3", R3).shape not in ((3, 3), (len(meas), 3, 3)):
        raise ValueError(f"R3: expected shape (3, 3) or ({len(meas)}, 3, 3), got {np.shape(R3)}")
    L, n = pred.shape[0], len(meas)
    if n == 0 or L == 0:
        e = np.zeros((L, n))
        return unchecked(AssociationCosts, e, np.zeros(n, int), e.astype(bool), np.zeros(n), e)
    H3 = J[:, :3, :]
    R3 = np.asarray(R3, dtype=float)
    per_path = R3.ndim == 3  # (n, 3, 3): each path's reported covariance
    S0 = H3 @ P @ np.swapaxes(H3, 1, 2) + (0.0 if per_path else R3)  # (L, 3, 3)
    z = meas.triples()  # (n, 3)
    has_k = np.isfinite(z[:, 2])
    y = z[None, :, :] - pred[:, None, :3]  # (L, n, 3)
    y[..., 0] = wrap_angle(y[..., 0])
    y[..., 2] = np.where(has_k[None, :], y[..., 2], 0.0)
    S = S0[:, None] + R3[None] if per_path else np.broadcast_to(S0[:, None], (L, n, 3, 3)).copy()
    nk = ~has_k
    S[:, nk, 2, :] = 0.0
    S[:, nk, :, 2] = 0.0
    S[:, nk, 2, 2] = 1.0
    eta2 = mahalanobis2(y, S)
    dof = np.where(has_k, 3, 2)
    thr = np.array([gate.threshold(int(k)) for k in dof])
    gated = np.isfinite(eta2) & (eta2 < thr)  # ChiSquareGate.accepts with the quantiles at hand
    if cost == "mahalanobis":
        return unchecked(AssociationCosts, eta2, dof, gated, thr, eta2)
    if cost != "likelihood":
        raise ValueError(f"cost: expected 'mahalanobis' or 'likelihood', got {cost!r}")
    # ln det over the components every pair carries (the angles): a far-field path has no
    # curvature row, and ln det of the full S would hand it a bonus of -ln S_kappa (about -11 at
    # a curvature sigma of 300 m), enough to take a track's path from the LoS it predicts
    lndet = np.linalg.slogdet(S[..., :2, :2])[1]
    return unchecked(AssociationCosts, eta2, dof, gated, thr, eta2 + lndet)


def greedy_nearest_neighbour(costs: AssociationCosts) -> list[tuple[int, int]]:
    """Algorithm 2 + the NN choice of section 3.3: repeatedly take the gated pair of smallest
    cost (``eta^2`` in the paper), then drop its track and its path. Returns
    ``[(track, path), ...]``."""
    instance("costs", costs, AssociationCosts)
    eta = np.where(costs.gated, costs.cost, np.inf)
    pairs = []
    while eta.size and np.isfinite(eta).any():
        i, j = np.unravel_index(np.argmin(eta), eta.shape)
        pairs.append((int(i), int(j)))
        eta[i, :] = np.inf
        eta[:, j] = np.inf
    return sorted(pairs)


def global_nearest_neighbour(costs: AssociationCosts) -> list[tuple[int, int]]:
    """The one-to-one assignment of gated pairs with the smallest total cost (ours).

    Ungated pairs get a cost above any gated total, so they are chosen only when nothing else
    fits and are then dropped; the result is the maximum-cardinality, minimum-cost matching.
    """
    instance("costs", costs, AssociationCosts)
    if costs.eta2.size == 0 or not costs.gated.any():
        return []
    # shift to non-negative costs (a log-likelihood cost can be negative), then price every
    # ungated pair above any gated total
    c = costs.cost - np.min(np.where(costs.gated, costs.cost, np.inf), initial=0.0)
    big = float(np.sum(np.where(costs.gated, c, 0.0))) + 1.0
    cost = np.where(costs.gated, c, big * 10.0)
    rows, cols = linear_sum_assignment(cost)
    return sorted((int(i), int(j)) for i, j in zip(rows, cols) if costs.gated[i, j])


_SOLVERS: dict[str, Callable[[AssociationCosts], list[tuple[int, int]]]] = {
    "greedy": greedy_nearest_neighbour,
    "gnn": global_nearest_neighbour,
}


@dataclass(frozen=True)
class Associator:
    """Gated costs (eq. 56-59) and a solver: ``cost`` ``"mahalanobis"`` (the paper's ``eta^2``)
    or ``"likelihood"`` (``eta^2 + ln det S``, ours); ``solver`` ``"greedy"`` (Algorithm 2) or
    ``"gnn"`` (global nearest neighbour, ours)."""

    cost: str = "mahalanobis"
    solver: str = "greedy"

    def __post_init__(self) -> None:
        if self.cost not in ("mahalanobis", "likelihood"):
            raise ValueError(f"cost: expected 'mahalanobis' or 'likelihood', got {self.cost!r}")
        if self.solver not in _SOLVERS:
            raise ValueError(f"solver: expected one of {tuple(_SOLVERS)}, got {self.solver!r}")

    def __call__(
        self, pred, J, P, meas: PathMeasurements, R3, gate: ChiSquareGate
    ) -> tuple[AssociationCosts, list[tuple[int, int]]]:
        """The costs of every (track, path) pair and the chosen ``[(track, path), ...]``."""
        costs = association_costs(pred, J, P, meas, R3, gate, self.cost)
        return costs, _SOLVERS[self.solver](costs)
