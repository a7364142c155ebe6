"""JAVELIN on a design: Monte-Carlo drives of every candidate array as one task set.

:func:`sweep_montecarlo` runs the tracker over drives of the scenario's route for every array
and run through ONE :func:`tunnelkit.montecarlo.run_trials` call (one Dask cluster for the whole
sweep; run ``r`` of every array shares child generator ``r``, so arrays are compared on the same
random numbers). Each trial returns the per-epoch 2-D position error of its drive, so the result
is identical serially and on any number of workers. Two measurement routes:

* ``mode="channel"``: the route's own signal chain (:func:`tunnelkit.studies.simulate_drive`,
  ``extraction="route"``: the ``M x Nf x Nt`` tensor and the ML extraction every epoch); on the
  ray-traced channel (``setup.channel == "sionna"``) the traced treatment of the tables
  (:mod:`tunnelkit.design.traced`): every epoch's ML measurements through the geometry
  pre-filter, the tracker told the array's own errors measured on that channel;
* ``mode="bound"``: each epoch's path measurements drawn from a
  :class:`~tunnelkit.design.errormodel.PathErrorModel` and reported with its CRLB
  (:func:`tunnelkit.design.fastroute.bound_drive`): the cost no longer grows with the array.

JAVELIN there takes each path's covariance as the extraction reports it (the CRLB at the
estimate, which the ML route attains), so the tracker is tuned by the design itself at any
carrier and size (:func:`javelin_config`). It starts from an open-sky fix drawn with the
uncertainty it is told (:data:`STARTS`; ``start_sigma`` per axis, default 1 m, 5 cm in
height), first fixes itself on the path the known surfaces say is the LoS, and takes its VUEs
from the tunnel's known surfaces (:data:`VUES`, :class:`tunnelkit.tracking.javelin.surfaces.GeometricBirth`): a design knows
its tunnel, and a tracker that learns every VUE afresh cannot use the reflections' information
until it has learnt the surfaces (under a calibration error, whose bias repeats, it never
does). Its settled error (after the first :data:`SETTLE_S`)
is set beside the PEB, the posterior CRLB over the drive (:func:`drive_pcrlb`, Tichavsky et
al. 1998 with JAVELIN's motion model and the position information of the model's reported bound)
and the bound over the drive under the impairments (:func:`drive_bound`: the posterior CRLB with
the position bias of the array's one calibration draw and of the wideband term added, which no
number of epochs averages down) and beside the same bound for a tracker that learns its VUEs
(:mod:`tunnelkit.design.learnedbound`); ``MonteCarloResult.tracker_bound`` is the one of the
tracker run. :func:`~tunnelkit.design.onearray.javelin_rmse` is the one-array summary on top of it.

Cost: the per-array work (error model, the bound route's shared part
:func:`~tunnelkit.design.fastroute.bound_route`, PEB, the bounds over the drive and the tracker)
is one task per array (:meth:`tunnelkit.montecarlo.TrialPool.prepare`, the largest array first)
and the drives go in a few tasks per worker, each depending on its array's task only: one task
set on one cluster (:func:`tunnelkit.montecarlo.trial_pool`, started once, or ``pool`` shared by
several sweeps), no barrier between models and drives, the array's state fetched worker to
worker once per worker and only the bounds brought back. A drive on the bound route then costs
its random draws and the tracker.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from contextlib import nullcontext
from dataclasses import dataclass, replace

import numpy as np

from .._checks import bound_array
from .._validate import boolean, choice, instance, integer, positive, record
from ..metrics import SETTLE_S, settled
from ..montecarlo import TrialPool, run_trials, trial_pool
from .bounds import path_bounds, route_bounds, route_geometry
from .channelbudget import channel_route_budget
from .drivebound import (
    START_SIGMA_M,
    drive_bound,
    drive_pcrlb,
    position_bias_rms,
    position_information,
)
from .errormodel import PathErrorModel
from .setup import ArraySpec, DesignSetup, parse_array

__all__ = [
    "MODES",
    "SETTLE_S",
    "STARTS",
    "START_HEIGHT_SIGMA_M",
    "START_SIGMA_M",
    "VUES",
    "MonteCarloResult",
    "javelin_config",
    "sweep_montecarlo",
]

#: the measurement routes of :func:`sweep_montecarlo`
MODES = ("bound", "channel")

#: where a drive's tracker starts (:func:`sweep_montecarlo`): ``"drawn"`` an open-sky fix drawn
#: from ``N(truth, diag(s^2, s^2, s_h^2))`` (``s`` the sweep's ``start_sigma``, default
#: :data:`START_SIGMA_M`; ``s_h``
#: :data:`START_HEIGHT_SIGMA_M`) with the run's generator, so the tracker's ``P_0`` is its true
#: error; ``"truth"`` the true first position with the same ``P_0`` (the paper tables' start,
#: which rewards a tracker that trusts its measurements too little)
STARTS = ("drawn", "truth")

#: how the design's tracker gets its VUEs (:func:`sweep_montecarlo`): ``"known"`` at the UE's
#: mirror image in the tunnel's known surfaces (the design knows its tunnel), ``"learned"`` from
#: each path's angles and learnt over the drive (Algorithm 3)
VUES = ("known", "learned")

#: the open-sky fix's height standard deviation [m]: a vehicle's antenna height is known (the
#: PEB and the bounds over the drive take it as known); the start's and the tracker's ``P_0``
START_HEIGHT_SIGMA_M = 0.05


def javelin_config(crlb: dict, min_d: float = 0.0, planes=None):
    """The design's JAVELIN: :func:`tunnelkit.tracking.javelin.designs.array_design` (reported
    covariances, likelihood cost, measured births, the joint innovation test; ``crlb`` sets
    only the fixed fallback sigmas, ``min_d`` Algorithm 1's delay check; ``planes`` the
    tunnel's surfaces when the VUEs come from the known geometry)."""
    # the tracker and the drive simulator load on the first Monte-Carlo, not with the bounds
    from ..tracking.javelin.designs import array_design

    return array_design(crlb, min_d, planes)


def design_planes(setup: DesignSetup) -> list:
    """The planes of the surfaces a design traces (:data:`tunnelkit.design.geometry.KINDS`)."""
    from .geometry import KINDS

    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    return [s.plane for s in setup.tunnel.surfaces if s.kind in KINDS]


@dataclass(frozen=True)
class MonteCarloResult:
    """One array's Monte-Carlo over the drive (:func:`sweep_montecarlo`).

    ``t`` (T,) [s] and ``x`` (T,) [m] the epochs and the vehicle's position along the tunnel;
    ``errors`` (runs, T) [m] the 2-D position error of every run and epoch; ``rmse_runs``
    (runs,) each run's RMSE over the settled epochs (the whole drive when it is shorter than
    :data:`SETTLE_S`); ``settled`` the indices of the settled epochs
    (:func:`tunnelkit.metrics.settled`); ``mode`` the measurement route; ``peb`` (T,) [m] the
    snapshot PEB; ``pcrlb`` (T,) [m] the posterior CRLB of the 2-D position over the drive,
    from the ideal per-path CRLB (under impairments the ideal posterior bound, not an achievable one)
    (``None`` on the channel route without a model; on the ray-traced channel's route ``pcrlb``,
    ``drive`` and ``learned`` are those of the sigmas the tracker is told,
    :func:`tunnelkit.design.traced.traced_bounds`); ``sigmas`` the tracker's fallback sigmas;
    ``drive`` (T,) [m] the achievable bound over the drive (:func:`drive_bound`: the posterior
    CRLB with the bias that does not average down; equal to ``pcrlb`` for an ideal model), the
    surfaces known; ``learned`` (T,) [m] the same for a tracker that learns its VUEs
    (:func:`~tunnelkit.design.learnedbound.learned_pcrlb`: the posterior CRLB of UE + VUEs and
    the bias of the filter attaining it, in quadrature); ``vues`` how the tracker run got its
    VUEs (:data:`VUES`), and :attr:`tracker_bound` the bound of that tracker; ``error_model``
    the traced route's measurement-noise model (:func:`tunnelkit.design.traced.error_model_summary`;
    ``None`` on the image channel, where each path carries its reported CRLB);
    ``dead_reckoning`` (runs, T) [m] the same drives' errors with every measurement dropped
    (``sweep_montecarlo(dead_reckoning=True)``; else ``None``).
    """

    spec: ArraySpec
    mode: str
    t: np.ndarray
    x: np.ndarray
    errors: np.ndarray
    rmse_runs: np.ndarray
    settled: np.ndarray
    peb: np.ndarray
    pcrlb: np.ndarray | None
    sigmas: dict
    drive: np.ndarray | None = None
    learned: np.ndarray | None = None
    vues: str = "known"
    error_model: dict | None = None
    dead_reckoning: np.ndarray | None = None

    def __post_init__(self) -> None:
        b = ("peb", "pcrlb", "drive", "learned")
        e = ("errors", "dead_reckoning")
        record(self, shapes={**dict.fromkeys(("t", "x", *b), ("T",)), **dict.fromkeys(e, ("R", "T")),
                             "rmse_runs": ("R",), "settled": (None,)},
               allow_nan=("errors", "rmse_runs"), nonnegative=(*e, "rmse_runs", "settled", *b),
               allow_inf=b, skip=("spec", "error_model"))  # fmt: skip
        instance("spec", self.spec, ArraySpec), choice("mode", self.mode, MODES)
        choice("vues", self.vues, VUES)
        if self.error_model is not None:
            instance("error_model", self.error_model, dict)

    @property
    def tracker_bound(self) -> np.ndarray | None:
        """The achievable bound over the drive of the tracker that was run (T,) [m]:
        ``drive`` for VUEs from the known surfaces, ``learned`` for learnt VUEs."""
        return self.drive if self.vues == "known" else self.learned

    @property
    def runs(self) -> int:
        return int(self.errors.shape[0])

    @property
    def rmse_settled(self) -> float:
        """RMSE over every run and settled epoch [m]."""
        return float(np.sqrt(np.mean(self.errors[:, self.settled] ** 2)))

    @property
    def median_settled(self) -> float:
        """Median 2-D error over every run and settled epoch [m]."""
        return float(np.median(self.errors[:, self.settled]))

    def settled_rms(self, bound: np.ndarray) -> float:
        """RMS of a per-epoch bound (T,) over the settled epochs [m]."""
        if bound_array("bound", bound, ndim=1).shape != self.t.shape:
            raise ValueError(f"bound: expected one value per epoch {self.t.shape}")
        return float(np.sqrt(np.mean(np.asarray(bound)[self.settled] ** 2)))


def _trial_errors(estimates: np.ndarray, truth: np.ndarray) -> np.ndarray:
    return np.linalg.norm(estimates[:, :2] - truth[:, :2], axis=1)


@dataclass(frozen=True)
class _SweepTrial:
    """One Monte-Carlo run of one array (picklable for Dask workers; sent to each worker once):
    a drive of the design's route through the chosen measurement route, JAVELIN, the 2-D error
    per epoch (T,). ``prep`` is the array's :class:`_Prepared` (built once per array on the
    sweep's cluster, fetched once by each worker that runs its drives)."""

    setup: DesignSetup
    mode: str
    n_epochs: int | None
    impairments: object = None  # achievable.DesignImpairments: the channel mode's
    start: str = "drawn"
    start_sigma: float = START_SIGMA_M
    dead_reckoning: bool = False

    def __call__(self, prep: _Prepared, rng: np.random.Generator) -> np.ndarray:
        from ..studies import evaluate, simulate_drive
        from ..tracking.javelin import draw_start

        spec = prep.spec
        if self.mode == "bound":
            from .fastroute import bound_drive

            drive = bound_drive(prep.route, self.setup, spec, rng, n_epochs=self.n_epochs)
        elif self.setup.channel == "sionna":
            from .traced import traced_drive, traced_route

            # the traced treatment (tunnelkit.design.traced): every epoch's ML measurements,
            # the geometry pre-filter; the tracker told this array's measured errors
            route = traced_route(self.setup, spec)
            drive = traced_drive(route, rng, n_epochs=self.n_epochs)["ml-traced"]
        else:
            route = self.setup.signal_route(spec)
            imp = self.impairments
            if imp is not None and not imp.ideal:
                # its calibration error drawn once per drive; fits judged against noise + it
                route = route.with_impairments(imp.channel_impairments(), rng)
                route = replace(
                    route, model_error_floor=True, bias_budget=prep.budget, centroid_unresolved=True
                )
            if imp is not None and imp.wideband_model:
                route = replace(route, wideband_model=True)
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
        alone = replace(drive, epochs=[None] * len(drive.epochs))
        ev = evaluate(alone, prep.design, sigma_p0_ue=sigma, start=p0, sigma_p0_height=sh)
        return np.stack([err, _trial_errors(ev.estimates, drive.truth)])


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
class _Prepared:
    """What the drives of one array share (:class:`_ArrayJob`): the bound route's shared part
    (``route``, bound mode), the tracker (``design``) and the bounds reported beside them."""

    spec: ArraySpec
    route: object  # fastroute.BoundRoute (bound mode) or None
    design: object  # tracking.javelin.JavelinDesign
    peb: np.ndarray
    pcrlb: np.ndarray | None
    drive: np.ndarray | None
    learned: np.ndarray | None = None
    budget: object = None  # signal_route.judging.BiasBudget: the channel route's, impaired
    error_model: dict | None = None  # traced.error_model_summary: the traced route's

    def summary(self) -> tuple:
        """What the sweep's result keeps (not the model and route the drives need)."""
        return self.peb, self.pcrlb, self.drive, self.design.config, self.learned, self.error_model


@dataclass(frozen=True)
class _ArrayJob:
    """Everything a sweep computes once per array, before its drives (one task per array, on
    the sweep's cluster when it has one): the error model, the bound route's shared part, the
    PEB, the bounds over the drive and the tracker (:class:`_Prepared`)."""

    setup: DesignSetup
    error_models: object
    mode: str
    T: int
    with_model: bool
    crlbs: dict | None
    impairments: object = None
    vues: str = "known"
    start_sigma: float = START_SIGMA_M

    def __call__(self, spec: ArraySpec) -> _Prepared:
        ep = np.arange(self.T)
        peb = route_bounds(self.setup, spec, epochs=ep).peb
        m = route = pc = drive = learned = None
        if self.with_model:
            m = _model(self.setup, spec, self.error_models, self.impairments)
            if self.mode == "bound":
                from .fastroute import bound_route

                route = bound_route(m, self.setup, spec)
            g = route_geometry(self.setup, spec, epochs=ep)
            head = _head(m, self.T)
            sp0 = self.start_sigma
            pc = drive_pcrlb(self.setup, position_information(head, g), sigma_p0=sp0)
            # the noise and the bias of a fix weighted as the tracker weighs (its reported
            # budget, one block per path, bound mode; on the channel route the extraction
            # reports its CRLB): the information a tracker told one block per path can use
            w, pc_w = None, pc
            if route is not None:
                from .fastroute import tracker_weights

                w = tracker_weights(route)[: self.T]
                pc_w = drive_pcrlb(self.setup, position_information(head, g, w), sigma_p0=sp0)
            drive = drive_bound(pc_w, position_bias_rms(head, g, w))
            from .learnedbound import learned_pcrlb

            # a tracker that learns its VUEs is told the same blocks: the paths taken one by one
            learned = drive_bound(
                *learned_pcrlb(
                    _per_path(head) if w is not None else head, g, self.setup, sigma_p0=sp0
                )
            )
        crlb = None if self.crlbs is None else self.crlbs.get(spec.label)
        if crlb is None and m is not None:
            crlb = _median_sigmas(m)
        if crlb is None:
            pb = path_bounds(self.setup, spec)
            crlb = {k: float(np.median(pb[k])) for k in ("d", "direction", "kappa")}
        planes = design_planes(self.setup) if self.vues == "known" else None
        design = javelin_config(crlb, self.setup.signal_route(spec).min_d, planes)
        imp = self.impairments if self.mode == "channel" else None  # its budget: channel, impaired
        budget = channel_route_budget(self.setup, spec, imp)
        error_model = None
        if self.mode == "channel" and self.setup.channel == "sionna":
            from .traced import design_errors, error_model_summary, traced_bounds, traced_javelin

            # this array's errors on the traced channel (cached with their provenance)
            rec = design_errors(self.setup, spec, n_epochs=self.T)
            design = traced_javelin(self.setup, spec, rec)
            error_model = error_model_summary(rec, design.config)
            # the bounds of the sigmas the tracker is told, not of the image channel's CRLB
            pc, drive, learned = traced_bounds(
                self.setup, spec, design.config, self.T, sigma_p0=self.start_sigma
            )
        return _Prepared(spec, route, design, peb, pc, drive, learned, budget, error_model)


def _load_tracker() -> None:
    """Import the tracker and the drive simulator (run on every worker before a sweep's tasks:
    a worker that imports them in a task while another thread unpickles a tracker sent from
    another worker deadlocks on the package's import locks)."""
    from .. import studies  # noqa: F401
    from ..tracking import javelin  # noqa: F401


def _summary(prep: _Prepared) -> tuple:
    return prep.summary()


def sweep_montecarlo(
    setup: DesignSetup,
    specs,
    runs: int,
    seed: int | np.random.Generator,
    *,
    mode: str = "bound",
    error_models: dict | Callable | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float | None = None,
    trial_timeout: float | None = None,
    progress: bool = False,
    n_epochs: int | None = None,
    crlbs: dict | None = None,
    pool: TrialPool | None = None,
    impairments=None,
    start: str = "drawn",
    vues: str = "known",
    start_sigma: float = START_SIGMA_M,
    dead_reckoning: bool = False,
) -> dict[str, MonteCarloResult]:
    """JAVELIN over ``runs`` drives of every array in ``specs``, all arrays x runs as one task
    set (module docstring); returns ``{label: MonteCarloResult}`` in the order of ``specs``.

    ``mode``: ``"bound"`` (measurements drawn from each array's error model) or ``"channel"``
    (the full signal chain). ``error_models``: per array a
    :class:`~tunnelkit.design.errormodel.PathErrorModel` (a dict by label, or a callable
    ``(setup, spec) -> model``, e.g. :func:`tunnelkit.design.achievable.path_error_model` with
    impairments); default the ideal model (``path_error_model(setup, spec)``: an efficient
    extraction without impairments). The bound mode draws from it, and
    both modes take the posterior CRLB from its reported bound (on the image channel's channel
    route only when models are given; the ray-traced channel's route takes the bounds of the
    sigmas its tracker is told, :func:`tunnelkit.design.traced.traced_bounds`, and refuses
    models). ``crlbs`` (by label) sets the tracker's fallback sigmas (default: the
    route-median per-path bounds, from the model when there is one). ``workers`` /
    ``scheduler`` / ``timeout`` / ``trial_timeout`` go to :func:`tunnelkit.montecarlo.run_trials` (one cluster for the
    sweep), or ``pool`` (a :func:`tunnelkit.montecarlo.trial_pool` already open, so several
    sweeps share one cluster, started once); ``seed`` an int or a Generator: run ``r`` of every
    array uses child generator ``r``.
    ``impairments`` (a :class:`~tunnelkit.design.achievable.DesignImpairments`, default none):
    on the channel route each run's array carries them (its calibration error drawn once per
    run, the wideband term and diffuse power in the tensor, the extraction modelling the
    wideband term with ``wideband_model``); the default error model carries them too.
    ``start`` (:data:`STARTS`): each drive's tracker starts from an open-sky fix drawn with the
    run's generator after the drive (``"drawn"``, default) or from the true first position
    (``"truth"``), with ``start_sigma`` [m] per axis of uncertainty either way (default
    :data:`START_SIGMA_M`; the entry fix's quality, also the prior of the bounds over the
    drive). ``dead_reckoning``: each drive also run with every measurement dropped (the same
    tracker, start and V2X messages: what the radio adds), its errors the result's
    ``dead_reckoning``. ``vues``
    (:data:`VUES`): the tracker's VUEs from the tunnel's known surfaces (``"known"``, default)
    or learnt from the paths' angles (``"learned"``).
    """
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    if not isinstance(specs, str | ArraySpec | Sequence):
        raise TypeError(f"specs: expected arrays such as ['8x8'], got {type(specs).__name__}")
    if isinstance(specs, str | ArraySpec) or not isinstance(specs, Sequence | tuple):
        specs = [specs]
    specs = tuple(parse_array(s) for s in specs)
    if not specs:
        raise ValueError("specs: expected at least one array")
    if len({s.label for s in specs}) != len(specs):
        raise ValueError(f"specs: every array once, got {[s.label for s in specs]}")
    if mode not in MODES:
        raise ValueError(f"mode: expected one of {MODES}, got {mode!r}")
    if start not in STARTS:
        raise ValueError(f"start: expected one of {STARTS}, got {start!r}")
    if vues not in VUES:
        raise ValueError(f"vues: expected one of {VUES}, got {vues!r}")
    runs = integer("runs", runs, minimum=1)
    start_sigma = positive("start_sigma", start_sigma)
    dead_reckoning = boolean("dead_reckoning", dead_reckoning)
    if impairments is not None:
        from .achievable import DesignImpairments

        if not isinstance(impairments, DesignImpairments):
            raise TypeError(
                "impairments: expected a design.DesignImpairments or None, got "
                f"{type(impairments).__name__}"
            )
    if mode == "channel" and setup.channel == "sionna":
        if impairments is not None and not impairments.ideal:
            raise ValueError(
                "impairments: the traced route's measurement noise is measured on the ray-traced "
                "channel as it is (tunnelkit.design.traced); give none with channel 'sionna'"
            )
        if vues != "known":
            raise ValueError(
                "vues: the traced route's tracker takes its VUEs from the known surfaces"
            )
        if error_models is not None:
            raise ValueError(
                "error_models: the traced route's noise is measured on the ray-traced channel "
                "(tunnelkit.design.traced); give none with channel 'sionna'"
            )
    if not isinstance(seed, np.random.Generator):
        seed = integer("seed", seed, minimum=0)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    if crlbs is not None and not isinstance(crlbs, dict):
        raise TypeError(f"crlbs: expected a dict by array label, got {type(crlbs).__name__}")
    traj = setup.trajectory
    T = len(traj) if n_epochs is None else min(n_epochs, len(traj))
    A = len(specs)
    with_model = mode == "bound" or error_models is not None
    job = _ArrayJob(setup, error_models, mode, T, with_model, crlbs, impairments, vues, start_sigma)
    kw = {"workers": workers, "scheduler": scheduler, "timeout": timeout}
    kw = {k: v for k, v in kw.items() if v is not None}
    if pool is not None:
        if not isinstance(pool, TrialPool):
            raise TypeError(f"pool: expected a montecarlo.TrialPool, got {type(pool).__name__}")
        if kw:
            raise ValueError(f"pool, {', '.join(kw)}: give a pool or where to start one, not both")
    # the largest array's model first (the longest task); its drives wait only for it
    order = sorted(range(A), key=lambda a: -specs[a].n_elements)
    with nullcontext(pool) if pool is not None else trial_pool(**kw) as pool:
        # one task set: the per-array work (models, bounds, tracker) and every drive, each drive
        # depending on its array's task only (no barrier; the state goes worker to worker)
        if pool.parallel:
            pool.client.run(_load_tracker)
        handles = pool.prepare(job, [specs[a] for a in order], desc="design arrays")
        prepared = [handles[order.index(a)] for a in range(A)]
        res = run_trials(
            _SweepTrial(setup, mode, n_epochs, impairments, start, start_sigma, dead_reckoning),
            A * runs,
            seed,
            inputs=[prepared[a] for a in range(A) for _ in range(runs)],
            streams=[r for _ in range(A) for r in range(runs)],
            progress=progress,
            desc=f"JAVELIN {mode} " + " ".join(s.label for s in specs),
            trial_timeout=trial_timeout,
            pool=pool,
        )
        built = pool.map(_summary, prepared, desc="design summaries")
    t = traj.t[:T].copy()
    idx = settled(t)
    use = idx if idx.size else np.arange(T)
    out = {}
    for a, spec in enumerate(specs):
        err = np.stack([np.asarray(e, float) for e in res[a * runs : (a + 1) * runs]])
        dr = None
        if dead_reckoning:  # each run (2, T): the tracker's errors, then dead reckoning's
            err, dr = err[:, 0], err[:, 1]
        peb, pc, drive, cfg, learned, error_model = built[a]
        out[spec.label] = MonteCarloResult(
            spec,
            mode,
            t,
            traj.position[:T, 0].copy(),
            err,
            np.sqrt(np.mean(err[:, use] ** 2, axis=1)),
            idx,
            peb,
            pc,
            {
                "direction_rad": cfg.sigma_phi,
                "kappa_m": cfg.sigma_kappa,
                "delta_d_m": cfg.sigma_delta_d,
            },
            drive,
            learned,
            vues,
            error_model,
            dr,
        )
    return out


def _median_sigmas(m: PathErrorModel) -> dict[str, float]:
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


def _per_path(m: PathErrorModel) -> PathErrorModel:
    """A model whose ideal bound keeps only each path's own block (the correlation of the joint
    CRLB between paths dropped): the information a tracker told one block per path uses."""
    P = m.exists.shape[1]
    keep = np.kron(np.eye(P, dtype=bool), np.ones((4, 4), dtype=bool))
    return replace(m, crlb=np.where(keep, m.crlb, 0.0))


def _head(m: PathErrorModel, T: int) -> PathErrorModel:
    """The first ``T`` epochs of a model."""
    if m.exists.shape[0] == T:
        return m
    cut = {k: getattr(m, k)[:T] for k in ("t", "exists", "truth", "v", "crlb", "cov", "bias")}
    for k in ("k_phase", "k_gain"):
        if getattr(m, k) is not None:
            cut[k] = getattr(m, k)[:T]
    return replace(m, **cut)
