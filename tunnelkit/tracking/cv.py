"""Constant-velocity motion model (Jiang et al. 2023, eq. 40-41).

State ``X_k = [x, y, vx, vy]`` (positions [m], velocities [m/s]) evolves as
``X_k = Phi X_{k-1} + U_{k-1}`` (eq. 40) with the transition matrix of eq. 41 and process noise
``U ~ N(0, Q)``. The paper leaves ``Q`` open; we use the continuous white-noise-acceleration model
(spectral density ``q`` [m^2/s^3] per axis, discretised exactly over the period ``T1``), built with
filterpy's :func:`~filterpy.common.Q_continuous_white_noise`.
"""

from __future__ import annotations

import numpy as np
from filterpy.common import Q_continuous_white_noise

from .._validate import finite_array, integer, nonnegative, positive, rng_or_error
from ..budget import check_elements

__all__ = ["STATE_DIM", "cv_process_noise", "cv_transition", "simulate_cv"]

#: length of the state vector ``[x, y, vx, vy]``
STATE_DIM = 4


def cv_transition(period: float) -> np.ndarray:
    """``Phi`` of Jiang eq. 41 for observation period ``T1 = period`` [s], shape (4, 4)."""
    t = positive("period", period)
    F = np.eye(STATE_DIM)
    F[0, 2] = F[1, 3] = t
    return F


def cv_process_noise(period: float, q: float) -> np.ndarray:
    """Process-noise covariance ``Q_k`` of eq. 40 for white-noise acceleration of density ``q``.

    Per axis ``q [[T^3/3, T^2/2], [T^2/2, T]]``, ordered ``[x, y, vx, vy]`` like ``Phi``;
    ``q = 0`` gives the zero matrix (no process noise).
    """
    t = positive("period", period)
    q = nonnegative("q", q)
    return np.asarray(
        Q_continuous_white_noise(dim=2, dt=t, spectral_density=q, block_size=2, order_by_dim=False),
        dtype=float,
    )


def simulate_cv(
    x0, period: float, q: float, steps: int, rng: np.random.Generator, size: int | None = None
) -> np.ndarray:
    """Draw state sequences from the model of eq. 40: shape (steps, 4), or (size, steps, 4).

    ``x0`` is the state at the first epoch (not random). Useful to test a filter and the posterior
    CRLB on trajectories that really follow the model the filter assumes.
    """
    x0 = finite_array("x0", x0, shape=(STATE_DIM,))
    steps = integer("steps", steps, minimum=1)
    rng = rng_or_error("rng", rng)
    # q > 0 here: a zero Q has no Cholesky factor
    F, Q = cv_transition(period), cv_process_noise(period, positive("q", q))
    lead = () if size is None else (integer("size", size, minimum=1),)
    check_elements(
        "steps, size", 2 * (lead[0] if lead else 1) * steps * STATE_DIM, what="states and noise"
    )
    L = np.linalg.cholesky(Q)
    noise = rng.standard_normal((*lead, steps - 1, STATE_DIM)) @ L.T
    out = np.empty((*lead, steps, STATE_DIM))
    out[..., 0, :] = x0
    for k in range(1, steps):
        out[..., k, :] = out[..., k - 1, :] @ F.T + noise[..., k - 1, :]
    return out
