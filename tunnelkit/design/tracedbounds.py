"""The bounds over the drive of what the traced route's trackers are told: a prediction there.

On the ray-traced channel the design's trackers (:mod:`tunnelkit.design.traced`) are told
measured sigmas, not each path's reported CRLB. The bounds over the drive beside them are those
of the told model: :func:`traced_bounds` every first-order path measured at every epoch with
independent Gaussian errors of the sigmas the ``"paths"`` tracker is told
(:func:`sigma_error_model`), :func:`los_bounds` the line of sight's two angles with the sigmas
the line-of-sight tracker reads from its table (:mod:`tunnelkit.design.tracedlos`). The traced
errors are neither Gaussian nor independent, so these are predictions of the told model, not
bounds on what the channel allows (``docs/results/traced-robust.md`` measures trackers below
them).
"""

from __future__ import annotations

import numpy as np

from .._physical import start_spread
from .._validate import finite_array, instance, integer, positive
from ..geometry import spherical
from .bounds import route_geometry
from .drivebound import drive_bound, drive_pcrlb, position_information
from .errormodel import PathErrorModel
from .setup import DesignSetup, parse_array
from .trackerfix import START_SIGMA_M

__all__ = ["config_sigmas", "los_bounds", "sigma_error_model", "traced_bounds"]


def config_sigmas(config) -> dict:
    """``config``'s four sigmas (a JavelinConfig's ``sigma_phi``, ``sigma_psi`` [rad],
    ``sigma_kappa``, ``sigma_delta_d`` [m]) as ``{"phi", "psi", "kappa", "d"}``."""
    names = (("phi", "sigma_phi"), ("psi", "sigma_psi"), ("kappa", "sigma_kappa"),
             ("d", "sigma_delta_d"))  # fmt: skip
    try:
        return {k: float(getattr(config, a)) for k, a in names}
    except (AttributeError, TypeError, ValueError):
        raise TypeError(f"config: expected a JavelinConfig, got {type(config).__name__}") from None


def sigma_error_model(setup: DesignSetup, spec, sigmas: dict, *, epochs=None):
    """A :class:`~tunnelkit.design.errormodel.PathErrorModel` of ``spec``'s route (``epochs``:
    indices that subsample it, as :func:`~tunnelkit.design.bounds.route_geometry`) in which every
    first-order path the image method traces is measured at every epoch with independent
    zero-mean Gaussian errors of ``sigmas`` (``{"phi", "psi"}`` [rad], ``{"kappa", "d"}`` [m],
    each > 0): no bias, no calibration term, the truth and radial speed zero (the bounds over the
    drive use only the geometry's Jacobians and the covariance). Any channel: the geometry is
    the image method's. Returns ``(model, geometry)``."""
    instance("setup", setup, DesignSetup)
    spec = parse_array(spec)
    if not isinstance(sigmas, dict) or set(sigmas) != {"phi", "psi", "kappa", "d"}:
        raise ValueError(
            f"sigmas: expected {{'phi', 'psi', 'kappa', 'd'}} to a sigma, got {sigmas!r}"
        )
    names = ("phi", "psi", "kappa", "d")
    sig = np.array([positive(f"sigmas['{k}']", sigmas[k]) for k in names], dtype=float)
    g = route_geometry(setup, spec, epochs=epochs)
    t = setup.trajectory.t
    if epochs is not None:  # route_geometry checked them: whole numbers inside the route
        t = t[finite_array("epochs", epochs, ndim=1).astype(int)]
    T, P = g.exists.shape
    ex4 = np.repeat(g.exists, 4, axis=1)
    cov = np.where(ex4[:, :, None] & ex4[:, None, :], np.kron(np.eye(P), np.diag(sig**2)), np.nan)
    zero = np.where(g.exists[..., None], 0.0, np.nan) * np.ones((T, P, 4))
    model = PathErrorModel(
        t=np.asarray(t, float), exists=g.exists, kinds=g.kinds, truth=zero,
        v=np.where(g.exists, 0.0, np.nan), crlb=cov, cov=cov, bias=zero,
    )  # fmt: skip
    return model, g


def traced_bounds(
    setup: DesignSetup, spec, config, T: int | None = None, *, sigma_p0: float | None = None
) -> tuple:
    """The bounds over the first ``T`` epochs of ``spec``'s drive (default all; a ``T`` beyond
    the route is the whole route, as the sweep's ``n_epochs``) of a tracker
    told the sigmas of ``config`` (a :class:`~tunnelkit.tracking.javelin.JavelinConfig`:
    ``sigma_phi``, ``sigma_psi``, ``sigma_kappa``, ``sigma_delta_d``; the traced design's,
    :func:`traced_javelin`), every first-order path measured with independent Gaussian errors of
    those sigmas (:func:`sigma_error_model`): ``(pcrlb, drive)`` (T,) [m] as the design's
    Monte-Carlo reports them (:func:`~tunnelkit.design.drivebound.drive_pcrlb` from a start of
    ``sigma_p0`` [m] per axis, default :data:`~tunnelkit.design.trackerfix.START_SIGMA_M`;
    ``drive`` the same with no bias). What the told sigmas allow: the traced
    errors are neither Gaussian nor independent, so not a bound on what the channel allows."""
    instance("setup", setup, DesignSetup)
    spec = parse_array(spec)
    n = len(setup.trajectory)
    T = n if T is None else min(integer("T", T, minimum=1), n)
    sig = config_sigmas(config)
    sigma_p0 = START_SIGMA_M if sigma_p0 is None else start_spread("sigma_p0", sigma_p0)
    try:
        model, g = sigma_error_model(setup, spec, sig, epochs=np.arange(T))
    except ValueError as exc:  # a sigma of the config that is not > 0
        raise ValueError(f"config: {exc}") from None
    pc = drive_pcrlb(setup, position_information(model, g), sigma_p0=sigma_p0)
    return pc, drive_bound(pc, np.zeros_like(pc))


def los_bounds(
    setup: DesignSetup, spec, table, T: int | None = None, *, sigma_p0: float | None = None
) -> tuple:
    """As :func:`traced_bounds` for the line-of-sight tracker told ``table`` (an
    :class:`~tunnelkit.design.los.ElevationSigmas`): the posterior CRLB over the first ``T``
    epochs (default all) of the line of sight's two angles seen from ``spec``'s array, as
    independent Gaussian errors of the table's sigmas at the true elevation
    (:func:`~tunnelkit.design.los.los_angle_information`), from a start of ``sigma_p0`` [m] per
    axis: ``(pcrlb, drive)`` (T,) [m]. A prediction of the told model, not a bound: the traced
    errors are neither Gaussian nor independent, and a tenth of the epochs feed a reflection."""
    from .los import ElevationSigmas, los_angle_information  # the line of sight's, on demand

    instance("setup", setup, DesignSetup)
    spec = parse_array(spec)
    table = instance("table", table, ElevationSigmas)
    n = len(setup.trajectory)
    T = n if T is None else min(integer("T", T, minimum=1), n)
    sigma_p0 = START_SIGMA_M if sigma_p0 is None else start_spread("sigma_p0", sigma_p0)
    ue = setup.trajectory.position[:T]
    station = setup.signal_route(spec).arrays[0].origin
    saz, sel = table.at(spherical(ue - station)[:, 1])
    pc = drive_pcrlb(setup, los_angle_information(ue, station, saz, sel), sigma_p0=sigma_p0)
    return pc, drive_bound(pc, np.zeros_like(pc))
