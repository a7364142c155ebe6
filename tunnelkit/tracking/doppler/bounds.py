"""What one transmitter can observe (Halili et al. 2022 setting): the Fisher information of one
epoch (:func:`snapshot_fim`) and the posterior CRLB along a drive (:func:`posterior_crlb`).
"""

from __future__ import annotations

import numpy as np

from ..._physical import start_spread
from ..._validate import finite_array, nonnegative, positive
from ...doppler_drive import Drive, slant_range
from .filters import DopplerSetup, cv_model, doppler_jacobian

__all__ = ["posterior_crlb", "snapshot_fim"]


def snapshot_fim(
    p, v, setup: DopplerSetup, *, sigma_hz: float | None = None, sigma_range: float | None = None
) -> np.ndarray:
    """Fisher information on the position ``[x, y]`` from one epoch (velocity known), shape (2, 2).

    Doppler (``sigma_hz``) and/or range from ToA (``sigma_range`` metres); closed form
    ``sum_i J_i^T J_i / sigma_i^2`` with ``J`` from :func:`doppler_jacobian` and ``w / r``.
    One scalar measurement gives a rank-one matrix: information along one direction only.
    """
    p = finite_array("p", p, shape=(2,))
    v = finite_array("v", v, shape=(2,))
    if sigma_hz is None and sigma_range is None:
        raise ValueError("sigma_hz, sigma_range: give at least one measurement")
    F = np.zeros((2, 2))
    if sigma_hz is not None:
        J = doppler_jacobian(np.concatenate([p, v]), setup)[:, :2]
        F += J.T @ J / positive("sigma_hz", sigma_hz) ** 2
    if sigma_range is not None:
        w = p - setup.tx
        J = (w / float(slant_range(p, setup.tx, setup.dz)))[None, :]
        F += J.T @ J / positive("sigma_range", sigma_range) ** 2
    return F


def posterior_crlb(
    drive: Drive,
    *,
    q: float = 0.5,
    sigma_hz: float | None = 32.79,
    sigma_range: float | None = None,
    sigma_p0: float | None = None,
    sigma_v0: float | None = None,
) -> np.ndarray:
    """Posterior CRLB (Tichavský et al. 1998) of ``[x, y, v_x, v_y]`` along the true drive, (T, 4, 4).

    For linear-Gaussian dynamics the information recursion is
    ``J_k = (Q + F J_{k-1}^{-1} F^T)^{-1} + H_k^T R^{-1} H_k`` with ``H_k`` at the true state;
    ``J_0 = P_0^{-1} + H_0^T R^{-1} H_0`` from the GNSS fix. Doppler (``sigma_hz``) and/or
    range (``sigma_range``, metres); both None gives the prior alone (dead reckoning).
    """
    if not isinstance(drive, Drive):
        raise TypeError(f"drive: expected a Drive, got {type(drive).__name__}")
    cfg = drive.config
    setup = DopplerSetup.from_drive(drive)
    q = nonnegative("q", q)
    sp = start_spread("sigma_p0", cfg.gnss_sigma_m if sigma_p0 is None else sigma_p0)
    sv = positive("sigma_v0", cfg.gnss_sigma_v if sigma_v0 is None else sigma_v0)
    F, Q = cv_model(setup.dt, q)
    s = np.concatenate([drive.position, drive.velocity], -1)
    info = np.zeros((len(s), 4, 4))
    if sigma_hz is not None:
        H = doppler_jacobian(s, setup)[:, 0, :]
        info += H[:, :, None] * H[:, None, :] / positive("sigma_hz", sigma_hz) ** 2
    if sigma_range is not None:
        w = drive.position - setup.tx
        H = np.concatenate(
            [w / slant_range(drive.position, setup.tx, setup.dz)[:, None], np.zeros_like(w)], -1
        )
        info += H[:, :, None] * H[:, None, :] / positive("sigma_range", sigma_range) ** 2
    out = np.empty_like(info)
    P = np.linalg.inv(np.diag([1 / sp**2, 1 / sp**2, 1 / sv**2, 1 / sv**2]) + info[0])
    out[0] = P
    for k in range(1, len(s)):
        Pp = F @ P @ F.T + Q
        P = np.linalg.inv(np.linalg.inv(Pp) + info[k])
        out[k] = 0.5 * (P + P.T)
    return out
