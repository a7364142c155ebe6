"""The design's fast measurement route: a drive whose path measurements are drawn from a
:class:`~tunnelkit.design.errormodel.PathErrorModel` instead of synthesised and extracted.

The channel route (:func:`tunnelkit.simulation.simulate_drive` with ``extraction="route"``) builds
the ``M x Nf x Nt`` tensor of every epoch and runs the maximum-likelihood extraction on it; its
cost grows with the array (580 s for two 32 x 32 drives). An efficient extraction above its
threshold delivers the true path parameters plus an error the model describes, and *reports*
the CRLB at its estimate; :func:`bound_drive` hands the tracker exactly that:

* ``z = [phi, psi, kappa, d]`` of every existing path from :func:`~tunnelkit.design.errordraws.draw` (truth,
  bias, one array's calibration error, Gaussian error with the model's ``cov``);
* the reported covariance: the ``(phi, psi, kappa)`` block and the ``d`` standard deviation of
  the model's ``crlb`` (``report="crlb"``: what an efficient extraction reports when it ignores
  the impairments) or of its error budget (``report="budget"``,
  :meth:`PathErrorModel.budget`: the CRLB plus the covariance of the stated calibration
  tolerance and the bias of the terms the model leaves out, what an extraction reports that
  knows its array's tolerance but not its draw); the default ``"auto"`` is the CRLB for an
  ideal model and the budget otherwise. A tracker told micrometres while its measurements carry
  centimetres of calibration bias gates out the truth and diverges: notebook 08, section 7;
* the clock bias drawn per epoch as the channel route draws it
  (:func:`tunnelkit.channel.sample_clock_bias`, the radio's sigma and limit) and added to every
  ``d``;
* the radial speed ``v`` from the truth plus :data:`SIGMA_V` of white noise (the Doppler
  clutter test only compares it with the vehicle speed at metre-per-second level; the ideal
  bound on ``v`` is far smaller, so this is a conservative, documented stand-in);
* the share of that budget which repeats every epoch (:func:`~tunnelkit.design.errordraws.split`: one
  array's calibration error, the bias of the terms the model leaves out, as far as they keep
  their value from one epoch to the next) handed over beside it
  (``PathMeasurements.bias_cov``; the budget report only), so that the tracker carries it as a
  bias of the path's track (:class:`tunnelkit.tracking.javelin.ConsiderNoise`) instead of
  averaging it down as if it were drawn afresh every epoch;
* a curvature the array cannot resolve is not reported: where the reported budget's standard
  deviation of ``kappa`` exceeds :data:`KAPPA_RESOLVED` of the path's range the path is handed
  on without curvature (``kappa`` NaN, the far-field case an extraction reports as a plane-wave
  fit), instead of a draw that would be negative or a kilometre off;
* the paths ordered by measured ``d`` (an extraction does not know which path is the LoS) and
  Algorithm 1's ``d >= min_d`` applied as the route does (``SignalRoute.min_d``);
* the V2X speed and heading messages as :func:`tunnelkit.simulation.simulate_drive` draws them.

The model comes from :func:`tunnelkit.design.achievable.path_error_model` (the joint ideal CRLB
and, under impairments, the misspecified covariance, bias and calibration sensitivities);
:func:`model_truth` gives the true ``z`` of a route geometry in the same convention.
"""

from __future__ import annotations

import numpy as np

from .._physical import carrier
from .._validate import choice, instance, integer, nonnegative, rng_or_error
from ..constants import C
from . import errordraws
from .errormodel import PathErrorModel
from .geometry import RouteGeometry
from .setup import DesignSetup, parse_array
from .trackerfix import KAPPA_RESOLVED, REPORTS, BoundRoute

__all__ = [
    "SIGMA_V",
    "bound_drive",
    "bound_route",
    "model_truth",
]


#: standard deviation [m/s] of the radial speed handed to the tracker on the bound route
SIGMA_V = 0.05


def model_truth(g, fc: float) -> tuple[np.ndarray, np.ndarray]:
    """True ``z = [phi, psi, kappa, d]`` (T, P, 4) and radial speed ``v`` (T, P) [m/s] of every
    slot of a :class:`~tunnelkit.design.geometry.RouteGeometry` (NaN where a path is absent)."""
    instance("g", g, RouteGeometry), carrier("fc", fc)
    rel = g.source - g.origin[:, None, :]
    r = np.linalg.norm(rel, axis=-1)
    phi = np.arctan2(rel[..., 1], rel[..., 0])
    psi = np.arctan2(rel[..., 2], np.hypot(rel[..., 0], rel[..., 1]))
    z = np.stack([phi, psi, r, r], axis=-1)
    z = np.where(g.exists[..., None], z, np.nan)
    v = np.where(g.exists, C * g.doppler / fc, np.nan)
    return z, v


def _reported_blocks(model: PathErrorModel, report: str) -> tuple[np.ndarray, np.ndarray | None]:
    T, P = model.exists.shape
    ideal = model.phase_sigma_rad == 0 and model.gain_sigma_db == 0
    ideal = ideal and not np.any(model.bias) and np.array_equal(model.cov, model.crlb)
    if report == "crlb" or (report == "auto" and ideal):
        idx = np.arange(P)
        return np.moveaxis(model.crlb.reshape(T, P, 4, P, 4)[:, idx, :, idx, :], 0, 1), None
    white, repeating = errordraws.split(model)
    return white + repeating, repeating


def bound_route(
    model: PathErrorModel,
    setup: DesignSetup,
    spec,
    *,
    report: str = "auto",
) -> BoundRoute:
    """The per-array part of :func:`bound_drive`, computed once (:class:`BoundRoute`)."""
    from .bounds import route_geometry

    if not isinstance(model, PathErrorModel):
        raise TypeError(f"model: expected a design.PathErrorModel, got {type(model).__name__}")
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    spec = parse_array(spec)
    if model.n_elements is not None and model.n_elements != spec.n_elements:
        raise ValueError(
            f"spec: the model was built for {model.n_elements} elements, {spec.label} has "
            f"{spec.n_elements}"
        )
    report = choice("report", report, REPORTS)
    T = model.exists.shape[0]
    if T != len(setup.trajectory):
        raise ValueError(f"model: expected {len(setup.trajectory)} epochs (the route's), got {T}")
    origin = route_geometry(setup, spec, epochs=np.arange(T)).origin
    blocks, repeating = _reported_blocks(model, report)
    return BoundRoute(
        model,
        spec.label,
        report,
        blocks,
        errordraws.noise_sqrt(model),
        origin,
        float(setup.signal_route(spec).min_d),
        repeating,
    )


def bound_drive(
    model: PathErrorModel | BoundRoute,
    setup: DesignSetup,
    spec,
    rng: np.random.Generator,
    *,
    n_epochs: int | None = None,
    sigma_v: float = SIGMA_V,
    report: str = "auto",
    calibration: tuple | None = None,
):
    """One drive of ``setup``'s route for ``spec`` measured through ``model`` (module docstring):
    a :class:`tunnelkit.simulation.DriveData` the tracker runs on exactly as on the channel route
    (``extraction="bound"``, reported covariances). ``n_epochs`` keeps the first epochs only.
    ``model`` may be a :class:`BoundRoute` of ``spec`` (:func:`bound_route`, computed once per
    array; its own ``report`` then applies): the same drive, without recomputing the array's
    share of it. ``calibration``: the unit's calibration draw
    (:func:`~tunnelkit.design.errordraws.draw_calibration`; ``None``: drawn from ``rng``, a unit per drive)."""
    choice("report", report, REPORTS)
    if isinstance(model, BoundRoute):
        prepared = model
        if parse_array(spec).label != prepared.label:
            raise ValueError(
                f"spec: the prepared route is {prepared.label}'s, got {parse_array(spec).label}"
            )
        if not isinstance(setup, DesignSetup):
            raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    else:
        prepared = bound_route(model, setup, spec, report=report)
    rng = rng_or_error("rng", rng)
    sigma_v = nonnegative("sigma_v", sigma_v)
    T = prepared.model.exists.shape[0]
    if T != len(setup.trajectory):
        raise ValueError(f"model: expected {len(setup.trajectory)} epochs (the route's), got {T}")
    if n_epochs is not None:
        T = min(integer("n_epochs", n_epochs, minimum=1), T)
    return indexed_drive(prepared, setup, rng, T, sigma_v, calibration)


def indexed_drive(
    prepared: BoundRoute,
    setup: DesignSetup,
    rng: np.random.Generator,
    T: int,
    sigma_v: float,
    calibration: tuple | None,
    rows: np.ndarray | None = None,
    origin: np.ndarray | None = None,
    served: np.ndarray | None = None,
    units: np.ndarray | None = None,
    odometry=None,
):
    """:func:`bound_drive` on checked arguments, its first ``T`` epochs. ``rows`` (T,): the row
    of ``prepared`` (its model's epoch) each epoch of the drive draws from (``None``: epoch
    ``k`` from row ``k``); ``origin`` (T, 3): each epoch's reference antenna, then handed to the
    tracker as the epoch's ``PathMeasurements.site``; ``served`` (T,) bool: the epochs that
    carry a measurement (the others ``None``: no site in range); ``units`` (T,): the array unit
    that measures each epoch, ``calibration`` then a list of every unit's draw (one per site).
    A row of sites draws its measurements this way from the model of one site
    (:mod:`tunnelkit.design.sites`). ``odometry``: the V2X messages' model
    (:class:`tunnelkit.odometry.Odometry`, checked; ``None``: the setup's trajectory's, its
    scenario's ``[odometry]``)."""
    from ..channel import sample_clock_bias
    from ..simulation.drives import DriveData
    from ..tracking.measurements import PathMeasurements

    model = prepared.model
    traj, cfg = setup.trajectory, setup.config
    min_d = prepared.min_d
    if rows is None:
        z = errordraws.draw(model, rng, noise_sqrt=prepared.noise_sqrt, calibration=calibration)[:T]
        model_rows = slice(0, T)
    else:
        model_rows = rows = np.asarray(rows)[:T]
        units = None if units is None else np.asarray(units)[:T]
        z = _draw_rows(model, prepared.noise_sqrt, rows, rng, calibration, units)
    ex = model.exists[model_rows]
    P = ex.shape[1]
    bias = sample_clock_bias(rng, cfg.clock_bias_sigma, cfg.clock_bias_limit, size=T)
    v = model.v[model_rows] + sigma_v * rng.standard_normal((T, P))
    per_path = prepared.blocks[model_rows]
    rep = None if prepared.repeating is None else prepared.repeating[model_rows]
    truth = model.truth[model_rows]
    epochs, tidx, kinds, los = [], [], [], np.zeros(T, bool)
    n_true = ex.sum(axis=1)
    for k in range(T):
        j = np.flatnonzero(ex[k])
        d = z[k, j, 3] + C * bias[k]
        o = j[np.argsort(d, kind="stable")]
        d = z[k, o, 3] + C * bias[k]
        blocks = per_path[k, o]  # (n, 4, 4)
        kap = z[k, o, 2]
        kap = np.where(np.sqrt(blocks[:, 2, 2]) <= KAPPA_RESOLVED * truth[k, o, 3], kap, np.nan)
        pm = PathMeasurements.from_arrays(
            z[k, o, 0],
            z[k, o, 1],
            kap,
            d,
            v[k, o],
            warn=False,
            cov=blocks[:, :3, :3],
            sigma_d=np.sqrt(blocks[:, 3, 3]),
            min_d=min_d,
            bias_cov=None if rep is None else rep[k, o],
        )
        if origin is not None:
            pm.site = origin[k].copy()  # the serving site's reference antenna (checked: (3,))
        if served is not None and not served[k]:
            pm = None  # no site in range: the tracker predicts only
        epochs.append(pm)
        tidx.append(o[pm.source] if pm is not None else np.zeros(0, dtype=int))
        kinds.append([model.kinds[p] for p in o])
        los[k] = bool(ex[k, 0]) and model.kinds[0] == "los"
    origin = prepared.origin[:T] if origin is None else origin[:T]
    vel = traj.velocity[:T]
    # the V2X messages of every bound-route drive (one site or a row of sites), drawn as the
    # drive simulator draws them (the white model: the same draws as simulation.drives)
    truth_motion = np.linalg.norm(vel[:, :2], axis=1), np.arctan2(vel[:, 1], vel[:, 0])
    odometry = traj.odometry if odometry is None else odometry
    speed, heading = odometry.draw(traj.t[:T], *truth_motion, rng)
    return DriveData(
        setup.name,
        None,
        traj.t[:T].copy(),
        traj.position[:T].copy(),
        vel.copy(),
        speed,
        heading,
        epochs,
        los,
        n_true,
        origin[-1].copy(),
        tidx,
        kinds,
        [],
        [np.zeros((0, 3)) for _ in range(T)],
        "bound",
        cfg.clock_bias_limit,
        True,
    )


def _draw_rows(model: PathErrorModel, noise_sqrt, rows, rng, calibration, units=None) -> np.ndarray:
    """:func:`~tunnelkit.design.errordraws.draw` of the model's epochs ``rows`` (one per drive epoch, a row
    may repeat): the same order of draws (the calibration first when not given, then one
    standard normal vector per drive epoch), so ``rows = arange(T)`` draws what ``draw`` does.
    ``units`` (T,): each epoch's array unit, ``calibration`` a list of their draws."""
    P = model.exists.shape[1]
    if units is None:
        phase, gain = (
            errordraws.draw_calibration(model, rng) if calibration is None else calibration
        )
        cal = errordraws.calibration_bias(model, phase, gain)[rows]
    else:
        cal = np.stack([errordraws.calibration_bias(model, *c) for c in calibration])[units, rows]
    e = rng.standard_normal((len(rows), 4 * P, 1))
    noise = (noise_sqrt[rows] @ e)[..., 0].reshape(len(rows), P, 4)
    z = (model.truth + model.bias)[rows] + cal + noise
    return np.where(model.exists[rows][..., None], z, np.nan)
