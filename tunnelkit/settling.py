"""The settled epochs of a drive: its first :data:`SETTLE_S` seconds are a tracker's start-up (an
open-sky fix with 1 m of uncertainty, the VUE tracks born over the first epochs), which every
settled error of the drives and the design leaves out."""

from __future__ import annotations

import numpy as np

from ._validate import finite_array

__all__ = ["SETTLE_S", "settled"]

#: the start-up a drive's settled errors leave out [s]
SETTLE_S = 1.0


def settled(t) -> np.ndarray:
    """Indices of the epochs of ``t`` [s] at least :data:`SETTLE_S` after its start."""
    t = finite_array("t", t, ndim=1)
    if not t.size:
        raise ValueError("t: expected at least one epoch time")
    return np.flatnonzero(t - t[0] >= SETTLE_S - 1e-9)
