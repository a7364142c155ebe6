"""The variable-dimension EKF update (eq. 64-68) with the Joseph-form covariance.

:func:`stack_measurement` stacks the associated pairs into the sorted ``z`` of eq. 54
(:class:`StackedMeasurement`); :func:`joseph_update` updates; a bias-aware tracker (ours) updates
as a Schmidt-Kalman consider filter (:mod:`tunnelkit.tracking.javelin.consider`, loaded when a
tracker carries biases); :class:`JosephUpdater` and :class:`JointTestUpdater` are the updater
roles.

How it works, and why consider rather than estimate the biases: docs/internals/tracking.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_factor, cho_solve

from ..._checks import unchecked
from ..._validate import finite_array, instance, integer, probability, record, sequence
from ...angles import wrap_angle
from ..gating import ChiSquareGate
from .config import JavelinConfig
from .measurement import KAPPA, PHI, PSI, RANGE, PathMeasurements, check_track_model
from .noise import FixedNoise

__all__ = [
    "StackedMeasurement",
    "exclude_inconsistent",
    "joseph_update",
    "stack_measurement",
]


def state_arguments(x, P, D: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A filter's state ``x`` (D,) and covariance ``P`` (D, D): finite, of matching sizes."""
    x = finite_array("x", x, ndim=1)
    if D is not None and x.size != D:
        raise ValueError(f"x: expected {D} entries (the state's dimension), got {x.size}")
    return x, finite_array("P", P, shape=(x.size, x.size))


@dataclass
class StackedMeasurement:
    """One update's stacked rows (eq. 54 of the associated pairs only, with the model and its
    noise; the epoch's paths themselves are a :class:`~.measurement.PathMeasurements`): ``z``,
    ``h``, ``H`` (K, D), ``R`` (K, K), ``angle`` (K,) bool, row labels and the
    reference pair of the TDoAs (or ``None``); for a consider filter ``B`` (K, 4 L_hat), the
    rows' sensitivity to every track's normalised bias (``R`` then the white share only)."""

    z: np.ndarray
    h: np.ndarray
    H: np.ndarray
    R: np.ndarray
    angle: np.ndarray
    labels: list[tuple[str, int, int]]
    reference: tuple[int, int] | None
    B: np.ndarray | None = None

    def __post_init__(self) -> None:
        rows = ("K",)
        record(self, shapes={"z": rows, "h": rows, "H": ("K", None), "R": ("K", "K"),
                             "angle": rows, "labels": rows, "reference": (2,)},
               may_be_empty=("labels",), skip=("B",))  # fmt: skip
        if self.B is not None:
            self.B = finite_array("B", self.B, ndim=2)
            if self.B.shape[0] != np.size(self.z):
                raise ValueError(f"B: expected one row per measured row ({np.size(self.z)})")

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
    C: np.ndarray | None = None,
) -> StackedMeasurement:
    """Rows of eq. 44/54 for the given (track, path) pairs; ``pred``/``J`` from ``track_model``;
    ``noise`` the measurement-noise role (:mod:`~tunnelkit.tracking.javelin.roles`; default the
    paper's fixed sigmas) gives the covariance of every row. With a consider cross-covariance
    ``C`` (D, 4 L_hat) and a noise role that splits off the repeating share
    (:class:`~.consider.ConsiderNoise`), ``R`` is the white share and ``B`` the rows' map of the
    tracks' normalised biases (a TDoA row ``L_j[d] u_i - L_ref[d] u_ref``)."""
    pred, J = check_track_model(pred, J)
    sequence("pairs", pairs, empty=True)
    if los_path is not None:
        integer("los_path", los_path, minimum=0)
    instance("meas", meas, PathMeasurements)
    instance("config", config, JavelinConfig)
    noise = FixedNoise() if noise is None else noise
    if not callable(getattr(noise, "covariances", None)):
        raise TypeError(f"noise: expected a measurement-noise role, got {type(noise).__name__}")
    D = J.shape[-1]
    if C is not None:
        C = finite_array("C", C, ndim=2)
        if C.shape[0] != D:
            raise ValueError(f"C: expected {D} rows (one per state entry), got {C.shape[0]}")
    consider = C is not None and getattr(noise, "consider", False)
    if consider:
        cov = noise.white_covariances(meas, config)
        Lf = noise.factors(meas)
    else:
        cov = noise.covariances(meas, config)
    z, h, H, blocks, ang, labels = [], [], [], [], [], []
    brow = []  # per row: [(track, path, component, sign)]
    for i, j in pairs:
        comps = [PHI, PSI] + ([KAPPA] if np.isfinite(meas.kappa[j]) else [])
        zj = (meas.phi[j], meas.psi[j], meas.kappa[j])
        for c in comps:
            z.append(zj[c])
            h.append(pred[i, c])
            H.append(J[i, c])
            ang.append(c == PHI)
            labels.append((("phi", "psi", "kappa")[c], i, j))
            brow.append([(i, j, c, 1.0)])
        blocks.append(cov[j][: len(comps), : len(comps)])  # comps: (PHI, PSI[, KAPPA]) = 0, 1[, 2]
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
            brow.append([(i, j, RANGE, 1.0), (ir, jr, RANGE, -1.0)])
    K = len(z)
    R = np.zeros((K, K))
    at = 0
    for b in blocks:
        R[at : at + len(b), at : at + len(b)] = b
        at += len(b)
    nd = K - n_direct
    if nd:
        others = [j for i, j in with_d if (i, j) != ref]
        tdoa = noise.white_tdoa_covariance if consider else noise.tdoa_covariance
        R[n_direct:, n_direct:] = tdoa(meas, others, jr, config)
    B = None
    if consider:
        B = np.zeros((K, C.shape[1]))
        for r, terms in enumerate(brow):
            for i, j, c, sign in terms:
                B[r, 4 * i : 4 * i + 4] += sign * Lf[j, c]
    # rows computed here from checked arguments: the record built unchecked (the step's loop)
    return unchecked(
        StackedMeasurement,
        np.asarray(z, float),
        np.asarray(h, float),
        np.asarray(H, float).reshape(K, D),
        R,
        np.asarray(ang, bool),
        labels,
        ref,
        B,
    )


def joseph_update(
    x: np.ndarray, P: np.ndarray, m: StackedMeasurement
) -> tuple[np.ndarray, np.ndarray, float]:
    """EKF update of eq. 64-68; returns ``(x, P, nis)`` with the normalised innovation squared.

    ``P = (I - K H) P (I - K H)^T + K R K^T`` (Joseph form, eq. 68) stays symmetric positive
    semi-definite under rounding; we symmetrise once more against round-off.
    """
    instance("m", m, StackedMeasurement)
    state_arguments(x, P, m.H.shape[1] if m.z.size else None)
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


def _nis(x: np.ndarray, P: np.ndarray, m: StackedMeasurement, C=None) -> float:
    """``y^T S^-1 y`` of the stacked measurement at the prior (0 without rows); with consider
    parameters ``S`` includes ``H C B^T + B C^T H^T + B B^T``."""
    if m.z.size == 0:
        return 0.0
    y = m.residual()
    S = m.H @ P @ m.H.T + m.R
    if m.B is not None and C is not None:
        HCB = m.H @ C @ m.B.T
        S = S + HCB + HCB.T + m.B @ m.B.T
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
    C=None,
) -> tuple[StackedMeasurement, list[tuple[int, int]]]:
    """Fault detection and exclusion on the stacked update (ours, RAIM-like): while the joint
    innovation fails its chi-square test, ``y^T S^-1 y > chi2_K(probability)`` with ``K`` the
    number of rows, leave out the (track, path) pair whose removal lowers the normalised
    innovation most, and stack again. Catches what the per-pair gates of Algorithm 2 cannot: a
    wrong LoS from eq. 61 and the TDoA rows, which no gate sees. Returns the stacked measurement
    of the kept pairs and the pairs left out (in order). Raises ``numpy.linalg.LinAlgError`` if
    an innovation covariance is not positive definite (the tracker then skips the update).
    ``C``: the consider cross-covariance (:func:`stack_measurement`)."""
    (
        state_arguments(x, P, np.shape(J)[-1] if np.ndim(J) else None),
        sequence("pairs", pairs, empty=True),
    )
    gate = ChiSquareGate(probability)
    pairs = list(pairs)
    out: list[tuple[int, int]] = []
    m = stack_measurement(pred, J, meas, pairs, config, los_path, noise, C)
    while m.z.size and _nis(x, P, m, C) > gate.threshold(int(m.z.size)):
        best = None
        for p in pairs:
            rest = [q for q in pairs if q != p]
            trial = stack_measurement(pred, J, meas, rest, config, los_path, noise, C)
            score = _nis(x, P, trial, C) / gate.threshold(max(int(trial.z.size), 1))
            if best is None or score < best[0]:
                best = (score, p, trial)
        _, p, m = best
        pairs.remove(p)
        out.append(p)
    return m, out


@dataclass(frozen=True)
class JosephUpdater:
    """The EKF update of eq. 64-68 with the Joseph-form covariance on every kept pair."""

    def stack(self, x, P, pred, J, meas, pairs, config, los_path, noise, C=None):
        """The stacked measurement of the pairs to update with and the pairs left out."""
        state_arguments(x, P, np.shape(J)[-1] if np.ndim(J) else None)
        return stack_measurement(pred, J, meas, pairs, config, los_path, noise, C), []

    def update(self, x, P, m: StackedMeasurement, C=None):
        """``(x, P, nis)`` after the update (:func:`~.update.joseph_update`); with a consider
        cross-covariance ``C`` and ``m.B``, ``(x, P, nis, C)``
        (:func:`~tunnelkit.tracking.javelin.consider.consider_update`)."""
        instance("m", m, StackedMeasurement)  # x and P: checked by the update that runs
        if C is not None:
            state_arguments(x, P, m.H.shape[1] if m.z.size else None)
            C = finite_array("C", C, ndim=2)
        if C is not None and m.B is not None and (np.any(m.B) or np.any(C)):
            from .consider import consider_update  # loaded when the tracker carries biases

            x, P, C, nis = consider_update(x, P, C, m)
            return x, P, nis, C
        # no bias anywhere (C = 0, B = 0): the consider update is the Joseph update exactly
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

    def stack(self, x, P, pred, J, meas, pairs, config, los_path, noise, C=None):
        return exclude_inconsistent(
            x, P, pred, J, meas, pairs, config, los_path, self.probability, noise, C
        )
