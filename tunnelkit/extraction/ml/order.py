"""The model order of the maximum-likelihood stage by a detection test per added path (GLRT):
:func:`ml_order`, :func:`~.paths.ml_paths` with one path more until the residual holds none."""

from __future__ import annotations

import warnings

from ..._validate import integer
from ..decomposition import check_tensor
from ..estimates import PathEstimates
from .paths import ml_paths

__all__ = ["ml_order"]


def ml_order(H, array, srs, *, max_paths: int | None = None, **kwargs) -> PathEstimates:
    """The model order by a detection test per added path (GLRT): :func:`ml_paths` with
    ``n_paths = 1, 2, ...`` until the residual holds no path more — the largest peak of its
    single-path periodogram (the GLRT statistic of one path more) below its threshold at the
    false-alarm rate ``FALSE_ALARM``, calibrated on noise-only tensors
    (:func:`~.residual.calibrated_threshold`). A fit whose newest path fails its own GLRT
    (``MLFit.detected``) stops the count one path earlier. Returns the estimates at the chosen
    order (``len`` of the result); ``max_paths`` (default ``M - 1``) caps the count. Other
    keywords go to :func:`ml_paths`."""
    H = check_tensor(H)
    M = H.shape[0]
    cap = M - 1 if max_paths is None else integer("max_paths", max_paths, minimum=1)
    cap = min(cap, M - 1)
    if "n_paths" in kwargs:
        raise TypeError("n_paths: ml_order chooses it; call ml_paths for a given order")
    prev = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for L in range(1, cap + 1):
            est = ml_paths(H, L, array, srs, **kwargs)
            if not est.fit.detected.all():
                return est if prev is None else prev
            if est.fit.peak <= est.fit.peak_max:
                return est
            prev = est
    return est
