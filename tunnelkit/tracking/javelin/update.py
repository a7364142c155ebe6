"""The variable-dimension EKF update (eq. 64-68) with the Joseph-form covariance.

From the pairs (track, path) left by association and track management we stack, per pair, the
rows ``phi, psi`` and ``kappa`` (if the path has a near-field curvature), and the TDoA rows
``Delta d_j = d_j - d_ref`` against a reference path (the LoS path when there is one, as in eq. 52
and Algorithm 1 line 13; otherwise, ours, the shortest associated path, since TDoAs between
reflections are clock-bias free too). The stacked vector is the sorted ``z`` of eq. 54.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_factor, cho_solve

from ..._validate import instance, probability
from ...crlb import wrap_angle
from ..gating import ChiSquareGate
from .config import JavelinConfig
from .measurement import KAPPA, PHI, PSI, RANGE, PathMeasurements, check_track_model
from .noise import FixedNoise

__all__ = ["StackedMeasurement", "exclude_inconsistent", "joseph_update", "stack_measurement"]


@dataclass
class StackedMeasurement:
    """``z``, ``h``, ``H`` (K, D), ``R`` (K, K), ``angle`` (K,) bool, row labels and the
    reference pair of the TDoAs (or ``None``)."""

    z: np.ndarray
    h: np.ndarray
    H: np.ndarray
    R: np.ndarray
    angle: np.ndarray
    labels: list[tuple[str, int, int]]
    reference: tuple[int, int] | None

    def residual(self) -> np.ndarray:
        """Innovation ``y = z - h(s)`` (eq. 64), azimuths wrapped."""
        y = self.z - self.h
        return np.where(self.angle, wrap_angle(y), y)


def stack_measurement(
    pred: np.ndarray,
    J: np.ndarray,
    meas: PathMeasurements,
    pairs,
    config: JavelinConfig,
    los_path: int | None = None,
    noise=None,
) -> StackedMeasurement:
    """Rows of eq. 44/54 for the given (track, path) pairs; ``pred``/``J`` from ``track_model``;
    ``noise`` the measurement-noise role (:mod:`~tunnelkit.tracking.javelin.roles`; default the
    paper's fixed sigmas) gives the covariance of every row."""
    pred, J = check_track_model(pred, J)
    instance("meas", meas, PathMeasurements)
    instance("config", config, JavelinConfig)
    noise = FixedNoise() if noise is None else noise
    if not callable(getattr(noise, "covariances", None)):
        raise TypeError(f"noise: expected a measurement-noise role, got {type(noise).__name__}")
    D = J.shape[-1]
    cov = noise.covariances(meas, config)
    z, h, H, blocks, ang, labels = [], [], [], [], [], []
    for i, j in pairs:
        comps = [PHI, PSI] + ([KAPPA] if np.isfinite(meas.kappa[j]) else [])
        zj = (meas.phi[j], meas.psi[j], meas.kappa[j])
        for c in comps:
            z.append(zj[c])
            h.append(pred[i, c])
            H.append(J[i, c])
            ang.append(c == PHI)
            labels.append((("phi", "psi", "kappa")[c], i, j))
        blocks.append(cov[j][np.ix_(comps, comps)])
    n_direct = len(z)
    with_d = [(i, j) for i, j in pairs if np.isfinite(meas.d[j])]
    ref = None
    if len(with_d) >= 2:
        los = [(i, j) for i, j in with_d if i == 0 and (los_path is None or j == los_path)]
        ref = los[0] if los else min(with_d, key=lambda p: meas.d[p[1]])
        ir, jr = ref
        for i, j in with_d:
            if (i, j) == ref:
                continue
            z.append(meas.d[j] - meas.d[jr])
            h.append(pred[i, RANGE] - pred[ir, RANGE])
            H.append(J[i, RANGE] - J[ir, RANGE])
            ang.append(False)
            labels.append(("delta_d", i, j))
    K = len(z)
    R = np.zeros((K, K))
    at = 0
    for b in blocks:
        R[at : at + len(b), at : at + len(b)] = b
        at += len(b)
    nd = K - n_direct
    if nd:
        others = [j for i, j in with_d if (i, j) != ref]
        R[n_direct:, n_direct:] = noise.tdoa_covariance(meas, others, jr, config)
    return StackedMeasurement(
        np.asarray(z, float),
        np.asarray(h, float),
        np.asarray(H, float).reshape(K, D),
        R,
        np.asarray(ang, bool),
        labels,
        ref,
    )


def joseph_update(
    x: np.ndarray, P: np.ndarray, m: StackedMeasurement
) -> tuple[np.ndarray, np.ndarray, float]:
    """EKF update of eq. 64-68; returns ``(x, P, nis)`` with the normalised innovation squared.

    ``P = (I - K H) P (I - K H)^T + K R K^T`` (Joseph form, eq. 68) stays symmetric positive
    semi-definite under rounding; we symmetrise once more against round-off.
    """
    instance("m", m, StackedMeasurement)
    if m.z.size == 0:
        return x.copy(), P.copy(), 0.0
    y = m.residual()
    S = m.H @ P @ m.H.T + m.R
    S = 0.5 * (S + S.T)
    cf = cho_factor(S, lower=True)
    K = cho_solve(cf, m.H @ P).T  # P H^T S^-1 (P symmetric)
    x_new = x + K @ y
    IKH = np.eye(x.size) - K @ m.H
    P_new = IKH @ P @ IKH.T + K @ m.R @ K.T
    nis = float(y @ cho_solve(cf, y))
    return x_new, 0.5 * (P_new + P_new.T), nis


def _nis(x: np.ndarray, P: np.ndarray, m: StackedMeasurement) -> float:
    """``y^T S^-1 y`` of the stacked measurement at the prior (0 without rows)."""
    if m.z.size == 0:
        return 0.0
    y = m.residual()
    S = m.H @ P @ m.H.T + m.R
    return float(y @ cho_solve(cho_factor(0.5 * (S + S.T), lower=True), y))


def exclude_inconsistent(
    x: np.ndarray,
    P: np.ndarray,
    pred: np.ndarray,
    J: np.ndarray,
    meas: PathMeasurements,
    pairs,
    config: JavelinConfig,
    los_path: int | None,
    probability: float,
    noise=None,
) -> tuple[StackedMeasurement, list[tuple[int, int]]]:
    """Fault detection and exclusion on the stacked update (ours, RAIM-like): while the joint
    innovation fails its chi-square test, ``y^T S^-1 y > chi2_K(probability)`` with ``K`` the
    number of rows, leave out the (track, path) pair whose removal lowers the normalised
    innovation most, and stack again. Catches what the per-pair gates of Algorithm 2 cannot: a
    wrong LoS from eq. 61 and the TDoA rows, which no gate sees. Returns the stacked measurement
    of the kept pairs and the pairs left out (in order). Raises ``numpy.linalg.LinAlgError`` if
    an innovation covariance is not positive definite (the tracker then skips the update)."""
    gate = ChiSquareGate(probability)
    pairs = list(pairs)
    out: list[tuple[int, int]] = []
    m = stack_measurement(pred, J, meas, pairs, config, los_path, noise)
    while m.z.size and _nis(x, P, m) > gate.threshold(int(m.z.size)):
        best = None
        for p in pairs:
            rest = [q for q in pairs if q != p]
            trial = stack_measurement(pred, J, meas, rest, config, los_path, noise)
            score = _nis(x, P, trial) / gate.threshold(max(int(trial.z.size), 1))
            if best is None or score < best[0]:
                best = (score, p, trial)
        _, p, m = best
        pairs.remove(p)
        out.append(p)
    return m, out


@dataclass(frozen=True)
class JosephUpdater:
    """The EKF update of eq. 64-68 with the Joseph-form covariance on every kept pair."""

    def stack(self, x, P, pred, J, meas, pairs, config, los_path, noise):
        """The stacked measurement of the pairs to update with and the pairs left out."""
        return stack_measurement(pred, J, meas, pairs, config, los_path, noise), []

    def update(self, x, P, m: StackedMeasurement):
        """``(x, P, nis)`` after the update (:func:`~.update.joseph_update`)."""
        return joseph_update(x, P, m)


@dataclass(frozen=True)
class JointTestUpdater(JosephUpdater):
    """The Joseph update after a chi-square test on the whole stacked innovation at
    ``probability``: while it fails, the pair whose removal lowers it most is left out (ours,
    RAIM-like: :func:`~.update.exclude_inconsistent`)."""

    probability: float = 0.999

    def __post_init__(self) -> None:
        p = probability("probability", self.probability)
        if ChiSquareGate(p).threshold(1) <= 0:
            raise ValueError(f"probability: too small to give a chi-square threshold, got {p!r}")

    def stack(self, x, P, pred, J, meas, pairs, config, los_path, noise):
        return exclude_inconsistent(
            x, P, pred, J, meas, pairs, config, los_path, self.probability, noise
        )
