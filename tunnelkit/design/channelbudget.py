"""The design's impairment budget handed to the channel route (:func:`channel_budget`).

On the bound route (:mod:`tunnelkit.design.fastroute`) the tracker is told each path's error
budget (:func:`~tunnelkit.design.errordraws.split`: the noise covariance, the
stated calibration tolerance and the bias of the terms the model leaves out) and the share of it
that repeats. On the channel route the extraction reports the noise share itself (the CRLB at
its estimate); :func:`channel_budget` gives the rest, per candidate slot of the route geometry
(one slot per surface: the LoS, each wall, the ceiling, the road, each road-marking column), as a
:class:`tunnelkit.signal_route.judging.BiasBudget` the route matches to its estimates by
direction and delay. Under calibration error the route also re-judges a fit its white-noise
test flags (``RouteOptions.model_error_floor``, :mod:`tunnelkit.signal_route.judging`).
"""

from __future__ import annotations

import numpy as np

from .._validate import instance
from ..signal_route.judging import BiasBudget
from .errordraws import split
from .errormodel import PathErrorModel
from .setup import DesignSetup, parse_array

__all__ = ["channel_budget", "channel_route_budget"]


def channel_budget(model: PathErrorModel, setup: DesignSetup, spec) -> BiasBudget:
    """The impairment budget of ``model`` (``spec``'s, over ``setup``'s whole route) by slot:
    ``extra`` = the budget's white share less the noise covariance ``cov``, plus its repeating
    share (:func:`~tunnelkit.design.errordraws.split`), ``repeating`` that share; sources and reference
    antennas from the route geometry the model was built on."""
    from .bounds import route_geometry

    instance("model", model, PathErrorModel)
    instance("setup", setup, DesignSetup)
    spec = parse_array(spec)
    T, P = model.exists.shape
    if T != len(setup.trajectory):
        raise ValueError(f"model: expected {len(setup.trajectory)} epochs (the route's), got {T}")
    g = route_geometry(setup, spec, epochs=np.arange(T))
    traced = model.exists if model.unresolved is None else model.exists | model.unresolved
    if g.exists.shape != (T, P) or not np.array_equal(g.exists, traced):
        raise ValueError(f"model: not built on {spec.label}'s route geometry (slots differ)")
    white, rep = split(model)
    idx = np.arange(P)
    noise = np.moveaxis(np.asarray(model.cov).reshape(T, P, 4, P, 4)[:, idx, :, idx, :], 0, 1)
    ex = model.exists[..., None, None]
    extra = np.where(ex, white - noise + rep, 0.0)
    return BiasBudget(g.source, g.exists, g.origin, extra, rep)


def channel_route_budget(setup: DesignSetup, spec, impairments) -> BiasBudget | None:
    """:func:`channel_budget` of the error model under ``impairments`` (a
    :class:`~tunnelkit.design.achievable.DesignImpairments`), None for none or ideal ones, and
    None where the model is undefined (a Fisher information singular at some epoch, e.g. the
    curvature of a 2 x 2 array: the route then reports the CRLB at the estimate alone, and the
    design reports that array's bound as undefined)."""
    from .achievable import DesignImpairments, path_error_model

    instance("setup", setup, DesignSetup)
    spec = parse_array(spec)
    if impairments is None:
        return None
    instance("impairments", impairments, DesignImpairments)
    if impairments.ideal:
        return None
    try:
        model = path_error_model(setup, spec, impairments)
    except ValueError:
        return None
    return channel_budget(model, setup, spec)
