"""Angles wrapped to ``(-pi, pi]``: the innovation of every bearing a tracker compares.

:func:`wrap_angle` checks its input; :func:`wrap_angle_unchecked` is its twin for inner loops that
already hold floats (bit for bit the same result).
"""

from __future__ import annotations

import numpy as np

from ._validate import finite_array

__all__ = ["wrap_angle"]


def wrap_angle(a):
    """Wrap angle(s) to ``(-pi, pi]``; ``a`` must be finite and real."""
    return wrap_angle_unchecked(finite_array("a", a))


def wrap_angle_unchecked(a: np.ndarray) -> np.ndarray:
    """:func:`wrap_angle` without the input check (inner loops that already hold floats).

    ``pi - mod(pi - a, 2 pi)``; ``mod`` returns its argument unchanged where it already lies in
    ``[0, 2 pi)`` (most residuals), so the slow floating-point ``mod`` runs only on the others:
    the result is bit for bit the same.
    """
    b = np.pi - a
    if b.size < 64:  # a few angles: the plain formula is quicker than the test
        return np.pi - np.mod(b, 2.0 * np.pi)
    out = np.pi - b
    far = (b < 0.0) | (b >= 2.0 * np.pi)
    if far.any():
        out[far] = np.pi - np.mod(b[far], 2.0 * np.pi)
    return out
