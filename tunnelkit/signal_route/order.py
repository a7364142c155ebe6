"""The model order of a route by a detection test per added path (:func:`glrt_paths`)."""

from __future__ import annotations

import warnings

import numpy as np

from .._validate import instance, integer
from ..arrays import ArrayGeometry
from ..channel import SRSConfig

__all__ = ["glrt_paths"]


def glrt_paths(
    H,
    array: ArrayGeometry,
    config: SRSConfig,
    n_start: int,
    max_paths: int,
    *,
    noise_power: float | None = None,
    wideband: bool = False,
):
    """The model order by a detection test per added path, from ``n_start`` paths up: the ML fit
    (:func:`tunnelkit.extraction.ml.ml_paths`) of ``n_start`` paths, then while its residual's
    single-path periodogram peak (the GLRT statistic of one path more, the fit's ``peak``)
    exceeds its threshold (``peak_max``) and fewer than ``max_paths`` (at most ``M - 1``) paths
    are fitted, one path more started at that peak (its far-field direction, delay and Doppler,
    :func:`tunnelkit.extraction.ml.residual.residual_peak`) and every path refitted from the
    previous fit (no re-seeding). A fit whose newest path fails its own detection test
    (``fit.detected``) ends the count one path earlier. ``noise_power`` is the floor of every
    test (estimated from ``H`` when None). Returns the estimates at the chosen order."""
    from ..extraction.ml import ml_paths
    from ..extraction.ml.residual import residual_peak

    instance("array", array, ArrayGeometry)
    instance("config", config, SRSConfig)
    H = np.asarray(H)
    if H.ndim != 3 or H.shape[0] != array.M:
        raise ValueError(f"H: expected an ({array.M}, Nf, Nt) tensor, got shape {H.shape}")
    n0 = integer("n_start", n_start, minimum=1, maximum=array.M - 1)
    cap = min(integer("max_paths", max_paths, minimum=n0), array.M - 1)

    def fit(n, start=None):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            e = ml_paths(
                H,
                n,
                array,
                config,
                start=start,
                noise_power=noise_power,
                n_reseed=None if start is None else 0,
                wideband=wideband,
            )
        return e, caught

    est, caught = fit(n0)
    while len(est) < cap and est.fit.peak > est.fit.peak_max:
        f = est.fit
        model = est.model_tensor()
        floor = f.noise_power if noise_power is None else noise_power
        _, (ux, uy, mu_f, mu_t), _ = residual_peak(H - model, array.local, config.fc, floor)
        start = (
            np.vstack([f.theta, [ux, uy, 0]]),
            np.append(f.mu_f, mu_f),
            np.append(f.mu_t, mu_t),
        )
        nxt, nxt_caught = fit(len(est) + 1, start)
        if not nxt.fit.detected.all():
            break
        est, caught = nxt, nxt_caught
    for w in caught:  # the chosen fit's own warnings (the smaller orders' are expected)
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return est
