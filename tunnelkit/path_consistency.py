"""The geometry-consistency test on a signal route's epoch, with the bound at the estimate.

:func:`tunnelkit.rt.consistency.geometry_consistency` asks whether one snapshot's paths agree with
one UE position through the tunnel's planes, each residual in standard deviations of a bound.
Here the bound is the CRLB at the estimate (:func:`bound_sigmas`: world azimuth, elevation and
range of each kept path, :func:`tunnelkit.signal_route.reported_covariance` computed whatever the
fit's own residual verdict), and :func:`epoch_consistency` runs the test
on a :class:`tunnelkit.signal_route.Epoch`::

    ep = route.epoch(12, rng, refine="ml")
    res = epoch_consistency(ep, route)        # res["consistent"], res["keep"], res["r2"], ...
"""

from __future__ import annotations

import numpy as np

from ._validate import boolean, instance
from .arrays import ArrayGeometry
from .channel import SRSConfig
from .rt.consistency import geometry_consistency, tunnel_planes
from .signal_route import Epoch, SignalRoute, reported_covariance

__all__ = ["bound_sigmas", "epoch_consistency"]


def bound_sigmas(est, array: ArrayGeometry, config: SRSConfig, keep=None) -> np.ndarray:
    """(K, 3) CRLB standard deviations at the estimate ``est`` (a
    :class:`tunnelkit.extraction.PathEstimates`) of the world azimuth, elevation [rad] and range
    [m] of the paths ``keep`` (indices into ``est``, in their order; default the paths Algorithm 1
    keeps with its printed check ``d >= 0``, as ``RouteMeasurements.index``): the route's
    reported covariance (:func:`tunnelkit.signal_route.reported_covariance`, ``judged=False``).
    Raises ``numpy.linalg.LinAlgError`` where the Fisher information is singular."""
    from .extraction import PathEstimates, algorithm1

    instance("est", est, PathEstimates)
    instance("array", array, ArrayGeometry)
    instance("config", config, SRSConfig)
    if keep is None:
        keep = algorithm1(est, 0.0)
    else:
        raw = np.asarray(keep)
        if raw.ndim != 1 or (raw.size and raw.dtype.kind not in "iu"):
            raise ValueError(f"keep: expected a 1-D array of path indices, got {keep!r}")
        if raw.size and (raw.min() < 0 or raw.max() >= len(est) or np.unique(raw).size < raw.size):
            raise ValueError(f"keep: indices must be distinct and in [0, {len(est)}), got {raw}")
        keep = raw.astype(int)
    if not keep.size:
        return np.zeros((0, 3))
    cov, sigma_d = reported_covariance(est, keep, array, config, judged=False)
    if cov is None:
        raise np.linalg.LinAlgError("the Fisher information is singular at the estimate")
    return np.stack([np.sqrt(cov[:, 0, 0]), np.sqrt(cov[:, 1, 1]), np.asarray(sigma_d)], -1)


def epoch_consistency(ep: Epoch, route: SignalRoute, *, bound: bool = True, **kw) -> dict:
    """:func:`tunnelkit.rt.consistency.geometry_consistency` of ``ep``'s measurements through
    ``route``'s tunnel planes (the UE hypotheses kept inside the tunnel). ``bound=True``: the
    residuals in CRLB standard deviations at the estimate (:func:`bound_sigmas`) plus any
    ``floor_angle`` / ``floor_range`` in ``kw``; ``bound=False``: the floors alone (``kw`` must
    give at least one). Other ``kw``: the test's options (``pfa``, ``n_los``, ...)."""
    instance("ep", ep, Epoch)
    instance("route", route, SignalRoute)
    m = ep.measurements
    if boolean("bound", bound):
        sig = bound_sigmas(ep.estimates, ep.array, route.config, m.index)
        if sig.shape[0] != len(m):
            raise RuntimeError("bound_sigmas: rows differ from the epoch's measurements")
    else:
        if not (kw.get("floor_angle") and kw.get("floor_range")):
            raise ValueError("bound: without the bound, give floor_angle and floor_range")
        sig = np.zeros((len(m), 3))
    kw.setdefault("inside", route.tunnel.contains)
    return geometry_consistency(
        m.direction, m.d, m.origin, tunnel_planes(route.tunnel), sig[:, 0], sig[:, 1], sig[:, 2],
        **kw,
    )  # fmt: skip
