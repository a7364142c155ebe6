"""The fits' linear algebra as public, checked functions: :func:`solve` (a linear solve that falls
back to least squares on a singular system), :func:`free_newton` (the bound-constrained
Gauss-Newton decrement) and :func:`damped_step` (the Levenberg-Marquardt step; in two parts
:func:`damped_system` and :func:`damped_solve`). Each checks its arguments, naming them, and runs
the unchecked twin in :mod:`.numerics` that the fits call on their own arrays: the same
arithmetic, bit for bit (``tests/test_inner_loops.py``)."""

from __future__ import annotations

import numpy as np

from .._validate import positive
from .numerics import (
    damped_solve_unchecked,
    damped_step_unchecked,
    damped_system_unchecked,
    free_newton_unchecked,
    solve_unchecked,
)

__all__ = ["damped_step", "free_newton", "solve"]


def _finite(name: str, A) -> np.ndarray:
    """``A`` as an array of finite numbers (real or complex, not converted: these helpers run
    inside the fits' iterations, so the check is the cheapest that names ``name``)."""
    A = np.asarray(A)
    if A.dtype.kind not in "biufc":
        raise TypeError(f"{name}: expected numbers, got dtype {A.dtype}")
    if not np.isfinite(A).all():
        raise ValueError(f"{name}: contains NaN or infinite values")
    return A


def _square(name: str, A) -> np.ndarray:
    A = _finite(name, A)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ValueError(f"{name}: expected a square matrix, got shape {A.shape}")
    return A


def _masks(g, *masks):
    _finite("g", g)
    if g.ndim != 1:
        raise ValueError(f"g: expected a vector, got shape {g.shape}")
    for name, m in masks:
        if np.shape(m) != g.shape:
            raise ValueError(f"{name}: expected shape {g.shape}, got {np.shape(m)}")


def solve(G, B) -> np.ndarray:
    """``G^{-1} B`` for a square ``G`` (n, n) and ``B`` (n,) or (n, k); the least-squares
    solution when ``G`` is singular."""
    G = _square("G", G)
    B = _finite("B", B)
    if B.ndim not in (1, 2) or B.shape[0] != G.shape[0]:
        raise ValueError(f"B: expected {G.shape[0]} rows, got shape {B.shape}")
    return solve_unchecked(G, B)


def free_newton(A, g, lower, upper) -> tuple[np.ndarray, float]:
    """Coordinates free to move and the Newton decrement ``g^T A^{-1} g`` over them.

    ``A`` (n, n) is the (real) Gauss-Newton matrix, ``g`` (n,) the descent direction, ``lower``
    and ``upper`` (n,) flag the coordinates at their lower and upper bounds. A coordinate at its
    lower (upper) bound whose Gauss-Newton step points down (up) is held: the projection would
    undo its step. ``A`` is Jacobi-scaled before the solve (the parameters differ by orders of
    magnitude). Returns ``(free (n,) bool, decrement)``.
    """
    A = _square("A", A)
    g = np.asarray(g)
    _masks(g, ("A", A[0]), ("lower", lower), ("upper", upper))
    return free_newton_unchecked(A, g, lower, upper)


def damped_step(A, g, free, lam: float) -> np.ndarray | None:
    """Levenberg-Marquardt step ``(A_s + lam I)^{-1} g`` on the ``free`` coordinates (n,) bool,
    with Marquardt's diagonal scaling ``A_s = D^{-1/2} A D^{-1/2}``; zero on the held ones.
    ``None`` when the damped system is singular (the caller raises ``lam``)."""
    A = _square("A", A)
    g = np.asarray(g)
    _masks(g, ("A", A[0]), ("free", free))
    return damped_step_unchecked(A, g, free, positive("lam", lam))


def damped_system(A, g, free) -> tuple:
    """The scaled system of :func:`damped_step` on the ``free`` coordinates (n,) bool, for
    :func:`damped_solve` (checked; the fits call :func:`damped_system_unchecked`)."""
    A = _square("A", A)
    g = np.asarray(g)
    _masks(g, ("A", A[0]), ("free", free))
    return damped_system_unchecked(A, g, free)


def damped_solve(system, lam: float) -> np.ndarray | None:
    """:func:`damped_step` of a system of :func:`damped_system` at damping ``lam`` (checked)."""
    if not (isinstance(system, tuple) and len(system) == 5):
        raise TypeError("system: expected the tuple damped_system returns")
    return damped_solve_unchecked(system, positive("lam", lam))
