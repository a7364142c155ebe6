"""The one drive simulator: a signal route driven along its trajectory, epoch by epoch.

Section 4 of Italiano et al. (2026) in two steps, so the expensive part is done once: this module
runs the signal route of notebook 03 (:class:`tunnelkit.signal_route.SignalRoute`: image method,
eq. 1 tensor with noise and clock bias, :func:`tunnelkit.extraction.extract_paths`, Algorithm 1)
for every epoch under a propagation *condition*, plus the V2X speed and heading messages
(``sigma_nu``, ``sigma_theta`` of section 4.2); :mod:`tunnelkit.simulation.scoring` then runs a
tracker on the stored measurements. The tables (notebook 04b, ``tunnelkit reproduce``), the
ablation, notebook 04 and the array design (``tunnelkit design``) all drive through
:func:`simulate_drive` / :func:`simulate_routes`, and one adapter,
:func:`path_measurements`, turns the route's measurements into the tracker's.

Conditions (section 4.3): ``"L"`` LoS, ``"N@0.5"`` LoS blocked with probability 0.5 per epoch,
``"N"`` LoS always blocked, ``"NoRRMs"`` the road markings removed. The paper does not say under
which visibility it ran NoRRMs; its numbers (worse than JAVELIN-N) suggest blocked LoS, and that
is our reading (``"NoRRMs-L"`` keeps the LoS, for comparison). Without a condition
(``condition=None``) the route is driven as it is, with no visibility draw (the array design).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from .._physical import speeds
from .._validate import (
    boolean,
    choice,
    instance,
    integer,
    probability,
    record,
    rng_or_error,
)
from ..extraction.ml import ml_paths
from ..odometry import SIGMA_HEADING, SIGMA_SPEED, Odometry
from ..signal_route import CHANNELS, MAX_SECOND_ORDER, Epoch, RouteOptions, SignalRoute
from ..signal_route.measurements import measure_epoch
from ..tracking.measurements import PathMeasurements

__all__ = [
    "CONDITIONS",
    "EXTRACTIONS",
    "FLAGGED",
    "HELD_OUT_SEED",
    "SIGMA_HEADING",
    "SIGMA_SPEED",
    "TUNING_SEEDS",
    "Condition",
    "DriveData",
    "path_measurements",
    "route_name",
    "scenario_route",
    "simulate_drive",
    "simulate_routes",
]


@dataclass(frozen=True)
class Condition:
    """A propagation condition: probability that the LoS exists in an epoch, RRMs present."""

    name: str
    los_probability: float
    rrms: bool = True

    def __post_init__(self) -> None:
        record(self)
        probability("los_probability", self.los_probability, open_interval=False)


CONDITIONS: dict[str, Condition] = {
    c.name: c
    for c in (
        Condition("L", 1.0),
        Condition("N@0.5", 0.5),
        Condition("N", 0.0),
        Condition("NoRRMs", 0.0, rrms=False),
        Condition("NoRRMs-L", 1.0, rrms=False),
    )
}


#: the shapes of a drive's fields: T epochs, positions and velocities in 3-D
_DRIVE_SHAPES = {
    **dict.fromkeys(("t", "speed", "heading", "los", "n_true"), ("T",)),
    **dict.fromkeys(("epochs", "truth_index", "kinds", "sources"), ("T",)),
    "truth": ("T", 3),
    "velocity": ("T", 3),
    "base_station": (3,),
}


@dataclass
class DriveData:
    """One simulated drive (one Monte-Carlo run of one condition): a tracker's whole input and
    the truth to score it; per epoch one :class:`PathMeasurements`, not one epoch's record.

    ``epochs[k]`` is the :class:`PathMeasurements` of epoch ``k`` (``None`` if extraction failed),
    ``truth`` (T, 3) / ``velocity`` (T, 3) the ground truth, ``speed`` / ``heading`` the V2X
    messages (NaN: lost), ``los`` whether the LoS path existed, ``n_true`` the traced path count,
    ``base_station`` the reference antenna, ``truth_index`` per epoch the matched true path of
    each measurement (-1: none), ``kinds`` per epoch the surface kind of each true path and
    ``sources`` its true wave source (the UE or a VUE), shape (n, 3), ``extraction`` the
    measurement route (:data:`EXTRACTIONS`), ``clock_bias_limit`` [s] the support of the clock
    bias (TeNFiLoc's consistency check of a LoS curvature against the delay). ``condition`` is
    ``None`` for a drive without a visibility draw; ``reports_covariance``: the route reported
    each path's covariance (``RouteOptions(report_covariance=True)``).
    """

    scenario: str
    condition: Condition | None
    t: np.ndarray
    truth: np.ndarray
    velocity: np.ndarray
    speed: np.ndarray
    heading: np.ndarray
    epochs: list[PathMeasurements | None]
    los: np.ndarray
    n_true: np.ndarray
    base_station: np.ndarray
    truth_index: list[np.ndarray] = field(default_factory=list)
    kinds: list[list[str]] = field(default_factory=list)
    faults: list[str] = field(default_factory=list)
    sources: list[np.ndarray] = field(default_factory=list)
    extraction: str = "paper"
    clock_bias_limit: float = 100e-9
    reports_covariance: bool = False

    def __post_init__(self) -> None:
        record(
            self,
            shapes=_DRIVE_SHAPES,
            positive=("clock_bias_limit",),
            allow_nan=("speed", "heading"),  # a V2X message lost
            may_be_empty=("truth_index", "kinds", "faults", "sources"),
        )
        speeds("velocity", self.velocity)
        speeds("speed", self.speed[np.isfinite(self.speed)], vectors=False)

    @property
    def dt(self) -> float:
        """Epoch period [s]."""
        return float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.1


#: measurement routes, all from the same tensors: ``"paper"`` the CPD and eq. 11-24 as published
#: (with the joint root refinement, ``extract_paths(refine="joint")``); ``"coherent"`` the same,
#: then paths merged in one CPD component separated by the array (``refine="coherent"``);
#: ``"ml"`` the joint maximum-likelihood fit of eq. 1 (``refine="ml"``, at the CRLB)
#: ``"route"`` the route's own extraction (:func:`~tunnelkit.extraction.extract_paths` with its
#: defaults, what :meth:`SignalRoute.epoch` runs), as the array design uses it
EXTRACTIONS = ("paper", "coherent", "ml", "route")

#: older name of a route
_ALIASES = {"separated": "coherent"}

#: the tuning seeds of the JAVELIN designs: seed 0 (the ML route's measurement noise of
#: :func:`~tunnelkit.tracking.javelin.designs.ours_ml` and its joint innovation test) and seed 7
#: (the CPD-route settings of :func:`~tunnelkit.tracking.javelin.designs.ours`)
TUNING_SEEDS = (0, 7)

#: the held-out seed of the JAVELIN tables: never looked at while choosing anything (designs,
#: sigmas, settings); every choice was made on :data:`TUNING_SEEDS`
HELD_OUT_SEED = 20261202


def route_name(extraction: str) -> str:
    """The route's name in :data:`EXTRACTIONS` (``"separated"`` is ``"coherent"``)."""
    e = _ALIASES.get(extraction, extraction)
    if e not in EXTRACTIONS:
        raise ValueError(f"extraction: expected one of {EXTRACTIONS}, got {extraction!r}")
    return e


_ROUTES: dict[tuple, SignalRoute] = {}


def _nuisance(nuisance) -> dict:
    """``nuisance`` checked: ``None`` or a dict of ``second_order`` (int) / ``diffuse_floor``."""
    if nuisance is None:
        return {}
    if not isinstance(nuisance, dict):
        raise TypeError(
            f"nuisance: expected a dict of second_order / diffuse_floor, got {type(nuisance).__name__}"
        )
    unknown = sorted(map(str, set(nuisance) - {"second_order", "diffuse_floor"}))
    if unknown:
        raise ValueError(f"nuisance: expected second_order / diffuse_floor, got {unknown}")
    out = {}
    if "second_order" in nuisance:
        out["second_order"] = integer(
            "nuisance.second_order", nuisance["second_order"], minimum=0, maximum=MAX_SECOND_ORDER
        )
    if "diffuse_floor" in nuisance:
        out["diffuse_floor"] = boolean("nuisance.diffuse_floor", nuisance["diffuse_floor"])
    return out


def scenario_route(
    route, model: str = "exact", channel: str | None = None, nuisance: dict | None = None
) -> SignalRoute:
    """``route`` itself (a :class:`SignalRoute`; ``channel``, if given, must be its own), or the
    route of a scenario name built once per ``(name, model, channel, nuisance)`` and kept
    (``channel`` :data:`~tunnelkit.signal_route.CHANNELS`, "image" by default; ``nuisance`` the
    route's ``second_order`` / ``diffuse_floor`` options, none by default)."""
    nuisance = _nuisance(nuisance)
    if isinstance(route, SignalRoute):
        if channel is not None and channel != route.channel:
            raise ValueError(
                f"channel: the route given runs on the {route.channel!r} channel, not {channel!r}"
            )
        return route.with_options(**nuisance) if nuisance else route
    if not isinstance(route, str) or not route:
        raise TypeError(f"route: expected a SignalRoute or a scenario name, got {route!r}")
    if channel is not None:
        choice("channel", channel, CHANNELS)
    key = (route, model, channel or "image", tuple(sorted(nuisance.items())))
    if key not in _ROUTES:
        _ROUTES[key] = SignalRoute.from_scenario(
            route, channel=channel or "image", options=RouteOptions(model=model, **nuisance)
        )
    return _ROUTES[key]


#: the reason an epoch the extraction flagged itself (``fit_ok = False``) carries no measurement
FLAGGED = "extraction flagged its own fit (fit_ok = False)"


def path_measurements(ep, route: SignalRoute) -> tuple[PathMeasurements | None, str | None]:
    """The tracker's measurements of one simulated epoch (``ep.measurements`` through Algorithm 1
    with ``route.min_d``, ``source`` its rows, the index of ``ep.truth_index``), or ``None`` and
    the reason: a route that reports covariances (``report_covariance``) gives none for a fit
    that failed its own residual test (or whose Fisher information is singular), and such an
    epoch carries no measurement (the tracker predicts only). An extraction that tests its own
    fit (the ML route: ``PathEstimates.fit_ok``) and flags it — a path missed, merged or in a wrong
    basin of the likelihood, or the snapshot in the threshold region — gives none either, with
    the reason :data:`FLAGGED`, unless the route re-judged the fit against noise plus its
    impairment power and it passed (``Epoch.fit_ok``, ``RouteOptions.model_error_floor``). The
    repeating share of the error a route with a bias budget reports goes on as ``bias_cov``."""
    instance("ep", ep, Epoch)
    instance("route", route, SignalRoute)
    m = ep.measurements
    if ep.fit_ok is False:
        return None, FLAGGED
    if route.options.report_covariance and m.cov is None and len(m):
        return None, "extraction failed its residual test"
    pm = PathMeasurements.from_arrays(
        m.phi,
        m.psi,
        m.kappa,
        m.d,
        m.v,
        warn=False,
        cov=m.cov,
        sigma_d=m.sigma_d,
        min_d=route.min_d,
        bias_cov=m.bias_cov,
    )
    return pm, None


def _condition(condition) -> Condition | None:
    if condition is None or isinstance(condition, Condition):
        return condition
    if isinstance(condition, str) and condition in CONDITIONS:
        return CONDITIONS[condition]
    raise ValueError(f"condition: expected one of {list(CONDITIONS)} or None, got {condition!r}")


def simulate_drive(
    route,
    rng: np.random.Generator,
    *,
    condition: str | Condition | None = "L",
    extraction: str = "paper",
    model: str = "exact",
    n_epochs: int | None = None,
    channel: str | None = None,
    nuisance: dict | None = None,
    odometry: Odometry | None = None,
) -> DriveData:
    """Drive ``route`` (a :class:`SignalRoute` or a scenario name, built with ``model``) under
    ``condition`` and measure every epoch through ``extraction`` (``rng`` explicit).

    Per epoch: with a condition, the LoS kept with its probability (one uniform draw per epoch)
    and the RRMs removed for ``NoRRMs``; the noisy SRS tensor synthesised (clock bias drawn per
    epoch); paths extracted with ``L`` known (Algorithm 1); angles in the world frame.
    ``extraction`` is a route of :data:`EXTRACTIONS`: ``"paper"`` (the CPD route of eq. 11-24,
    with the joint root refinement), ``"coherent"`` (the same, then coherent paths merged in one
    CPD component separated by the array,
    :func:`tunnelkit.extraction.coherent.resolve_coherent`; alias ``"separated"``), ``"ml"`` (the
    joint maximum-likelihood fit from its own start) or ``"route"`` (the route's own extraction,
    :meth:`SignalRoute.epoch`). An extraction failure leaves ``None`` (the tracker then predicts
    only) and is recorded in ``faults``. ``channel``: the route's channel source
    (:func:`scenario_route`; "sionna" is the ray-traced channel); ``nuisance`` the route's
    ``second_order`` / ``diffuse_floor`` (:func:`scenario_route`); ``odometry`` the V2X messages'
    model (:func:`simulate_routes`).
    """
    return simulate_routes(
        route,
        rng,
        condition=condition,
        extractions=(extraction,),
        model=model,
        n_epochs=n_epochs,
        channel=channel,
        nuisance=nuisance,
        odometry=odometry,
    )[route_name(extraction)]


def _ml_only_epoch(route: SignalRoute, k: int, rng: np.random.Generator, tunnel):
    """Epoch ``k`` of a drive measured by the ML route alone: the slot drawn as
    :meth:`SignalRoute.epoch` draws it, then :func:`~.reextract.ml_epoch`'s extraction and measurements,
    without the paper route's extraction, which the ML route does not use (it starts from its
    own CPD): the same epoch as ``ml_epoch(route.epoch(...), ...)``, the same draws."""
    arr, paths, snap = route.draw(k, rng, tunnel=tunnel)
    est = ml_paths(
        snap.H, len(paths), arr, route.config, noise_power=route.ml_noise_power(k, snap, tunnel)
    )
    meas, truth = measure_epoch(est, arr, paths, snap, None, 0.0)
    traj = route.trajectory
    return Epoch(
        k, float(traj.t[k]), traj.position[k].copy(), traj.velocity[k].copy(), arr, paths, snap,
        est, meas, truth,
    )  # fmt: skip


def _accumulator(T: int) -> dict:
    """One route's per-epoch record of a drive (filled by :func:`_record`)."""
    return {
        "epochs": [],
        "los": np.zeros(T, bool),
        "n_true": np.zeros(T, int),
        "tidx": [],
        "kinds": [],
        "faults": [],
        "sources": [],
    }


def _record(a: dict, k: int, ep, pm, reason: str | None) -> None:
    """Epoch ``k`` of one route into its accumulator ``a``: the measurements ``pm`` of ``ep``, or
    a fault with ``reason`` when either is ``None``."""
    if ep is not None:
        a["n_true"][k] = len(ep.paths)
    if ep is None or pm is None:
        a["faults"].append(f"epoch {k}: {reason}")
        a["epochs"].append(None)
        a["tidx"].append(np.zeros(0, int))
        a["kinds"].append([])
        a["sources"].append(np.zeros((0, 3)))
        return
    a["los"][k] = any(p.kind == "los" for p in ep.paths)
    a["epochs"].append(pm)
    a["tidx"].append(np.asarray(ep.truth_index)[pm.source])
    a["kinds"].append([p.surface_kind for p in ep.paths])
    a["sources"].append(np.array([p.source for p in ep.paths]).reshape(-1, 3))


def _adapters(adapters, extractions: tuple[str, ...]) -> dict:
    """``adapters`` checked: ``{name: (extraction, callable)}``, each extraction one of
    ``extractions``, each name new."""
    if adapters is None:
        return {}
    if not isinstance(adapters, dict):
        raise TypeError(
            f"adapters: expected a dict of name: (extraction, adapter), got {type(adapters).__name__}"
        )
    out = {}
    for name, spec in adapters.items():
        if not isinstance(name, str) or not name or name in extractions or name in EXTRACTIONS:
            raise ValueError(
                f"adapters: expected new route names (not one of {EXTRACTIONS}), got {name!r}"
            )
        if not isinstance(spec, tuple) or len(spec) != 2 or not callable(spec[1]):
            raise TypeError(f"adapters: {name!r} must map to (extraction, callable), got {spec!r}")
        base = route_name(spec[0])
        if base not in extractions or base == "route":
            raise ValueError(
                f"adapters: {name!r} measures the epochs of {base!r}, which is not one of the "
                f"extractions {list(extractions)}"
            )
        out[name] = (base, spec[1])
    return out


def simulate_routes(
    route,
    rng: np.random.Generator,
    *,
    condition: str | Condition | None = "L",
    extractions: tuple[str, ...] = ("paper", "coherent", "ml"),
    model: str = "exact",
    n_epochs: int | None = None,
    channel: str | None = None,
    nuisance: dict | None = None,
    adapters: dict | None = None,
    odometry: Odometry | None = None,
) -> dict[str, DriveData]:
    """One drive (:func:`simulate_drive`) measured through every route in ``extractions``.

    Each epoch's tensor is synthesised and decomposed once: the paper's route (CPD, joint root
    refinement) runs on it and the coherent route starts from those estimates, the ML route runs
    its own start on the same tensor; ``"route"`` is the route's own extraction and cannot be
    combined with the others (it draws the tensor itself). ``channel`` and ``nuisance`` as in
    :func:`scenario_route`. ``adapters``: extra routes measured from the same epochs, ``{name:
    (extraction, adapter)}``: ``adapter(ep, route) -> (PathMeasurements | None, reason)`` turns
    the epoch of ``extraction`` (one of ``extractions``) into the tracker's measurements instead
    of :func:`path_measurements` (no extra draw, the other routes unchanged); the drive's
    ``extraction`` field is that extraction. Returns ``{extraction: DriveData}``, the adapters'
    names after the extractions. ``odometry``: the model of the V2X messages
    (:class:`tunnelkit.odometry.Odometry`, NaN for a message lost); ``None``: the route's
    (``route.trajectory.odometry``: its scenario's ``[odometry]``, the paper's white model
    :data:`tunnelkit.odometry.WHITE` where the scenario has none).
    """
    rng = rng_or_error("rng", rng)
    cond = _condition(condition)
    if odometry is not None:
        instance("odometry", odometry, Odometry)
    if channel is not None:
        choice("channel", channel, CHANNELS)
    if n_epochs is not None:
        integer("n_epochs", n_epochs, minimum=1)
    if isinstance(extractions, str) or not isinstance(extractions, tuple | list):
        raise TypeError(f"extractions: expected a tuple of routes, got {extractions!r}")
    if not extractions:
        raise ValueError(f"extractions: expected one or more of {EXTRACTIONS}, got none")
    extractions = tuple(dict.fromkeys(route_name(e) for e in extractions))
    if "route" in extractions and len(extractions) > 1:
        raise ValueError(
            f"extractions: 'route' (the route's own extraction) cannot be combined with "
            f"{[e for e in extractions if e != 'route']}"
        )
    adapters = _adapters(adapters, extractions)
    label = route if isinstance(route, str) else "route"
    route = scenario_route(route, model, channel, nuisance)
    kinds_all = tuple(route.kinds)
    no_los = replace(route, kinds=tuple(k for k in kinds_all if k != "los"))
    tunnel = route.tunnel if cond is None or cond.rrms else route.tunnel.without_plates()
    traj = route.trajectory
    odometry = traj.odometry if odometry is None else odometry
    T = len(traj) if n_epochs is None else min(int(n_epochs), len(traj))
    measure = {e: (e, path_measurements) for e in extractions} | adapters
    acc = {e: _accumulator(T) for e in measure}
    bs = None
    own = extractions == ("route",)
    ml_only = extractions == ("ml",)
    for k in range(T):
        has_los = True if cond is None else bool(rng.random() < cond.los_probability)
        r = route if has_los else no_los
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                if ml_only:  # the ML route starts from its own CPD: no paper route to run
                    ep0 = _ml_only_epoch(r, k, rng, tunnel)
                elif own:
                    ep0 = r.epoch(k, rng)
                else:
                    ep0 = r.epoch(k, rng, tunnel=tunnel, refine="joint")
            except (ValueError, np.linalg.LinAlgError) as exc:
                ep0, failure = None, exc
            except FloatingPointError as exc:  # the ML route's failures, as in redo_epoch
                if not ml_only:
                    raise
                ep0, failure = None, exc
            eps = {}
            for e in extractions:
                ep = ep0
                if ep is not None and e not in ("paper", "route") and not ml_only:
                    from .reextract import redo_epoch  # the coherent or the ML route

                    try:
                        ep = redo_epoch(ep0, e, r, tunnel)
                    except (ValueError, np.linalg.LinAlgError, FloatingPointError) as exc:
                        ep, failure = None, exc
                eps[e] = (ep, None if ep is not None else f"extraction failed ({failure})")
            for name, (e, adapt) in measure.items():
                ep, reason = eps[e]
                pm = None
                if ep is not None:
                    bs = ep.measurements.origin.copy()
                    pm, reason = adapt(ep, route)
                _record(acc[name], k, ep, pm, reason)
    if bs is None:
        bs = route.arrays[0].origin.copy()
    vel = traj.velocity[:T]
    truth = np.linalg.norm(vel[:, :2], axis=1), np.arctan2(vel[:, 1], vel[:, 0])
    speed, heading = odometry.draw(traj.t[:T], *truth, rng)
    return {
        name: DriveData(
            label,
            cond,
            traj.t[:T].copy(),
            traj.position[:T].copy(),
            vel.copy(),
            speed.copy(),
            heading.copy(),
            a["epochs"],
            a["los"],
            a["n_true"],
            bs.copy(),
            a["tidx"],
            a["kinds"],
            a["faults"],
            a["sources"],
            measure[name][0],
            route.config.clock_bias_limit,
            bool(route.options.report_covariance),
        )
        for name, a in acc.items()
    }
