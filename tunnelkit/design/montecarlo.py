"""JAVELIN on a design: Monte-Carlo drives of every candidate array as one task set.

:func:`sweep_montecarlo` runs the tracker over drives of the scenario's route for every array
and run through ONE :func:`tunnelkit.runner.run_trials` call (one Dask cluster for the whole
sweep; run ``r`` of every array shares child generator ``r``, so arrays are compared on the same
random numbers). Each trial returns the per-epoch 2-D position error of its drive, so the result
is identical serially and on any number of workers. Two measurement routes:

* ``mode="channel"``: the route's own signal chain (:func:`tunnelkit.simulation.simulate_drive`,
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
from the tunnel's known surfaces (:class:`tunnelkit.tracking.javelin.surfaces.GeometricBirth`): a design knows
its tunnel, and a tracker that learns every VUE afresh cannot use the reflections' information
until it has learnt the surfaces (under a calibration error, whose bias repeats, it never
does). Its settled error (after the first :data:`SETTLE_S`)
is set beside the PEB, the posterior CRLB over the drive (:func:`drive_pcrlb`, Tichavsky et
al. 1998 with JAVELIN's motion model and the position information of the model's reported bound)
and the bound over the drive under the impairments (:func:`drive_bound`: the posterior CRLB with
the position bias of the array's one calibration draw and of the wideband term added, which no
number of epochs averages down).

Cost: the per-array work (error model, the bound route's shared part
:func:`~tunnelkit.design.fastroute.bound_route`, PEB, the bounds over the drive and the tracker)
is one task per array (:meth:`tunnelkit.runner.TrialPool.prepare`, the largest array first)
and the drives go in a few tasks per worker, each depending on its array's task only: one task
set on one cluster (:func:`tunnelkit.runner.trial_pool`, started once, or ``pool`` shared by
several sweeps), no barrier between models and drives, the array's state fetched worker to
worker once per worker and only the bounds brought back. A drive on the bound route then costs
its random draws and the tracker.
"""

from __future__ import annotations

import json
from collections import OrderedDict
from collections.abc import Callable, Sequence
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np

from .._checks import bound_array
from .._physical import start_spread
from .._validate import boolean, choice, instance, integer, record
from ..budget import check_bytes
from ..montecarlo import RUN_BYTES
from ..runner import TRIAL_TIMEOUT_S, TrialPool, run_trials, trial_pool
from ..settling import SETTLE_S, settled
from .arrayjob import (
    START_HEIGHT_SIGMA_M,
    ArrayJob,
    SweepTrial,
    javelin_config,
    load_tracker,
    prepared_summary,
)
from .setup import ArraySpec, DesignSetup, parse_array
from .trackerfix import MODES, START_SIGMA_M
from .units import drive_streams, unit_seeds

__all__ = [
    "MODES",
    "SETTLE_S",
    "STARTS",
    "START_HEIGHT_SIGMA_M",
    "START_SIGMA_M",
    "MonteCarloResult",
    "javelin_config",
    "sweep_montecarlo",
]

#: where a drive's tracker starts (:func:`sweep_montecarlo`): ``"drawn"`` an open-sky fix drawn
#: from ``N(truth, diag(s^2, s^2, s_h^2))`` (``s`` the sweep's ``start_sigma``, default
#: :data:`START_SIGMA_M`; ``s_h``
#: :data:`START_HEIGHT_SIGMA_M`) with the run's generator, so the tracker's ``P_0`` is its true
#: error; ``"truth"`` the true first position with the same ``P_0`` (the paper tables' start,
#: which rewards a tracker that trusts its measurements too little)
STARTS = ("drawn", "truth")


@dataclass(frozen=True)
class MonteCarloResult:
    """One array's Monte-Carlo over the drive (:func:`sweep_montecarlo`).

    ``t`` (T,) [s] and ``x`` (T,) [m] the epochs and the vehicle's position along the tunnel;
    ``errors`` (runs, T) [m] the 2-D position error of every run and epoch, the runs in unit
    order (``drives_per_unit`` drives of one manufactured unit, one calibration draw, after
    each other: :mod:`tunnelkit.design.units`); ``rmse_runs`` (runs,) each run's RMSE over the
    settled epochs (NaN when the drive is shorter than :data:`SETTLE_S`: nothing settled, and
    the settled statistics refuse); ``settled`` the
    indices of the settled epochs (:func:`tunnelkit.settling.settled`); ``mode`` the
    measurement route; ``peb`` (T,) [m] the snapshot PEB; ``sigmas`` the tracker's fallback
    sigmas. Two **bounds** over the drive (with a model: the bound route, or given models),
    each a lower bound of what it is shown beside (:func:`~tunnelkit.design.drivebound.unit_pcrlb`):
    ``pcrlb`` (T,) [m] every unit's posterior CRLB (its calibration draw known to the bound),
    ``hybrid`` (T,) [m] the posterior CRLB pooled over units (the draw a fixed unknown with its
    prior). Two **predictions** (first-order, not bounds: a tracker may beat them):
    ``predicted`` (T,) [m] the posterior CRLB of the tracker's weighting with the position bias
    of the calibration draw and the wideband term added (:func:`drive_bound`), the surfaces
    known; on the ray-traced channel's route that of the sigmas the tracker is told
    (:mod:`tunnelkit.design.tracedbounds`: ``traced_bounds``, ``los_bounds``) and ``pcrlb`` is
    ``None``. ``error_model`` the traced
    route's measurement-noise model (:func:`tunnelkit.design.traced.error_model_summary`;
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
    predicted: np.ndarray | None = None
    error_model: dict | None = None
    dead_reckoning: np.ndarray | None = None
    hybrid: np.ndarray | None = None
    drives_per_unit: int = 1

    def __post_init__(self) -> None:
        b = ("peb", "pcrlb", "predicted", "hybrid")
        e = ("errors", "dead_reckoning")
        record(self, shapes={**dict.fromkeys(("t", "x", *b), ("T",)), **dict.fromkeys(e, ("R", "T")),
                             "rmse_runs": ("R",), "settled": (None,)},
               allow_nan=("errors", "rmse_runs"), nonnegative=(*e, "rmse_runs", "settled", *b),
               allow_inf=b, skip=("spec", "error_model"))  # fmt: skip
        instance("spec", self.spec, ArraySpec), choice("mode", self.mode, MODES)
        d = integer("drives_per_unit", self.drives_per_unit, minimum=1)
        if self.errors.shape[0] % d:
            raise ValueError(f"drives_per_unit: {self.errors.shape[0]} runs are not units of {d}")
        if self.error_model is not None:
            instance("error_model", self.error_model, dict)

    @property
    def runs(self) -> int:
        return int(self.errors.shape[0])

    def _settled(self) -> np.ndarray:
        """The settled epochs, refused when there are none (never the whole route instead)."""
        if not self.settled.size:
            raise ValueError(
                f"settled: a {self.t[-1] - self.t[0]:.3g} s route has no epoch after the tracker's "
                f"{SETTLE_S:g} s start-up (settling.SETTLE_S): nothing settled to score"
            )
        return self.settled

    @property
    def rmse_settled(self) -> float:
        """RMSE over every run and settled epoch [m]."""
        return float(np.sqrt(np.mean(self.errors[:, self._settled()] ** 2)))

    @property
    def median_settled(self) -> float:
        """Median 2-D error over every run and settled epoch [m]."""
        return float(np.median(self.errors[:, self._settled()]))

    def settled_rms(self, bound: np.ndarray) -> float:
        """RMS of a per-epoch bound (T,) over the settled epochs [m]."""
        if bound_array("bound", bound, ndim=1).shape != self.t.shape:
            raise ValueError(f"bound: expected one value per epoch {self.t.shape}")
        return float(np.sqrt(np.mean(np.asarray(bound)[self._settled()] ** 2)))


#: arrays prepared by serial sweeps, kept for the process (the oldest dropped first)
PREPARED_KEPT = 32
_PREPARED: OrderedDict = OrderedDict()


def _prepare(pool: TrialPool, job: ArrayJob, specs: list) -> list:
    """``pool.prepare(job, specs)``; serially, an array prepared before in this process by an
    equal job (the same setup and error-model objects, mode, epochs, fallback sigmas,
    impairments, entry fix and traced tracker) is that preparation again: a sweep's next batch of units
    (:func:`tunnelkit.design.report.design_sweep`'s sequential rule) prepares the same arrays,
    and the preparation draws nothing at random (the drives only read it). At most
    :data:`PREPARED_KEPT` are kept; on a cluster every sweep prepares its arrays."""
    if pool.parallel:
        return pool.prepare(job, specs, desc="design arrays")
    head = (id(job.setup), id(job.error_models), job.mode, job.T, job.with_model,
            json.dumps(job.crlbs, sort_keys=True, default=repr), repr(job.impairments),
            job.start_sigma, job.traced_tracker)  # fmt: skip
    out, todo = {}, []
    for spec in specs:
        kept = _PREPARED.get((head, spec))
        if kept is not None and kept[0] is job.setup and kept[1] is job.error_models:
            _PREPARED.move_to_end((head, spec))
            out[spec] = kept[2]
        else:
            todo.append(spec)
    for spec, prep in zip(todo, pool.prepare(job, todo, desc="design arrays"), strict=True):
        _PREPARED[(head, spec)] = (job.setup, job.error_models, prep)
        out[spec] = prep
    while len(_PREPARED) > PREPARED_KEPT:
        _PREPARED.popitem(last=False)
    return [out[spec] for spec in specs]


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
    trial_timeout: float | None = TRIAL_TIMEOUT_S,
    progress: bool = False,
    n_epochs: int | None = None,
    crlbs: dict | None = None,
    pool: TrialPool | None = None,
    impairments=None,
    start: str = "drawn",
    start_sigma: float = START_SIGMA_M,
    dead_reckoning: bool = False,
    drives_per_unit: int = 1,
    first_unit: int = 0,
    traced_tracker: str | None = None,
) -> dict[str, MonteCarloResult]:
    """JAVELIN over ``runs`` drives of every array in ``specs``, all arrays x runs as one task
    set (module docstring); returns ``{label: MonteCarloResult}`` in the order of ``specs``.

    The drives are ``runs / drives_per_unit`` manufactured units of ``drives_per_unit`` drives
    each (:mod:`tunnelkit.design.units`): a unit's calibration error is drawn once from its own
    generator and shared by its drives; ``first_unit`` numbers the first unit, so a sweep that
    adds units (an int ``seed``) repeats none. The same unit of every array shares its
    generators (arrays compared on the same random numbers).

    ``mode``: ``"bound"`` (measurements drawn from each array's error model) or ``"channel"``
    (the full signal chain). ``error_models``: per array a
    :class:`~tunnelkit.design.errormodel.PathErrorModel` (a dict by label, or a callable
    ``(setup, spec) -> model``, e.g. :func:`tunnelkit.design.achievable.path_error_model` with
    impairments); default the ideal model (``path_error_model(setup, spec)``: an efficient
    extraction without impairments). The bound mode draws from it, and
    both modes take the posterior CRLB from its reported bound (on the image channel's channel
    route only when models are given; the ray-traced channel's route takes the bounds of the
    sigmas its tracker is told, :mod:`tunnelkit.design.tracedbounds`, and refuses
    models). ``crlbs`` (by label) sets the tracker's fallback sigmas (default: the
    route-median per-path bounds, from the model when there is one). ``workers`` /
    ``scheduler`` / ``timeout`` / ``trial_timeout`` go to :func:`tunnelkit.runner.run_trials` (one cluster for the
    sweep), or ``pool`` (a :func:`tunnelkit.runner.trial_pool` already open, so several
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
    ``dead_reckoning``. ``traced_tracker`` (:data:`tunnelkit.design.tracedtracker.TRACED_TRACKERS`,
    the ray-traced channel's channel route only): ``"los"``, ``"paths"``, ``"auto"`` (there the
    default: per array the one whose told model predicts the smaller error) or ``"direct"``
    (:mod:`tunnelkit.design.traceddirect`).
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
    runs = integer("runs", runs, minimum=1)
    drives_per_unit = integer("drives_per_unit", drives_per_unit, minimum=1)
    first_unit = integer("first_unit", first_unit, minimum=0)
    if runs % drives_per_unit:
        raise ValueError(
            f"runs: expected whole units of drives_per_unit = {drives_per_unit} drives, got {runs}"
        )
    start_sigma = start_spread("start_sigma", start_sigma)
    dead_reckoning = boolean("dead_reckoning", dead_reckoning)
    if impairments is not None:
        from .achievable import DesignImpairments

        if not isinstance(impairments, DesignImpairments):
            raise TypeError(
                "impairments: expected a design.DesignImpairments or None, got "
                f"{type(impairments).__name__}"
            )
    if traced_tracker is None:  # the default: chosen per array on the traced channel's route
        traced_tracker = "auto" if (mode, setup.channel) == ("channel", "sionna") else "paths"
    elif traced_tracker != "paths":  # the names load when another is asked for
        from .tracedtracker import checked_tracker

        traced_tracker = checked_tracker(traced_tracker, mode, setup.channel)
    if mode == "channel" and setup.channel == "sionna":
        if impairments is not None and not impairments.ideal:
            raise ValueError(
                "impairments: the traced route's measurement noise is measured on the ray-traced "
                "channel as it is (tunnelkit.design.traced); give none with channel 'sionna'"
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
    # refused before any per-array work: every drive's errors, its generator and its unit's
    check_bytes(
        "runs",
        A * runs * (8 * T * (2 if dead_reckoning else 1) + 2 * RUN_BYTES),
        f"{A} arrays x {runs} drives x {T} epochs of errors and their generators",
    )
    with_model = mode == "bound" or error_models is not None
    job = ArrayJob(
        setup, error_models, mode, T, with_model, crlbs, impairments, start_sigma, traced_tracker
    )
    kw = {"workers": workers, "scheduler": scheduler, "timeout": timeout}
    kw = {k: v for k, v in kw.items() if v is not None}
    if pool is not None:
        if not isinstance(pool, TrialPool):
            raise TypeError(f"pool: expected a runner.TrialPool, got {type(pool).__name__}")
        if kw:
            raise ValueError(f"pool, {', '.join(kw)}: give a pool or where to start one, not both")
    # the largest array's model first (the longest task); its drives wait only for it
    order = sorted(range(A), key=lambda a: -specs[a].n_elements)
    with nullcontext(pool) if pool is not None else trial_pool(**kw) as pool:
        # one task set: the per-array work (models, bounds, tracker) and every drive, each drive
        # depending on its array's task only (no barrier; the state goes worker to worker)
        if pool.parallel:
            pool.client.run(load_tracker, traced_tracker == "direct")
        handles = _prepare(pool, job, [specs[a] for a in order])
        prepared = [handles[order.index(a)] for a in range(A)]
        n_units = runs // drives_per_unit
        # each drive gets its unit's seed and makes its own generator: the same calibration
        units = [u for u in unit_seeds(seed, first_unit, n_units) for _ in range(drives_per_unit)]
        streams = drive_streams(first_unit, n_units, drives_per_unit)
        res = run_trials(
            SweepTrial(setup, mode, n_epochs, impairments, start, start_sigma, dead_reckoning),
            A * runs,
            seed,
            inputs=[(prepared[a], units[r]) for a in range(A) for r in range(runs)],
            streams=[r for _ in range(A) for r in streams],
            shared_streams=True,  # the same unit of every array: common random numbers
            progress=progress,
            desc=f"JAVELIN {mode} " + " ".join(s.label for s in specs),
            trial_timeout=trial_timeout,
            pool=pool,
        )
        built = pool.map(prepared_summary, prepared, desc="design summaries")
    t = traj.t[:T].copy()
    idx = settled(t)  # empty on a route shorter than the start-up: nothing settled to score
    out = {}
    for a, spec in enumerate(specs):
        err = np.stack([np.asarray(e, float) for e in res[a * runs : (a + 1) * runs]])
        dr = None
        if dead_reckoning:  # each run (2, T): the tracker's errors, then dead reckoning's
            err, dr = err[:, 0], err[:, 1]
        peb, pc, drive, cfg, error_model, hybrid = built[a]
        out[spec.label] = MonteCarloResult(
            spec,
            mode,
            t,
            traj.position[:T, 0].copy(),
            err,
            np.sqrt(np.mean(err[:, idx] ** 2, axis=1)) if idx.size else np.full(runs, np.nan),
            idx,
            peb,
            pc,
            {
                "direction_rad": cfg.sigma_phi,
                "kappa_m": cfg.sigma_kappa,
                "delta_d_m": cfg.sigma_delta_d,
            },
            drive,
            error_model,
            dr,
            hybrid,
            drives_per_unit,
        )
    return out
