"""The bias-aware JAVELIN (ours), a Schmidt-Kalman consider filter: :class:`ConsiderNoise` splits
each reported covariance into its white share and its repeating share
(``PathMeasurements.bias_cov``), which the tracker carries as consider parameters
(:func:`bias_factors` factors it), and :func:`consider_update` updates with them, through
:func:`schmidt_update`. Loaded when a design carries biases.

Why consider rather than estimate the biases: docs/internals/tracking.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.linalg import cho_factor, cho_solve

from ..._checks import attributes
from ..._physical import step_seconds
from ..._validate import finite_array, instance, integer, positive
from .config import JavelinConfig
from .measurement import PathMeasurements
from .noise import ReportedNoise, check_tdoa_rows

__all__ = ["ConsiderNoise", "bias_factors", "consider_update", "schmidt_update"]


def bias_factors(bias_cov: np.ndarray) -> np.ndarray:
    """A lower-triangular factor ``L`` (n, 4, 4) with ``L L^T = bias_cov`` of every path's
    repeating error: the Cholesky factor of ``bias_cov`` (a tiny ridge keeps a singular block
    factorisable; rows of a zero block stay zero). Lower-triangular, so the factor of a bias
    covariance that changes smoothly along the drive changes smoothly too (an eigenvector
    factor may flip its signs from one epoch to the next)."""
    b = finite_array("bias_cov", bias_cov, ndim=3)
    if b.shape[1:] != (4, 4):
        raise ValueError(f"bias_cov: expected shape (n, 4, 4), got {b.shape}")
    n = b.shape[0]
    out = np.zeros((n, 4, 4))
    sd = np.sqrt(np.clip(np.diagonal(b, axis1=1, axis2=2), 0.0, None))  # (n, 4)
    ons = sd > 0
    full = ons.all(axis=1)
    if full.any():  # every component repeats: the blocks factorised together
        s = sd[full]
        Lc = np.linalg.cholesky(b[full] / (s[:, :, None] * s[:, None, :]) + 1e-12 * np.eye(4))
        out[full] = s[:, :, None] * Lc
    for k in np.flatnonzero(ons.any(axis=1) & ~full):  # some components only
        s, on = sd[k], ons[k]
        c = b[k][np.ix_(on, on)] / np.outer(s[on], s[on])
        Lc = np.linalg.cholesky(c + 1e-12 * np.eye(int(on.sum())))
        out[k][np.ix_(on, on)] = s[on][:, None] * Lc
    return out


@dataclass(frozen=True)
class ConsiderNoise(ReportedNoise):
    """Reported covariances split into a white share, drawn afresh every epoch, and a repeating
    share (``PathMeasurements.bias_cov``: one array's calibration error, the bias of the terms
    the estimator's model leaves out), which the tracker carries as consider parameters of the
    path's track instead of averaging it down (ours; docs/internals/tracking.md, the section on
    :mod:`tunnelkit.tracking.javelin.update`, says why consider and not estimate). Each track's
    normalised bias ``u`` (4,: one per ``phi, psi, kappa, d``, prior ``N(0, I)``) enters a
    measurement of path ``j`` as ``L_j u`` (:func:`bias_factors`), and
    decorrelates as a first-order Gauss-Markov process with time constant ``tau_s`` [s]
    (``inf``, the default: the same draw the whole drive). Association and births see the whole
    reported covariance (:meth:`covariances`); the update the white share
    (:meth:`white_covariances`) plus ``L_j u``. Without ``bias_cov`` it is :class:`ReportedNoise`."""

    tau_s: float = float("inf")
    consider: ClassVar[bool] = True

    def __post_init__(self) -> None:
        super().__post_init__()
        t = self.tau_s
        if not (isinstance(t, float) and t == float("inf")):
            positive("tau_s", t)  # a finite time constant [s] (inf: the same draw all drive)

    def decay(self, dt: float) -> float:
        """``exp(-dt / tau_s)``: how much of the normalised bias survives ``dt`` [s]."""
        return float(np.exp(-step_seconds("dt", dt) / self.tau_s))

    def white_covariances(self, meas: PathMeasurements, config: JavelinConfig) -> np.ndarray:
        """The white share (n, 3, 3) of each path's reported ``(phi, psi, kappa)`` covariance."""
        cov = self.covariances(meas, config)
        if meas.reported and meas.bias_cov is not None:
            return cov - meas.bias_cov[:, :3, :3]
        return cov

    def white_tdoa_covariance(
        self, meas: PathMeasurements, others, reference: int, config: JavelinConfig
    ) -> np.ndarray:
        """The white share of :meth:`tdoa_covariance`."""
        others, reference = check_tdoa_rows(meas, others, reference, config)
        if not (meas.reported and meas.bias_cov is not None):
            return self.tdoa_covariance(meas, others, reference, config)
        var = meas.sigma_d**2 - meas.bias_cov[:, 3, 3]
        return np.diag(var[others]) + var[reference]

    def factors(self, meas: PathMeasurements) -> np.ndarray:
        """``L`` (n, 4, 4) of every path's repeating share (zeros without ``bias_cov``)."""
        instance("meas", meas, PathMeasurements)
        if not (meas.reported and meas.bias_cov is not None):
            return np.zeros((len(meas), 4, 4))
        return bias_factors(meas.bias_cov)


def schmidt_update(
    x: np.ndarray,
    P: np.ndarray,
    H: np.ndarray,
    R: np.ndarray,
    y: np.ndarray,
    n_est: int | None = None,
    gain: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The linear update of a state ``x`` (N,) whose first ``n_est`` entries are estimated and
    the rest are consider parameters (Schmidt 1966): the gain's rows of the consider parameters
    are zero, so they keep their mean and covariance, and the estimated rows take the best gain
    under that constraint, ``K = (P H^T S^-1)[:n_est]`` with ``S = H P H^T + R``. Returns
    ``(x, P, K, nis)``, ``P`` in the Joseph form ``(I - K H) P (I - K H)^T + K R K^T``, which is
    the true covariance for *any* gain: ``gain`` (n_est, K) replaces the optimal one (to
    evaluate a filter that ignores the consider parameters). ``n_est = N`` (default) is the
    Kalman filter on the whole state."""
    x = finite_array("x", x, ndim=1)
    N = x.size
    P = finite_array("P", P, shape=(N, N))
    y = finite_array("y", y, ndim=1)
    H = finite_array("H", H, shape=(y.size, N))
    R = finite_array("R", R, shape=(y.size, y.size))
    n_est = N if n_est is None else integer("n_est", n_est, minimum=1, maximum=N)
    S = H @ P @ H.T + R
    S = 0.5 * (S + S.T)
    cf = cho_factor(S, lower=True)
    Ka = np.zeros((N, y.size))
    if gain is None:
        Ka[:n_est] = cho_solve(cf, H @ P[:, :n_est]).T
    else:
        Ka[:n_est] = finite_array("gain", gain, shape=(n_est, y.size))
    x_new = x + Ka @ y
    IKH = np.eye(N) - Ka @ H
    P_new = IKH @ P @ IKH.T + Ka @ R @ Ka.T
    nis = float(y @ cho_solve(cf, y))
    return x_new, 0.5 * (P_new + P_new.T), Ka[:n_est], nis


def consider_update(
    x: np.ndarray, P: np.ndarray, C: np.ndarray, m
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The Schmidt-Kalman update of the JAVELIN state with the tracks' normalised biases as
    consider parameters (docs/internals): the augmented covariance ``[[P, C], [C^T, I]]``, the
    rows ``z = h(x) + B u + w`` of ``m`` (:func:`~.update.stack_measurement`: ``m.B``, white
    ``m.R``), :func:`schmidt_update` with the state estimated. Returns ``(x, P, C, nis)``; the
    biases' block stays ``I``."""
    x = finite_array("x", x, ndim=1)
    D = x.size
    P = finite_array("P", P, shape=(D, D))
    C = finite_array("C", C, ndim=2)
    if C.shape[0] != D:
        raise ValueError(f"C: expected {D} rows (one per state entry), got {C.shape[0]}")
    attributes("m", m, ("z", "H", "B", "R", "residual"), "a javelin.update.StackedMeasurement")
    if m.z.size == 0:
        return x.copy(), P.copy(), C.copy(), 0.0
    Lc = C.shape[1]
    Pa = np.block([[P, C], [C.T, np.eye(Lc)]])
    xa = np.concatenate([x, np.zeros(Lc)])
    Ha = np.hstack([m.H, m.B])
    xa, Pa, _, nis = schmidt_update(xa, Pa, Ha, m.R, m.residual(), n_est=D)
    return xa[:D], Pa[:D, :D], Pa[:D, D:], nis
