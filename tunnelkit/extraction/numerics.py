"""The numerics every extraction stage shares, below all of them.

- :data:`MIN_SIGNIFICANCE` — the log-likelihood ratio a path needs to stand above the noise;
- ``solve_unchecked``, ``free_newton_unchecked`` and ``damped_step_unchecked`` (in two parts,
  ``damped_system_unchecked`` and ``damped_solve_unchecked``) — a linear solve that falls back
  to least squares on a singular system, the bound-constrained Gauss-Newton decrement and the
  Levenberg-Marquardt step of the variable-projection fits (:mod:`.coherent`, :mod:`.ml`);
  their checked public forms are :mod:`.linalg`'s;
- :func:`contract` — ``sum_{s,k} H[m, s, k] F[s, l] T[k, l]``, the contraction of the channel
  tensor with frequency and time vectors;
- :func:`grid_index` — the rectangular-lattice coordinates of a URA (or ULA) layout;
- :func:`spatial_phase` — the exact spherical spatial phase of eq. 1 and its derivatives in
  ``(u_x, u_y, w = 1 / kappa)``;
- :func:`scan_peak` — the far-field beam-scan peak of a spatial vector.

The fits call :func:`~.linalg.solve`, :func:`~.linalg.free_newton`, :func:`~.linalg.damped_step`,
:func:`spatial_phase` and :func:`contract` on every iteration with arrays they built themselves;
there the finiteness checks cost ~2 % of an extraction. Each has an unchecked twin
(``solve_unchecked``, ``free_newton_unchecked``, ``damped_step_unchecked``,
``spatial_phase_unchecked``, ``contract_unchecked``; not exported) that the fits call on their own
arrays: the same arithmetic, bit for bit (``tests/test_inner_loops.py``); the checked forms are the
public ones.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .._physical import carrier
from .._validate import finite_array, integer, positive
from ..budget import check_elements
from ..constants import C

__all__ = [
    "MIN_SIGNIFICANCE",
    "contract",
    "grid_index",
    "scan_grid",
    "scan_peak",
    "spatial_phase",
]

#: log-likelihood ratio of a path against noise below which it is indistinguishable from noise
MIN_SIGNIFICANCE = 25.0


def solve_unchecked(G, B) -> np.ndarray:
    """:func:`~.linalg.solve` without the checks (the fits' inner loops, on their own finite
    arrays)."""
    try:
        return np.linalg.solve(G, B)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(G, B, rcond=None)[0]


def _free_block(A, free, every: bool):
    """``A`` on the ``free`` coordinates (``A`` itself when ``every`` one is free)."""
    return A if every else A[np.ix_(free, free)]


def free_newton_unchecked(A, g, lower, upper) -> tuple[np.ndarray, float]:
    """:func:`~.linalg.free_newton` without the checks (the fits' inner loops, on their own
    arrays).

    A coordinate with a negative curvature ``A[i, i] < 0``, or a zero one beside a non-zero
    coupling, is held: ``A`` is a Schur complement, positive semi-definite, and such a diagonal
    is rounding where the fit has become degenerate (two paths merging: their Gram matrix near
    singular), whose scaling would overflow and hand LAPACK non-finite numbers. A zero row (a
    path of zero gain) stays free, its Newton step zero."""
    d = np.diag(A)
    free = d > 0.0
    zero = d == 0.0
    if zero.any():
        free[zero] = ~A[zero].any(axis=1)
    for _ in range(3):
        sc = 1.0 / np.sqrt(np.maximum(d[free], 1e-300))
        As = sc[:, None] * _free_block(A, free, bool(free.all())) * sc[None, :]
        gs = sc * g[free]
        newton = np.zeros(g.size)
        newton[free] = sc * np.linalg.lstsq(As, gs, rcond=1e-12)[0]
        out = (lower & (newton < 0)) | (upper & (newton > 0))
        if not out.any():
            break
        free &= ~out
    return free, float(g[free] @ newton[free])


def damped_step_unchecked(A, g, free, lam: float) -> np.ndarray | None:
    """:func:`~.linalg.damped_step` without the checks (the fits' inner loops, on their own
    arrays)."""
    return damped_solve_unchecked(damped_system_unchecked(A, g, free), lam)


def damped_system_unchecked(A, g, free) -> tuple:
    """The scaled system of :func:`~.linalg.damped_step` on the ``free`` coordinates, for
    :func:`damped_solve_unchecked` (a fit that raises ``lam`` at the same point builds it once)."""
    sc = 1.0 / np.sqrt(np.maximum(np.diag(A)[free], 1e-300))
    As = sc[:, None] * _free_block(A, free, bool(free.all())) * sc[None, :]
    return sc, As, np.eye(As.shape[0]), sc * g[free], free


def damped_solve_unchecked(system, lam: float) -> np.ndarray | None:
    """:func:`~.linalg.damped_step` of a system of :func:`damped_system_unchecked` at damping
    ``lam``."""
    sc, As, eye, gs, free = system
    try:
        sub = sc * np.linalg.solve(As + lam * eye, gs)
    except np.linalg.LinAlgError:
        return None
    step = np.zeros(free.size)
    step[free] = sub
    return step


def contract(H, F, T) -> np.ndarray:
    """``sum_{s,k} H[m, s, k] F[s, l] T[k, l]`` (M, L) via one matrix product and a reduction,
    for a tensor ``H`` (M, Nf, Nt) and mode matrices ``F`` (Nf, L), ``T`` (Nt, L)."""
    H, F, T = np.asarray(H), np.asarray(F), np.asarray(T)
    if H.ndim != 3:
        raise ValueError(f"H: expected a 3-D tensor (M x Nf x Nt), got shape {H.shape}")
    _, nf, nt = H.shape
    if F.ndim != 2 or F.shape[0] != nf:
        raise ValueError(f"F: expected ({nf}, L), got shape {F.shape}")
    if T.ndim != 2 or T.shape != (nt, F.shape[1]):
        raise ValueError(f"T: expected ({nt}, {F.shape[1]}), got shape {T.shape}")
    finite_array("F", F, dtype=complex)
    finite_array("T", T, dtype=complex)
    out = contract_unchecked(H, F, T)
    if not np.isfinite(out).all():  # F and T are finite: H is not (checked here, not per sample)
        raise ValueError("H: contains NaN or infinite values")
    return out


def contract_unchecked(H, F, T) -> np.ndarray:
    """:func:`contract` without the checks (arrays (M, Nf, Nt), (Nf, L), (Nt, L) the caller
    built or checked)."""
    M, nf, nt = H.shape
    tmp = (H.reshape(M * nf, nt) @ T).reshape(M, nf, -1)
    return np.einsum("msl,sl->ml", tmp, F)


def grid_index(element_positions, tol: float = 1e-6):
    """``(rows, cols, n_rows, n_cols)`` integer grid coordinates of the elements if their xy
    positions (M, >= 2) form a full rectangular lattice (a URA, or a ULA along x or y), else
    ``None``. Positions closer than ``tol`` along an axis count as one level."""
    p = finite_array("element_positions", element_positions)
    if p.ndim != 2 or p.shape[1] < 2:
        raise ValueError(f"element_positions: expected shape (M, 3), got {p.shape}")
    tol = positive("tol", tol)
    out = []
    for ax in (1, 0):
        v = p[:, ax]
        u = np.unique(v)
        levels = u[np.concatenate([[True], np.diff(u) > tol])]  # values closer than tol merge
        if levels.size == 1:
            out.append((np.zeros(p.shape[0], int), 1))
            continue
        # the step from the float positions (rounding them to tol first lets the rounding error
        # accumulate along the axis: a 32 x 32 URA at 28 GHz was not recognised as a grid)
        idx = np.round((v - levels[0]) / np.min(np.diff(levels))).astype(int)
        step = float(np.sum(idx * (v - levels[0])) / np.sum(idx * idx))
        if not np.allclose(levels[0] + idx * step, v, rtol=0.0, atol=10 * tol):
            return None
        out.append((idx, int(idx.max()) + 1))
    (r, nr), (c, nc) = out
    if nr * nc != p.shape[0] or len(set(zip(r.tolist(), c.tolist()))) != p.shape[0]:
        return None
    return r, c, nr, nc


def spatial_phase(theta, element_positions, k0: float):
    """Spatial phase ``psi`` (M, L) of eq. 1 and its derivatives (M, L) for ``u_x, u_y, w``.

    ``theta`` (L, 3) = ``(u_x, u_y, w)`` per wave: the direction cosines in the array plane and
    the curvature ``w = 1 / kappa``; ``element_positions`` (M, 3) in the local frame (``z = 0``,
    reference at the origin), ``k0 = 2 pi fc / c``. With ``D = ||u - w p|| = sqrt(1 - 2 w u.p +
    w^2 |p|^2)``, ``N = w |p|^2 - 2 u.p`` and ``Q = 1 + D``, ``psi_m = k0 (||q - p_m|| - ||q||) =
    k0 N / Q`` (``q = u / w``), a form smooth through the far field ``w = 0``:

        d psi / d u_x = k0 p_x (-2 / Q + N w / (Q^2 D))         (likewise u_y with p_y),
        d psi / d w   = k0 (|p|^2 / Q - N (w |p|^2 - u.p) / (Q^2 D)).
    """
    th = np.atleast_2d(finite_array("theta", theta))
    if th.ndim != 2 or th.shape[1] != 3:
        raise ValueError(f"theta: expected shape (L, 3), got {th.shape}")
    p = finite_array("element_positions", element_positions)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"element_positions: expected shape (M, 3), got {p.shape}")
    return spatial_phase_unchecked(th, p, positive("k0", k0))


def spatial_phase_unchecked(th, p, k0: float):
    """:func:`spatial_phase` without the checks: ``th`` (L, 3) and ``p`` (M, 3) finite float
    arrays, ``k0 > 0`` (the fits' inner loops, on their own arrays)."""
    p2 = np.sum(p**2, axis=1)[:, None]
    up = p[:, :2] @ th[:, :2].T
    w = th[None, :, 2]
    D = np.sqrt(np.maximum(1.0 - 2.0 * w * up + w * w * p2, 1e-300))
    Q = 1.0 + D
    N = w * p2 - 2.0 * up
    psi = k0 * N / Q
    common = k0 * (-2.0 / Q + N * w / (Q * Q * D))
    dx = common * p[:, 0:1]
    dy = common * p[:, 1:2]
    dw = k0 * (p2 / Q - N * (w * p2 - up) / (Q * Q * D))
    return psi, dx, dy, dw


@lru_cache(maxsize=4)
def _scan_grid(pos_bytes: bytes, m: int, fc: float, n_grid: int, edge: float = 0.99):
    """Far-field beam-scan grid of one array: directions (G, 2) with ``|u|^2 < edge`` and the
    steering matrix (M, G) (read-only: it is shared by every call with the same array)."""
    p = np.frombuffer(pos_bytes).reshape(m, 3)
    g = np.linspace(-1, 1, n_grid)
    ux, uy = np.meshgrid(g, g)
    keep = ux**2 + uy**2 < edge
    u = np.column_stack([ux[keep], uy[keep]])
    A = np.exp(-2j * np.pi * fc / C * (p[:, :2] @ u.T))  # far field: delta_m = -u . p_m
    u.flags.writeable = False
    A.flags.writeable = False
    return u, A


def scan_grid(element_positions, fc: float, n_grid: int = 61):
    """The far-field beam-scan grid of an array over the whole visible region ``|u| <= 1`` (to
    end-fire): directions ``u`` (G, 2) on an ``n_grid x n_grid`` lattice and the steering matrix
    ``A`` (M, G), ``A[m, g] = exp(-j k0 u_g . p_m)`` (cached, read-only)."""
    p = np.ascontiguousarray(finite_array("element_positions", element_positions))
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"element_positions: expected shape (M, 3), got {p.shape}")
    n_grid = integer("n_grid", n_grid, minimum=2)
    check_elements("n_grid", n_grid * n_grid * (p.shape[0] + 2), 16, f"a {n_grid} x {n_grid} scan")
    return _scan_grid(p.tobytes(), p.shape[0], carrier("fc", fc), n_grid, 1.0 + 1e-12)


def scan_peak(r, element_positions, fc: float, n_grid: int = 61) -> np.ndarray:
    """Direction cosines ``(u_x, u_y)`` of the strongest far-field beam of the spatial vector
    ``r`` (M,) on an ``n_grid x n_grid`` grid of the unit disc (the steering matrix of the last
    two arrays is cached)."""
    p = np.ascontiguousarray(finite_array("element_positions", element_positions))
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"element_positions: expected shape (M, 3), got {p.shape}")
    if np.shape(r) != (p.shape[0],):
        raise ValueError(f"r: expected shape ({p.shape[0]},), got {np.shape(r)}")
    finite_array("r", r, dtype=complex)
    n_grid = integer("n_grid", n_grid, minimum=2)
    check_elements("n_grid", n_grid * n_grid * (p.shape[0] + 2), 16, f"a {n_grid} x {n_grid} scan")
    u, A = _scan_grid(p.tobytes(), p.shape[0], carrier("fc", fc), n_grid)
    return u[int(np.argmax(np.abs(np.conj(r) @ A)))]  # |A^H r| without copying A^H
