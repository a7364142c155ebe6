"""Posterior Cramer-Rao lower bound for tracking (Tichavský, Muravchik & Nehorai 1998).

For ``X_k = Phi X_{k-1} + U``, ``U ~ N(0, Q)`` and ``Z_k = h(X_k) + V``, ``V ~ N(0, R)``, the
information matrix of the state obeys the recursion (Tichavský et al. 1998, eq. 21 and 34)::

    J_0     = P0^-1 + E[H_0^T R^-1 H_0]                 (the filters update at epoch 0)
    J_k     = D22 - D21 (J_{k-1} + D11)^-1 D12
    D11     = Phi^T Q^-1 Phi,   D12 = D21^T = -Phi^T Q^-1,
    D22     = Q^-1 + E[H_k^T R^-1 H_k],                 H_k = d h / d X at X_k

and ``E[(X_hat_k - X_k)(X_hat_k - X_k)^T] >= J_k^-1`` for any estimator. A truth without process
noise (``Q = 0``: a deterministic path from a random start) has the limit of that recursion,
``J_k = Phi^-T J_{k-1} Phi^-1 + E[H_k^T R^-1 H_k]`` (the information about the start carried
forward; ``Phi`` invertible). The expectation over the
true states is taken over the sample of states passed in (one trajectory: the bound along it; many
trajectories drawn from the model: the full Bayesian bound). No paper in this workbook gives it;
notebook 05 puts it under every RMSE curve.
"""

from __future__ import annotations

import numpy as np

from .._domains import spd_matrix
from .._validate import boolean, finite_array

__all__ = ["measurement_information", "pcrlb", "pcrlb_position_rmse", "vs_pcrlb"]


def measurement_information(jacobians, R) -> np.ndarray:
    """``E[H^T R^-1 H]`` over all leading axes but the epoch axis: (..., T, m, n) -> (T, n, n)."""
    H = finite_array("jacobians", jacobians)
    if H.ndim < 3:
        raise ValueError(f"jacobians: expected shape (..., T, m, n), got {H.shape}")
    R = finite_array("R", R, ndim=2)
    if R.shape != (H.shape[-2], H.shape[-2]):
        raise ValueError(f"R: expected shape {(H.shape[-2],) * 2}, got {R.shape}")
    spd_matrix("R", R)
    info = np.swapaxes(H, -1, -2) @ np.linalg.solve(R, H)
    return info.reshape(-1, *info.shape[-3:]).mean(axis=0)


def pcrlb(F, Q, P0, info) -> np.ndarray:
    """Bound matrices ``J_k^-1`` (T, n, n) from the recursion above; ``info`` (T, n, n) holds
    ``E[H_k^T R^-1 H_k]`` per epoch. ``Q`` is one (n, n) matrix or one per epoch (T, n, n),
    ``Q[k]`` the process noise of the step into epoch ``k`` (``Q[0]`` unused): positive definite,
    or all zero for a truth without process noise (the module docstring's limit)."""
    F = finite_array("F", F, ndim=2)
    n = F.shape[0]
    info = finite_array("info", info, ndim=3)
    if info.shape[1:] != (n, n):
        raise ValueError(f"info: expected shape (T, {n}, {n}), got {info.shape}")
    Q = finite_array("Q", Q)
    if Q.shape not in ((n, n), (info.shape[0], n, n)):
        raise ValueError(f"Q: expected shape ({n}, {n}) or {(info.shape[0], n, n)}, got {Q.shape}")
    P0 = finite_array("P0", P0, shape=(n, n))
    Qs = np.broadcast_to(Q, info.shape)
    deterministic = not np.any(Q[1:] if Q.ndim == 3 else Q)
    if deterministic:
        if np.linalg.cond(F) > 1e12:
            raise ValueError("F: a truth without process noise (Q = 0) needs an invertible F")
        Fi = np.linalg.inv(F)
    else:
        for k in range(1 if Q.ndim == 3 else 0, Qs.shape[0] if Q.ndim == 3 else 1):
            spd_matrix("Q", Qs[k])
    spd_matrix("P0", P0)
    _psd("info", info)
    J = np.linalg.inv(P0) + info[0]
    out = np.empty_like(info)
    out[0] = np.linalg.inv(J)
    for k in range(1, info.shape[0]):
        if deterministic:
            J = Fi.T @ J @ Fi + info[k]
        else:
            Qi = np.linalg.inv(Qs[k])
            D11 = F.T @ Qi @ F
            D12 = -F.T @ Qi
            J = Qi + info[k] - D12.T @ np.linalg.solve(J + D11, D12)
        J = 0.5 * (J + J.T)
        out[k] = np.linalg.inv(J)
    return out


def _psd(name: str, A: np.ndarray) -> None:
    """Symmetric positive semi-definite (an expected information may be singular, never negative)."""
    scale = float(np.max(np.abs(A))) if A.size else 0.0
    if np.max(np.abs(A - np.swapaxes(A, -1, -2)), initial=0.0) > 1e-9 * scale:
        raise ValueError(f"{name}: must be symmetric positive semi-definite (it is not symmetric)")
    ev = np.linalg.eigvalsh(0.5 * (A + np.swapaxes(A, -1, -2)))
    if np.any(ev < -1e-9 * max(scale, np.finfo(float).tiny)):
        raise ValueError(
            f"{name}: must be symmetric positive semi-definite (eigenvalue {float(ev.min()):.3g})"
        )


def pcrlb_position_rmse(bounds) -> np.ndarray:
    """``sqrt(tr)`` of the position block (first two states) of bound matrices (..., n, n) [m].

    The bounds must be symmetric positive semi-definite (a negative "bound" raises).
    """
    B = finite_array("bounds", bounds)
    if B.ndim < 2 or B.shape[-1] != B.shape[-2] or B.shape[-1] < 2:
        raise ValueError(f"bounds: expected square matrices (..., n, n) with n >= 2, got {B.shape}")
    _psd("bounds", B)
    return np.sqrt(B[..., 0, 0] + B[..., 1, 1])


def vs_pcrlb(model, states, P0, *, process_noise: bool = True) -> np.ndarray:
    """Position RMSE bound (T,) [m] for the virtual-station model along ``states``.

    ``states`` is one true trajectory (T, 4) or a sample of them (S, T, 4) (the expectation of
    the measurement information is the average over the sample). ``process_noise``: the truth
    moves with the model's ``Q`` (True) or on a deterministic path known up to its start (False,
    ``Q = 0``): for one fixed path, whose start the data know through the prior mean (drawn from
    ``N(X_0, P0)``), the classical CRLB of any unbiased estimator; over random starts, the
    Bayesian bound. It is the bound for the presets' noise-free drives, whatever ``q`` a filter
    is told.
    """
    process_noise = boolean("process_noise", process_noise)
    if not all(hasattr(model, a) for a in ("jacobian", "R", "F", "Q")):
        raise TypeError(
            f"model: expected a virtual-station model (jacobian, R, F, Q), got {type(model).__name__}"
        )
    X = finite_array("states", states)
    if X.ndim not in (2, 3) or X.shape[-1] != 4:
        raise ValueError(f"states: expected shape (T, 4) or (S, T, 4), got {X.shape}")
    info = measurement_information(model.jacobian(X), model.R)
    Q = model.Q if process_noise else np.zeros_like(model.Q)
    return pcrlb_position_rmse(pcrlb(model.F, Q, P0, info))
