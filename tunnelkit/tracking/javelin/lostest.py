"""The LoS test of eq. 60-61 (Italiano et al. 2026): the path whose delay distance is nearest its
curvature is the LoS if their ratio is within ``gamma`` of one (:func:`los_test`). Track
management (:func:`~tunnelkit.tracking.javelin.manage.manage_tracks`) runs it when no path was
associated with the UE; TeNFiLoc runs it on every epoch.
"""

from __future__ import annotations

import numpy as np

from ..._checks import series
from ..._validate import integer, positive, sequence

__all__ = ["los_test"]


def los_test(d, kappa, gamma: float, candidates=None) -> int | None:
    """Index of the LoS path by eq. 60 (``argmin |d - kappa|``) if it passes eq. 61
    (``1 - gamma <= d / kappa <= 1 + gamma``), else ``None`` (NLoS).

    ``candidates`` restricts the search (we search only paths no VUE track claimed); paths
    without a curvature or a delay cannot be tested.
    """
    series("d", d), series("kappa", kappa), positive("gamma", gamma)
    if candidates is not None:
        for i in sequence("candidates", candidates, empty=True):
            integer("candidates", i, minimum=0, maximum=np.size(d) - 1)
    d = np.asarray(d, dtype=float)
    kappa = np.asarray(kappa, dtype=float)
    ok = np.isfinite(d) & np.isfinite(kappa) & (kappa > 0)
    if candidates is not None:
        mask = np.zeros(d.size, bool)
        mask[np.asarray(list(candidates), dtype=int)] = True
        ok &= mask
    if not ok.any():
        return None
    gap = np.where(ok, np.abs(d - kappa), np.inf)
    j = int(np.argmin(gap))
    ratio = d[j] / kappa[j]
    return j if (1.0 - gamma) <= ratio <= (1.0 + gamma) else None
