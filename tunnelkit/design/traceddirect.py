"""The direct fit under the tracker, on the ray-traced channel.

At every epoch JAVELIN predicts with the V2X message, and the direct fit (:func:`~tunnelkit.extraction.direct.fit.direct_fix`:
every atom of the visibility model tied to one UE position, one clock bias and one speed) starts
from that prediction. Its position goes to the tracker as a line of sight (the fix's angles seen
from the site, told their sigmas by elevation, :class:`~tunnelkit.design.los.ElevationSigmas`);
its speed, with ``speed_sigma`` given, is averaged with the next step's V2X speed
(inverse-variance weights, the tracker told the mean's sigma). The measurement depends on the
track, so a stored drive's fixes told other sigmas (:func:`direct_drive`'s ``replay``) only
approximate the drive those sigmas would have had.

Beside it on the same messages and snapshots (:func:`direct_drive`): dead reckoning (the same
JAVELIN, every measurement dropped), the traced tables' line-of-sight column (eq. 1's ML route,
the path :func:`~tunnelkit.design.los.los_path` takes, its design survey's sigmas) and, with
``speed_sigma``, dead reckoning on the averaged speed alone (``"direct speed alone"``: the
direct fits' speeds, no position update), which tells the speed's share from the angles'. The
truth starts every tracker (told ``start_sigma``) unless an entry fix is given, and the eq. 1
column reads what the traced tables' ML route reads (the number of true first-order paths, and
with the route's ``diffuse_floor`` the traced diffuse power in its noise floor); no other truth
enters a tracker. It scores them and records the errors each was fed, from which
:func:`~tunnelkit.design.los.elevation_sigmas` and an RMS make the told sigmas on the drives
they are chosen on. ``benchmarks/bench_rt_direct.py`` runs it
(``docs/results/traced-models.md``).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from .._validate import boolean, finite_array, instance, integer, positive, record, rng_or_error
from ..arrays import ArrayGeometry
from ..channel import ChannelSnapshot
from ..extraction.direct.fit import (
    MAX_DIFFUSE,
    MAX_HEIGHT_M,
    DirectFix,
    beyond_noise_unchecked,
    diffuse_share,
    direct_fix,
)
from ..extraction.ml import ml_paths
from ..geometry import spherical
from ..signal_route import SignalRoute, measurements_from_estimates
from ..tracking.javelin import Javelin, JavelinDesign, ReportedNoise
from ..tracking.javelin.motion import midpoint_messages, ue_velocity
from ..tracking.measurements import PathMeasurements
from .los import LOS_WINDOW_M, ElevationSigmas, los_error_rows, los_path, told_epoch
from .tracedbounds import config_sigmas

__all__ = [
    "DESIGN_OPTIONS",
    "RESTART_M",
    "TRACKERS",
    "DirectDrive",
    "direct_drive",
    "eq1_los",
    "repointed",
    "unmodelled_share",
]

#: the trackers of one drive (``"eq. 1"`` only with an ``eq1_table``, the last only with
#: ``speed_sigma``)
TRACKERS = ("dead reckoning", "eq. 1", "direct", "direct speed alone")

#: :func:`direct_drive`'s options on the design's traced route (chosen with the constant told
#: sigmas, :data:`~tunnelkit.design.directsurvey.DESIGN_SIGMAS_DEG`): the fix's speed averaged
#: with the V2X message's, told 0.1 m/s; the second-order atoms each on the elements that see
#: it; one diffuse atom, tried where the tied fit leaves more than 4 % of the power unmodelled;
#: the second start from eq. 1's line of sight
DESIGN_OPTIONS = {
    "speed_sigma": 0.1,
    "element_second_order": True,
    "diffuse": 1,
    "diffuse_above": 0.04,
    "second_start": True,
}


#: the extraction errors a fit may raise; the epoch is then predicted only
_FAILURES = (ValueError, np.linalg.LinAlgError, FloatingPointError)


@dataclass(frozen=True)
class DirectDrive:
    """One drive of :func:`direct_drive`: the true positions ``truth`` (T, 3) [m];
    ``estimates`` tracker -> (T, 3) [m] (:data:`TRACKERS`); ``los_errors`` ``"eq. 1"`` (when run)
    and ``"direct"`` -> (N, 3) rows ``(measured elevation, azimuth error, elevation error)`` [rad] of
    the line of sight each was fed; ``speed_errors`` (N,) [m/s] of the direct fits' speeds (the
    ok ones); ``seconds`` ``"eq. 1"`` / ``"direct"`` -> (T,) [s] of extraction per epoch;
    ``dropped`` the same keys -> epochs without a measurement (a failed, unconverged or gated fit,
    one past ``max_unmodelled``, or one Algorithm 1 refuses); ``unmodelled`` (K,) the unmodelled
    share (:func:`unmodelled_share`) of every ok direct fit (converged, within its gate), whether
    fed or dropped; ``fixes`` per epoch the direct fit kept (a
    :class:`~tunnelkit.extraction.direct.fit.DirectFix`, None where every fit raised), which
    :func:`direct_drive`'s ``replay`` tells other sigmas (empty: not kept, a drive pickled before
    they were)."""

    truth: np.ndarray
    estimates: dict = field(repr=False)
    los_errors: dict = field(repr=False)
    speed_errors: np.ndarray = field(repr=False)
    seconds: dict = field(repr=False)
    dropped: dict
    unmodelled: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))
    fixes: tuple = field(repr=False, default=())

    def __post_init__(self) -> None:
        record(self, shapes={"truth": (None, 3), "speed_errors": (None,), "unmodelled": (None,)},
               may_be_empty=("speed_errors", "unmodelled", "fixes"),
               skip=("estimates", "los_errors", "seconds", "dropped"))  # fmt: skip
        T = finite_array("truth", self.truth, shape=(None, 3)).shape[0]
        finite_array("speed_errors", self.speed_errors, ndim=1)
        if np.any(self.unmodelled > 1.0 + 1e-9):
            raise ValueError("unmodelled: a share of the tensor's power is at most 1")
        for name in ("estimates", "los_errors", "seconds", "dropped"):
            instance(name, getattr(self, name), dict)
        for x in self.estimates.values():
            finite_array("estimates", x, shape=(T, 3))
        for x in self.los_errors.values():
            finite_array("los_errors", x, shape=(None, 3))
        for x in self.seconds.values():
            finite_array("seconds", x, shape=(T,))
        if len(instance("fixes", self.fixes, tuple)) not in (0, T):
            raise ValueError(f"fixes: expected one per epoch ({T}) or none, got {len(self.fixes)}")
        for f in self.fixes:
            if f is not None:
                instance("fixes", f, DirectFix)

    def rmse(self) -> dict:
        """Tracker -> the horizontal RMSE [m] over the drive."""
        return {
            name: float(np.sqrt(np.mean(np.sum((x[:, :2] - self.truth[:, :2]) ** 2, axis=1))))
            for name, x in self.estimates.items()
        }


def _fix_los(fix, origin: np.ndarray, velocity: np.ndarray, min_d: float) -> PathMeasurements:
    """The line of sight of a direct fix seen from ``origin``: its angles, its range as the
    curvature, range plus clock bias as the delay, the radial speed of ``velocity``; Algorithm
    1's checks applied (``min_d``: the route's)."""
    q = fix.position - origin
    phi, psi, r = spherical(q)
    v = -float(q @ velocity) / r
    return PathMeasurements.from_arrays(
        [phi], [psi], [r], [r + fix.clock_bias], [v], warn=False, min_d=min_d
    )


class _StepSigma(Javelin):
    """JAVELIN told each step's speed sigma: ``step_sigma`` [m/s] (set before :meth:`predict`;
    None: the design's) for a speed message that arrived."""

    step_sigma: float | None = None

    def _motion(self, speed, heading, faults):
        nu, theta, sig = super()._motion(speed, heading, faults)
        return nu, theta, self.step_sigma if sig is None else sig


def eq1_los(route, k: int, arr, n_paths: int, snap):
    """The traced tables' line of sight of the snapshot ``snap`` (a
    :class:`~tunnelkit.channel.ChannelSnapshot`) of epoch ``k`` of ``route`` received at ``arr``:
    eq. 1's ML route (``L = n_paths`` known, the route's noise power), every row, the path
    :func:`los_path` takes; None if none."""
    instance("route", route, SignalRoute)
    k = integer("k", k, minimum=0, maximum=len(route.trajectory) - 1)
    instance("arr", arr, ArrayGeometry)
    n_paths = integer("n_paths", n_paths, minimum=1, maximum=arr.M - 1)  # as ml_paths
    instance("snap", snap, ChannelSnapshot)
    if snap.H.shape[0] != arr.M:
        raise ValueError(f"snap: {snap.H.shape[0]} elements, the array arr has {arr.M}")
    if snap.config != route.config:
        raise ValueError("snap: received with another radio than the route's (its config)")
    return _eq1_los(route, k, arr, n_paths, snap)


def _eq1_los(route, k, arr, n_paths, snap):
    """:func:`eq1_los` of checked arguments."""
    n1 = route.ml_noise_power(k, snap)
    est = ml_paths(snap.H, n_paths, arr, route.config, noise_power=n1)
    m = measurements_from_estimates(est, arr)
    m = PathMeasurements.from_arrays(m.phi, m.psi, m.kappa, m.d, m.v, warn=False, min_d=route.min_d)
    return m.subset(np.array([los_path(m.d, m.psi, LOS_WINDOW_M)])) if len(m) else None


def unmodelled_share(residual: float, snap: ChannelSnapshot) -> float:
    """What a fit's ``residual`` (its cost over ``||H||^2`` of the snapshot ``snap``) leaves
    beyond the noise: ``residual - N0 M Nf Nt / ||H||^2`` with ``N0`` the snapshot's noise power
    (the receiver's own). About zero where the model holds (negative by the noise's own spread);
    where it does not, the share of the tensor's power in the misfit the model cannot absorb: an
    underestimate of what it lacks, the fit absorbing part of it (the slalom's epoch 22: 6.9 %
    left of a diffuse part of 8.6 %)."""
    r = float(finite_array("residual", residual, ndim=0))
    if not 0.0 <= r <= 1.0 + 1e-9:
        raise ValueError(f"residual: a share of the tensor's power in [0, 1], got {r:g}")
    return _unmodelled(r, instance("snap", snap, ChannelSnapshot))


def _unmodelled(residual: float, snap) -> float:
    """:func:`unmodelled_share` of checked arguments."""
    return beyond_noise_unchecked(
        residual, snap.noise_power, snap.H.size, float(np.sum(np.abs(snap.H) ** 2))
    )


#: the second start of the direct fit is tried when it lies this far from the prediction [m]
#: (horizontally; :func:`direct_drive`'s ``second_start``)
RESTART_M = 0.25


def repointed(los: PathMeasurements, origin, prediction) -> np.ndarray:
    """The point (3,) [m] along the line of sight ``los`` (one path's measured angles, seen from
    ``origin`` (3,)) at the range of ``prediction`` (3,) from ``origin``, at the prediction's
    height: the prediction moved onto the measured direction (its range and height kept, where
    a far line of sight's elevation says little about the range)."""
    instance("los", los, PathMeasurements)
    if len(los) != 1:
        raise ValueError(f"los: expected one path (the line of sight), got {len(los)}")
    origin = finite_array("origin", origin, shape=(3,))
    prediction = finite_array("prediction", prediction, shape=(3,))
    if np.linalg.norm(prediction - origin) == 0.0:
        raise ValueError("prediction: at the origin, no range to keep")
    return _repointed(los, origin, prediction)


def _repointed(los, origin, prediction) -> np.ndarray:
    """:func:`repointed` of checked arguments."""
    r = float(np.linalg.norm(prediction - origin))
    phi, psi = float(los.phi[0]), float(los.psi[0])
    q = origin + r * np.array([np.cos(psi) * np.cos(phi), np.cos(psi) * np.sin(phi), np.sin(psi)])
    return np.array([q[0], q[1], prediction[2]])


def _second_start(route, arr, los, pred) -> list:
    """[the second start] of :func:`direct_drive` (:func:`repointed`), or [] without eq. 1's
    line of sight, within :data:`RESTART_M` of the prediction, or outside the tunnel."""
    if los is None or not len(los):
        return []
    q = _repointed(los, arr.origin, pred)
    far = np.hypot(*(q[:2] - pred[:2])) > RESTART_M
    return [q] if far and bool(route.tunnel.contains(q, 1e-6)) else []


def _best_fix(route, arr, snap, starts, velocity, **options):
    """The direct fit (:func:`~tunnelkit.extraction.direct.fit.direct_fix`, ``options``) of ``snap`` from each of
    ``starts``: the ok fit of smallest residual; else the first fit (not ok); None when every
    fit raised."""
    fits = []
    for p in starts:
        try:
            fits.append(direct_fix(route, arr, snap.H, p, velocity, **options))
        except _FAILURES:
            pass
    good = [f for f in fits if f.ok]
    return min(good, key=lambda f: f.residual) if good else (fits[0] if fits else None)


def direct_drive(
    route: SignalRoute,
    rng: np.random.Generator,
    design: JavelinDesign,
    eq1_table: ElevationSigmas | None,
    table: ElevationSigmas,
    *,
    speed_sigma: float | None = None,
    second_order: int = 64,
    n_epochs: int | None = None,
    start_sigma: float = 0.1,
    start_height_sigma: float | None = None,
    element_second_order: bool = False,
    max_unmodelled: float | None = None,
    diffuse: int = 0,
    diffuse_above: float = 0.0,
    start: np.ndarray | None = None,
    second_start: bool = False,
    replay: DirectDrive | None = None,
) -> DirectDrive:
    """One drive of ``route`` (the line of sight always present; the study's channel is the ray
    tracer's, on the image channel the direct model is eq. 1's own with masks): the V2X
    messages of its trajectory's odometry, then each epoch's snapshot, drawn from ``rng`` in that
    order; copies of ``design`` (a line-of-sight JAVELIN reading each measurement's covariance,
    :func:`tunnelkit.design.tracedlos.los_javelin`) started at the true first position told
    ``start_sigma`` [m] (the traced tables' line-of-sight column; ``start`` (3,) [m] given,
    every tracker starts there instead: an entry fix drawn by the caller, the design's
    :func:`~tunnelkit.tracking.javelin.runs.draw_start`, at most 10 ``start_sigma`` from the
    truth), its height told
    ``start_height_sigma`` [m] (None: ``start_sigma``, as the tables; a vehicle's antenna height
    is known better, the design tells :data:`~tunnelkit.design.START_HEIGHT_SIGMA_M`: a loosely
    told height takes up a bias of the measured elevations and turns it into an error along the
    tunnel near the site), one per :data:`TRACKERS`
    (module docstring): eq. 1's line of sight told ``eq1_table`` (None: no ``"eq. 1"`` tracker,
    its extraction not run), the direct fix's (at most
    ``second_order`` second-order atoms) ``table``, its speed told ``speed_sigma`` [m/s] (None:
    the speed not used, no ``"direct speed alone"``). The curvature's and the delay's sigmas are
    ``design``'s (the delay told half its TDoA variance, as
    :func:`~tunnelkit.design.tracedlos.told_los`). ``element_second_order``: the direct fit's
    second-order atoms each on the elements that see it (:func:`~tunnelkit.extraction.direct.fit.direct_fix`).
    ``max_unmodelled``: a direct fix whose :func:`unmodelled_share` exceeds it is dropped (the
    fit's own flag: the model cannot absorb that share of the tensor's power; None: every ok fix
    is fed). ``diffuse``: the direct fit admits at most that many diffuse atoms (a delay and a
    Doppler, a free gain per element; :class:`~tunnelkit.extraction.direct.fit.DirectProblem`), tested against the
    snapshot's noise power; the unmodelled share is then what the tied atoms and those free gains
    leave, a weaker flag for ``max_unmodelled``, and the told ``table`` does not know whether a
    fix admitted one; ``diffuse_above``: tried only where the tied fit's unmodelled share exceeds
    it (:func:`~tunnelkit.extraction.direct.fit.direct_fix`). ``second_start``: the direct fit also started from eq. 1's
    line of sight of the epoch (:func:`eq1_los`, run for it with or without ``eq1_table``) at
    the prediction's range and height (:func:`repointed`), where that start lies more than
    :data:`RESTART_M` from the prediction; of the ok fits the one of smaller residual is kept
    (a prediction far off, the design's 1 m entry fix, leads a fit started there alone into the
    wrong basin). ``replay``: an earlier drive of this route from this generator (``rng`` in
    the same state, the same ``design``, start, ``speed_sigma`` and ``max_unmodelled``: a drive
    whose dead reckoning or snapshots differ from the replayed one's is refused) whose
    :attr:`DirectDrive.fixes` are fed instead of fitting (no extraction, so the fit's options
    ``second_order``, ``element_second_order``, ``diffuse``, ``diffuse_above`` and
    ``second_start`` play no part; not with ``eq1_table``): the trackers told another ``table``
    on the same fixes, to choose told sigmas in seconds. The fit starts at the prediction, so a
    track told other sigmas would have met slightly different fixes: a replay approximates that
    drive, it does not repeat it (the same sigmas repeat it to the last digit)."""
    instance("route", route, SignalRoute)
    rng = rng_or_error("rng", rng)
    instance("design", design, JavelinDesign)
    if not isinstance(design.noise, ReportedNoise):
        raise TypeError(
            "design: expected a line-of-sight JAVELIN reading each measurement's covariance "
            f"(tracedlos.los_javelin), got noise {type(design.noise).__name__}"
        )
    if eq1_table is not None:
        instance("eq1_table", eq1_table, ElevationSigmas)
    instance("table", table, ElevationSigmas)
    if speed_sigma is not None and positive("speed_sigma", speed_sigma) > 10.0:
        raise ValueError(f"speed_sigma: a speed's sigma of at most 10 m/s, got {speed_sigma:g}")
    n2 = integer("second_order", second_order, minimum=0, maximum=64)
    by_element = boolean("element_second_order", element_second_order)
    restart = boolean("second_start", second_start)
    if max_unmodelled is not None and not 0.0 < positive("max_unmodelled", max_unmodelled) <= 1.0:
        raise ValueError(f"max_unmodelled: a share of the power in (0, 1], got {max_unmodelled:g}")
    n_diffuse = integer("diffuse", diffuse, minimum=0, maximum=MAX_DIFFUSE)
    above = diffuse_share(diffuse_above, n_diffuse)
    if positive("start_sigma", start_sigma) > 1000.0:
        raise ValueError(f"start_sigma: at most 1000 m, got {start_sigma:g}")
    if start_height_sigma is None:
        start_height_sigma = start_sigma
    elif positive("start_height_sigma", start_height_sigma) > MAX_HEIGHT_M:
        raise ValueError(
            f"start_height_sigma: at most {MAX_HEIGHT_M:g} m, got {start_height_sigma:g}"
        )
    traj = route.trajectory
    p0 = traj.position[0]
    if start is not None:
        p0 = finite_array("start", start, shape=(3,))
        off = np.abs(p0 - traj.position[0]) / np.array([start_sigma] * 2 + [start_height_sigma])
        if np.max(off) > 10.0:
            raise ValueError(
                f"start: {np.max(off):.3g} of its told sigmas from the drive's first position "
                "(at most 10: a fix the told start_sigma / start_height_sigma describe)"
            )
    T = (
        len(traj)
        if n_epochs is None
        else integer("n_epochs", n_epochs, minimum=1, maximum=len(traj))
    )
    if replay is not None:
        instance("replay", replay, DirectDrive)
        if eq1_table is not None:
            raise ValueError("replay, eq1_table: a replay feeds the direct fixes only; give no "
                             "eq1_table")  # fmt: skip
        if len(replay.truth) < T or not np.array_equal(replay.truth[:T], traj.position[:T]):
            raise ValueError(f"replay: not a drive of this route's first {T} epochs")
        if len(replay.fixes) < T:
            raise ValueError("replay: holds no fixes (a drive pickled before DirectDrive.fixes); "
                             "drive it again")  # fmt: skip
    vel = traj.velocity[:T]
    truth = np.linalg.norm(vel[:, :2], axis=1), np.arctan2(vel[:, 1], vel[:, 0])
    speed, heading = traj.odometry.draw(traj.t[:T], *truth, rng)
    d = design.with_(
        base_station=tuple(float(v) for v in route.arrays[0].origin),
        sigma_p0_ue=start_sigma,
        sigma_p0_height=start_height_sigma,
    )
    names = [n for n in TRACKERS if (n != "eq. 1" or eq1_table is not None)
             and (n != "direct speed alone" or speed_sigma is not None)]  # fmt: skip
    trackers = {name: _StepSigma(p0, d) for name in names}
    c = config_sigmas(d.config)
    if speed_sigma is not None:  # the averaged speed's sigma
        fused = float(1.0 / np.hypot(1.0 / d.config.sigma_speed, 1.0 / speed_sigma))
    told = {"direct": table} if eq1_table is None else {"eq. 1": eq1_table, "direct": table}
    spd, hdg = (speed, heading) if d.config.motion_step != "midpoint" else midpoint_messages(
        speed, heading)  # fmt: skip
    dt = float(traj.t[1] - traj.t[0]) if T > 1 else 0.1  # as DriveData.dt
    est = {name: np.empty((T, 3)) for name in names}
    errs, speed_err, unmodelled = {name: [] for name in told}, [], []
    secs = {name: np.zeros(T) for name in told}
    dropped = dict.fromkeys(told, 0)
    fixes = []
    radio = float("nan")  # the last ok fit's speed
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fits' own tests flag every traced epoch
        for k in range(T):
            v, th = (spd[k - 1], hdg[k - 1]) if k else (speed[0], heading[0])
            for name, jav in trackers.items():
                u, jav.step_sigma = v, None  # the message's speed, told the design's sigma
                fuse = name.startswith("direct") and speed_sigma is not None
                if fuse and np.isfinite(radio) and np.isfinite(v):  # averaged with the fit's
                    w = (d.config.sigma_speed / speed_sigma) ** 2
                    u, jav.step_sigma = (v + w * radio) / (1.0 + w), fused
                jav.predict(u, th, dt if k else 0.0)
            arr, paths, snap = route.draw(
                k, rng
            )  # paths: only their number, as the tables' ML route
            pm, los1, t_eq = {}, None, 0.0
            if (eq1_table is not None or restart) and replay is None:
                t0 = time.perf_counter()
                try:
                    los1 = _eq1_los(route, k, arr, len(paths), snap)
                except _FAILURES:
                    pass
                t_eq = time.perf_counter() - t0
                if eq1_table is not None:
                    pm["eq. 1"], secs["eq. 1"][k], t_eq = los1, t_eq, 0.0
            t0 = time.perf_counter()
            ok = np.isfinite(speed[k]) and np.isfinite(heading[k])
            v_msg = ue_velocity(speed[k], heading[k]) if ok else np.zeros(3)
            pred = trackers["direct"].x[:3]
            if replay is not None:
                fix = replay.fixes[k]
            else:
                starts = [pred] if not restart else [pred, *_second_start(route, arr, los1, pred)]
                fix = _best_fix(route, arr, snap, starts, v_msg,
                                second_order=n2, speed=speed_sigma is not None and ok,
                                element_second_order=by_element, diffuse=n_diffuse,
                                noise_power=snap.noise_power if n_diffuse else None,
                                diffuse_above=above)  # fmt: skip
            fixes.append(fix)
            radio = float("nan")
            share = _unmodelled(fix.residual, snap) if fix is not None and fix.ok else None
            if share is not None:
                unmodelled.append(share)
            if share is not None and (max_unmodelled is None or share <= max_unmodelled):
                pm["direct"] = _fix_los(fix, arr.origin, v_msg, route.min_d)
                if np.isfinite(fix.speed):
                    radio = fix.speed
                    speed_err.append(fix.speed - float(np.linalg.norm(vel[k, :2])))
            secs["direct"][k] = time.perf_counter() - t0 + t_eq  # with eq. 1's for the start
            for name, jav in trackers.items():
                m = pm.get(name)
                if name in told:
                    if m is None or not len(m):
                        dropped[name] += 1
                        m = None
                    else:
                        m = told_epoch(m, told[name], c["kappa"], c["d"] / np.sqrt(2))
                        errs[name].append(
                            los_error_rows(m.phi[:1], m.psi[:1], [traj.position[k] - arr.origin])[0]
                        )
                jav.update(m)
                est[name][k] = jav.x[:3]
    if replay is not None and not (
        np.array_equal(est["dead reckoning"], replay.estimates["dead reckoning"][:T])
        and np.array_equal(unmodelled, replay.unmodelled[: len(unmodelled)])
    ):
        raise ValueError("replay: not a drive of this route, generator, start and design (its "
                         "dead reckoning or its snapshots differ)")  # fmt: skip
    return DirectDrive(
        traj.position[:T].copy(),
        est,
        {n: np.array(r, float).reshape(-1, 3) for n, r in errs.items()},
        np.array(speed_err, float),
        secs,
        dropped,
        np.array(unmodelled, float),
        tuple(fixes),
    )
