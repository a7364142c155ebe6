"""What the drives of one array share, and one drive: the per-array job of a design sweep.

:class:`ArrayJob` computes once per array (on the sweep's cluster, one task): the error model,
the bound route's shared part, the PEB, the bounds over the drive (every unit's and the one
pooled over units, :func:`~tunnelkit.design.drivebound.unit_pcrlb`), the predictions over the
drive and the tracker (:class:`Prepared`). :class:`SweepTrial` is one drive of one unit on
it: the unit's calibration draw, the drive's measurements, JAVELIN from the open-sky fix and
the 2-D error per epoch (:mod:`tunnelkit.design.montecarlo` runs them as one task set).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .._validate import instance
from ..odometry import Odometry
from .bounds import route_bounds, route_geometry
from .channelbudget import channel_route_budget
from .drivebound import (
    START_SIGMA_M,
    drive_bound,
    drive_pcrlb,
    position_bias_rms,
    position_information,
    unit_pcrlb,
)
from .errordraws import draw_calibration
from .errormodel import PathErrorModel
from .pathbounds import path_bounds
from .setup import ArraySpec, DesignSetup
from .verdict import counted_epochs

__all__ = ["START_HEIGHT_SIGMA_M", "design_planes", "javelin_config"]

#: the open-sky fix's height standard deviation [m]: a vehicle's antenna height is known (the
#: PEB and the bounds over the drive take it as known); the start's and the tracker's ``P_0``
START_HEIGHT_SIGMA_M = 0.05


def javelin_config(crlb: dict, min_d: float = 0.0, planes=None, odometry=None):
    """The design's JAVELIN: :func:`tunnelkit.tracking.javelin.arraydesign.array_design` (reported
    covariances, likelihood cost, measured births, the joint innovation test; ``crlb`` sets
    only the fixed fallback sigmas, ``min_d`` Algorithm 1's delay check; ``planes`` the
    tunnel's surfaces when the VUEs come from the known geometry), told the white noise of the
    drive's messages (``odometry``, the drive's model; None: the paper's 0.2 m/s and 1 deg)."""
    # the tracker and the drive simulator load on the first Monte-Carlo, not with the bounds
    from ..tracking.javelin.arraydesign import array_design

    if odometry is not None:
        instance("odometry", odometry, Odometry)
    design = array_design(crlb, min_d, planes)
    if odometry is None:
        return design
    noise = {"sigma_speed": odometry.speed_noise, "sigma_heading": odometry.heading_noise}
    if all(getattr(design.config, k) == v for k, v in noise.items()):
        return design  # the paper's white noise: the design as it is
    return design.with_(config=design.config.with_(**noise))


def design_planes(setup: DesignSetup) -> list:
    """The planes of the surfaces a design traces (:data:`tunnelkit.design.geometry.KINDS`)."""
    from .geometry import KINDS

    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    return [s.plane for s in setup.tunnel.surfaces if s.kind in KINDS]


def _trial_errors(estimates: np.ndarray, truth: np.ndarray) -> np.ndarray:
    return np.linalg.norm(estimates[:, :2] - truth[:, :2], axis=1)


@dataclass(frozen=True)
class SweepTrial:
    """One Monte-Carlo run of one array (picklable for Dask workers; sent to each worker once):
    a drive of the design's route through the chosen measurement route, JAVELIN, the 2-D error
    per epoch (T,). ``prep`` is the array's :class:`Prepared` (built once per array on the
    sweep's cluster, fetched once by each worker that runs its drives)."""

    setup: DesignSetup
    mode: str
    n_epochs: int | None
    impairments: object = None  # achievable.DesignImpairments: the channel mode's
    start: str = "drawn"
    start_sigma: float = START_SIGMA_M
    dead_reckoning: bool = False

    def __call__(self, item: tuple, rng: np.random.Generator) -> np.ndarray:
        from ..simulation import evaluate, simulate_drive, without_radio
        from ..tracking.javelin import draw_start

        prep, unit_seed = item  # the array's shared part, the unit's calibration seed
        unit = np.random.default_rng(unit_seed)  # this drive's own copy: the unit's draw
        spec = prep.spec
        if self.mode == "bound":
            from .fastroute import bound_drive

            cal = draw_calibration(prep.route.model, unit)  # the unit's, every drive the same
            drive = bound_drive(
                prep.route, self.setup, spec, rng, n_epochs=self.n_epochs, calibration=cal
            )
        elif self.setup.channel == "sionna" and prep.direct is not None:
            return self._direct(prep, rng)
        elif self.setup.channel == "sionna":
            from .traced import design_drive

            # the traced treatment (tunnelkit.design.traced): every epoch's ML measurements,
            # the geometry pre-filter; the tracker told this array's measured errors (a drive
            # of the same setup and seed, driven before in this process, is reused). The
            # line-of-sight tracker: of every epoch's measurements the line of sight, told its
            # sigmas by its elevation from this array's survey
            los = prep.los_table is not None
            kind = "ml-all" if los else "ml-traced"
            drive = design_drive(self.setup, spec, rng, n_epochs=self.n_epochs, kind=kind)
            if los:
                from .tracedlos import told_los

                drive = told_los(drive, prep.los_table, prep.design.config)
        else:
            route = self.setup.signal_route(spec)
            imp = self.impairments
            if imp is not None and not imp.ideal:
                # the unit's calibration error (every drive of the unit the same); fits judged
                # against noise + it
                route = route.with_impairments(imp.channel_impairments(), unit)
                route = route.with_options(
                    model_error_floor=True, bias_budget=prep.budget, centroid_unresolved=True
                )
            if imp is not None and imp.wideband_model:
                route = route.with_options(wideband_model=True)
            drive = simulate_drive(
                route, rng, condition=None, extraction="route", n_epochs=self.n_epochs
            )
        sigma = self.start_sigma
        # the open-sky fix: drawn after the drive (the drive's draws do not depend on it)
        sh = START_HEIGHT_SIGMA_M
        p0 = draw_start(drive.truth[0], sigma, rng, sh) if self.start == "drawn" else None
        ev = evaluate(drive, prep.design, sigma_p0_ue=sigma, start=p0, sigma_p0_height=sh)
        err = _trial_errors(ev.estimates, drive.truth)
        if not self.dead_reckoning:
            return err
        # the same tracker, start and V2X messages with every measurement dropped
        alone = without_radio(drive)
        ev = evaluate(alone, prep.design, sigma_p0_ue=sigma, start=p0, sigma_p0_height=sh)
        return np.stack([err, _trial_errors(ev.estimates, drive.truth)])

    def _direct(self, prep, rng: np.random.Generator) -> np.ndarray:
        """One drive of the direct tracker (:mod:`tunnelkit.design.traceddirect`): its
        measurements depend on its own track, so the drive and the tracker run together, dead
        reckoning on the same messages beside it; the open-sky fix drawn from a generator
        spawned before the drive's."""
        from ..tracking.javelin import draw_start
        from .traced import traced_route
        from .traceddirect import DESIGN_OPTIONS, direct_drive

        route = traced_route(self.setup, prep.spec)
        n = None if self.n_epochs is None else min(self.n_epochs, len(route.trajectory))
        rng, g = rng.spawn(2)
        sh, sigma = START_HEIGHT_SIGMA_M, self.start_sigma
        drawn = self.start == "drawn"
        p0 = draw_start(route.trajectory.position[0], sigma, g, sh) if drawn else None
        out = direct_drive(route, rng, prep.design, None, prep.direct, n_epochs=n,
                           start_sigma=sigma, start_height_sigma=sh, start=p0,
                           **DESIGN_OPTIONS)  # fmt: skip
        err = _trial_errors(out.estimates["direct"], out.truth)
        if not self.dead_reckoning:
            return err
        return np.stack([err, _trial_errors(out.estimates["dead reckoning"], out.truth)])


def _model(setup, spec, error_models, impairments=None) -> PathErrorModel:
    from .achievable import path_error_model

    if error_models is None:
        m = path_error_model(setup, spec, impairments=impairments)
    elif callable(error_models):
        m = error_models(setup, spec)
    elif isinstance(error_models, dict) and spec.label in error_models:
        m = error_models[spec.label]
    else:
        raise ValueError(
            f"error_models: expected None, a callable (setup, spec) -> PathErrorModel or a "
            f"dict by array label holding {spec.label!r}"
        )
    if not isinstance(m, PathErrorModel):
        raise TypeError(
            f"error_models: expected PathErrorModel for {spec.label}, got {type(m).__name__}"
        )
    return m


@dataclass(frozen=True)
class Prepared:
    """What the drives of one array share (:class:`ArrayJob`): the bound route's shared part
    (``route``, bound mode), the tracker (``design``) and the bounds reported beside them."""

    spec: ArraySpec
    route: object  # trackerfix.BoundRoute (bound mode) or None
    design: object  # tracking.javelin.JavelinDesign
    peb: np.ndarray
    pcrlb: np.ndarray | None
    drive: np.ndarray | None
    budget: object = None  # signal_route.judging.BiasBudget: the channel route's, impaired
    error_model: dict | None = None  # traced.error_model_summary: the traced route's
    hybrid: np.ndarray | None = None  # the bound pooled over units (drivebound.unit_pcrlb)
    los_table: object = None  # los.ElevationSigmas: the traced route's line-of-sight tracker
    direct: object = None  # los.ElevationSigmas: the direct tracker's told sigmas (traceddirect)

    def summary(self) -> tuple:
        """What the sweep's result keeps (not the model and route the drives need)."""
        return (
            self.peb,
            self.pcrlb,
            self.drive,
            self.design.config,
            self.error_model,
            self.hybrid,
        )


@dataclass(frozen=True)
class ArrayJob:
    """Everything a sweep computes once per array, before its drives (one task per array, on
    the sweep's cluster when it has one): the error model, the bound route's shared part, the
    PEB, the bounds over the drive and the tracker (:class:`Prepared`)."""

    setup: DesignSetup
    error_models: object
    mode: str
    T: int
    with_model: bool
    crlbs: dict | None
    impairments: object = None
    start_sigma: float = START_SIGMA_M
    traced_tracker: str = "paths"  # tracedtracker.TRACED_TRACKERS: the ray-traced channel's tracker

    def __call__(self, spec: ArraySpec) -> Prepared:
        ep = np.arange(self.T)
        peb = route_bounds(self.setup, spec, epochs=ep).peb
        m = route = pc = hybrid = drive = None
        if self.with_model:
            m = _model(self.setup, spec, self.error_models, self.impairments)
            if self.mode == "bound":
                from .fastroute import bound_route

                route = bound_route(m, self.setup, spec)
            g = route_geometry(self.setup, spec, epochs=ep)
            head = model_head(m, self.T)
            sp0 = self.start_sigma
            # the bounds: every unit's (its calibration draw known to the bound) and the one
            # pooled over units (the draw a fixed unknown of the drive, with its prior)
            pc = unit_pcrlb(self.setup, head, g, sigma_p0=sp0, calibration=False)
            calibrated = head.phase_sigma_rad > 0 or head.gain_sigma_db > 0
            hybrid = unit_pcrlb(self.setup, head, g, sigma_p0=sp0) if calibrated else pc
            # the prediction (not a bound): the noise and the bias of a fix weighted as the
            # tracker weighs (its reported budget, one block per path, bound mode; on the
            # channel route the extraction reports its CRLB)
            w = None
            if route is not None:
                from .trackerfix import tracker_weights

                w = tracker_weights(route)[: self.T]
            pc_w = drive_pcrlb(self.setup, position_information(head, g, w), sigma_p0=sp0)
            drive = drive_bound(pc_w, position_bias_rms(head, g, w))
        crlb = None if self.crlbs is None else self.crlbs.get(spec.label)
        if crlb is None and m is not None:
            crlb = median_sigmas(m)
        if crlb is None:  # the paths the array resolves (an unresolved one is a gap)
            pb = path_bounds(self.setup, spec)
            ok = np.all([np.isfinite(pb[k]) for k in ("d", "direction", "kappa")], axis=0)
            if not ok.any():
                raise ValueError(
                    f"arrays: the {spec.label} array resolves no path anywhere on the route (its "
                    "per-path CRLB is infinite at every epoch); choose a larger array"
                )
            crlb = {k: float(np.median(pb[k][ok])) for k in ("d", "direction", "kappa")}
        design = javelin_config(
            crlb,
            self.setup.signal_route(spec).min_d,
            design_planes(self.setup),
            self.setup.trajectory.odometry,
        )
        imp = self.impairments if self.mode == "channel" else None  # its budget: channel, impaired
        budget = channel_route_budget(self.setup, spec, imp)
        error_model = table = None
        if self.mode == "channel" and self.setup.channel == "sionna":
            from . import traced, tracedbounds

            # this array's errors on the traced channel (cached with their provenance)
            rec = traced.design_errors(self.setup, spec, n_epochs=self.T)
            # the bounds of the sigmas the tracker is told, not of the image channel's CRLB
            # (a model's posterior CRLB, not a bound of the tracker on the traced channel,
            # whose errors are neither Gaussian nor independent: a prediction)
            pc, sp0, los, told = None, self.start_sigma, None, {}
            design = traced.traced_javelin(self.setup, spec, rec)  # "paths"
            if self.traced_tracker == "direct":
                return self._direct(spec, rec, design, peb, budget, hybrid)
            if self.traced_tracker != "los":
                told["paths"] = tracedbounds.traced_bounds(self.setup, spec, design.config,
                                                           self.T, sigma_p0=sp0)[1]  # fmt: skip
            fallback = None
            if self.traced_tracker != "paths":  # the line of sight, surveyed on the same drives
                from . import tracedlos

                try:
                    t = tracedlos.los_table(rec)
                except ValueError as exc:  # no survey in the record: "auto" keeps "paths"
                    if self.traced_tracker == "los":
                        raise
                    t, fallback = None, str(exc)
                if t is not None:
                    told["los"] = tracedbounds.los_bounds(self.setup, spec, t, self.T,
                                                          sigma_p0=sp0)[1]  # fmt: skip
                # "auto": the tracker whose told model predicts the smaller RMS over the
                # settled route (the row's prediction; a route too short to settle: all of it)
                try:
                    k = counted_epochs(self.setup.trajectory.t[: self.T])
                except ValueError:
                    k = np.arange(self.T)
                rms = {n: float(np.sqrt(np.mean(v[k] ** 2))) for n, v in told.items()}
                if min(rms, key=rms.get) == "los":
                    table, design = t, tracedlos.los_javelin(design)
                    los = tracedlos.los_summary(rec, t)
            drive = told["los" if los is not None else "paths"]
            error_model = traced.error_model_summary(rec, design.config, los)
            if self.traced_tracker == "auto":  # what it chose by
                error_model["chosen_by_predicted_rms_m"] = rms
                if fallback is not None:
                    error_model["auto_fallback"] = fallback
        return Prepared(spec, route, design, peb, pc, drive, budget, error_model, hybrid, table)

    def _direct(self, spec, rec, design, peb, budget, hybrid) -> Prepared:
        """The direct tracker's preparation (:mod:`tunnelkit.design.traceddirect`): the line of
        sight's JAVELIN fed the direct fix, told :func:`~.directsurvey.design_table`; the
        posterior CRLB of that told model beside it (a prediction, not a bound)."""
        from . import traced, tracedbounds, tracedlos
        from .directsurvey import design_table, direct_summary
        from .traceddirect import DESIGN_OPTIONS

        table = design_table(self.setup.name, spec)
        design = tracedlos.los_javelin(design)
        drive = tracedbounds.los_bounds(self.setup, spec, table, self.T,
                                        sigma_p0=self.start_sigma)[1]  # fmt: skip
        em = traced.error_model_summary(rec, design.config)
        em["told_sigmas"] = {k: em["told_sigmas"][k] for k in ("kappa_m", "delta_d_m")}
        em.update(tracker="direct", direct=direct_summary(self.setup.name, spec, DESIGN_OPTIONS))
        return Prepared(spec, None, design, peb, None, drive, budget, em, hybrid, None, table)


def load_tracker(direct: bool = False) -> None:
    """Import the tracker and the drive simulator (run on every worker before a sweep's tasks:
    a worker that imports them in a task while another thread unpickles a tracker sent from
    another worker deadlocks on the package's import locks); with ``direct`` also the direct
    fit's (the traced tracker ``"direct"``, :mod:`.traceddirect`), which no other sweep needs."""
    # the modules themselves: the packages load their names on first use, and the branches a
    # task may take load theirs (the first fix, the measured birth, the odometry states, the
    # channel route's epoch and the ML fit's moves)
    from .. import calibration  # noqa: F401
    from ..extraction.ml import merged, resolved, rho_reseed, split  # noqa: F401
    from ..signal_route import covariance, epoch  # noqa: F401
    from ..simulation import baselines, drives, reextract, scoring  # noqa: F401
    from ..tracking import reported  # noqa: F401
    from ..tracking.javelin import (  # noqa: F401
        arraydesign,
        designs,
        iterated,
        linearbirth,
        lostest,
        manage,
        measuredbirth,
        measurement,
        noise,
        odometrystates,
        reflector,
        roles,
        state,
        tracker,
        update,
    )
    from . import los, tracedlos  # noqa: F401  (the traced route's trackers)

    if direct:  # with the direct fit's modules (extraction.direct: fit, visibility, aperture)
        from . import traceddirect  # noqa: F401


def prepared_summary(prep: Prepared) -> tuple:
    return prep.summary()


def median_sigmas(m: PathErrorModel) -> dict[str, float]:
    """Route-median standard deviations of ``d`` [m], direction [rad] and ``kappa`` [m] in a
    model's reported bound (what :func:`path_bounds` gives, without evaluating it again)."""
    T, P = m.exists.shape
    var = np.diagonal(m.crlb, axis1=1, axis2=2).reshape(T, P, 4)[m.exists]
    psi = m.truth[..., 1][m.exists]
    return {
        "d": float(np.median(np.sqrt(var[:, 3]))),
        "direction": float(np.median(np.sqrt(var[:, 0] * np.cos(psi) ** 2 + var[:, 1]))),
        "kappa": float(np.median(np.sqrt(var[:, 2]))),
    }


def model_head(m: PathErrorModel, T: int) -> PathErrorModel:
    """The first ``T`` epochs of a model."""
    if m.exists.shape[0] == T:
        return m
    cut = {k: getattr(m, k)[:T] for k in ("t", "exists", "truth", "v", "crlb", "cov", "bias")}
    for k in ("k_phase", "k_gain", "unresolved"):
        if getattr(m, k) is not None:
            cut[k] = getattr(m, k)[:T]
    return replace(m, **cut)
