"""An epoch of the signal route redone by another extraction on the same tensor: the coherent
route (:func:`separate_epoch`, ``coherent.resolve_coherent`` from the paper route's estimates) and
the ML route (:func:`ml_epoch`, ``L`` known); :func:`redo_epoch` picks one by route name, as
:func:`~tunnelkit.simulation.drives.simulate_routes` runs them after the paper's route.
"""

from __future__ import annotations

from .._validate import instance
from ..channel import SRSConfig
from ..extraction.coherent import resolve_coherent
from ..extraction.ml import ml_paths
from ..signal_route import Epoch, SignalRoute

__all__ = ["ml_epoch", "separate_epoch"]


def ml_epoch(ep, config, noise_power: float | None = None):
    """``ep`` with its estimates and measurements redone by the maximum-likelihood route
    (:func:`tunnelkit.extraction.ml.ml_paths`, ``L`` known) on the same tensor (``noise_power``:
    what its fit is tested against, estimated from the tensor by default)."""
    instance("ep", ep, Epoch)
    instance("config", config, SRSConfig)
    return ep.with_estimates(
        ml_paths(ep.snapshot.H, len(ep.paths), ep.array, config, noise_power=noise_power)
    )


def separate_epoch(ep, config):
    """``ep`` with its estimates and measurements redone by ``coherent.resolve_coherent``."""
    instance("ep", ep, Epoch)
    instance("config", config, SRSConfig)
    return ep.with_estimates(resolve_coherent(ep.snapshot.H, ep.estimates, ep.array, config))


def redo_epoch(ep0, e: str, route: SignalRoute, tunnel):
    """``ep0`` (the paper's route) redone by route ``e`` (the coherent or the ML route; any other
    route: ``ep0`` itself)."""
    if e == "coherent":
        return separate_epoch(ep0, route.config)
    if e == "ml":
        return ml_epoch(ep0, route.config, route.ml_noise_power(ep0.k, ep0.snapshot, tunnel))
    return ep0
