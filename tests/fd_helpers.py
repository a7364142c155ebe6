"""Central differences and the flat parameter vector shared by the tests of the maximum-likelihood
stage (``test_ml.py``, ``test_ml_wideband.py``)."""

from __future__ import annotations

import numpy as np


def flat(th, mf, mt) -> np.ndarray:
    """The ML parameters ``theta`` (L, 3), ``mu_f``, ``mu_t`` (L,) as one vector, path by path."""
    return np.column_stack([th, mf, mt]).ravel()


def unflat(x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`flat` undone: ``(theta, mu_f, mu_t)``."""
    x = x.reshape(-1, 5)
    return x[:, :3].copy(), x[:, 3].copy(), x[:, 4].copy()


def central_differences(f, x, steps) -> np.ndarray:
    """``(f(x + h_i e_i) - f(x - h_i e_i)) / (2 h_i)`` for every coordinate ``i`` of ``x``, with
    ``h = steps``: shape (n,) for a scalar ``f``, (m, n) for ``f`` returning (m,) (column ``i``
    is the derivative along ``x_i``)."""
    cols = []
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = steps[i]
        cols.append((f(x + e) - f(x - e)) / (2 * steps[i]))
    return np.stack(cols, axis=-1)
