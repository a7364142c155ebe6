"""The JAVELIN tracker: :meth:`Javelin.step` reads like Algorithm 4 (Italiano et al. 2026).

    predict  (eq. 62-63)   -> associate (Algorithm 2) -> manage tracks (Algorithm 3)
    -> update (eq. 64-68)  -> drop the one-epoch tracks of dynamic reflectors

Faults in the input stream never stop a run: an epoch without measurement (``None``) or with no
usable path is predict-only; a missing speed/heading message reuses the last one with a larger
speed noise; an update whose innovation covariance is not positive definite is skipped. Each is
reported with a :class:`JavelinWarning` and in the step report.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..._checks import attributes, optional_real, unchecked
from ..._physical import speeds, step_seconds
from ..._validate import boolean, finite_array, messages, record, vector
from ..gating import ChiSquareGate
from ..registry import register
from .associate import AssociationCosts
from .manage import ManageResult, manage_tracks
from .measurement import DopplerClutter, JavelinWarning, PathMeasurements
from .motion import midpoint_messages, predict, ue_velocity
from .roles import JavelinDesign
from .state import JavelinState, track_slice

__all__ = [
    "Javelin",
    "JavelinRun",
    "StepReport",
]


@dataclass
class StepReport:
    """Everything one epoch did, for plots and the epoch-by-epoch explorer."""

    k: int
    prior_positions: np.ndarray
    prior_ids: list[int]
    prior_cov: list[np.ndarray]
    costs: AssociationCosts | None
    associated: list[tuple[int, int]]
    manage: ManageResult | None
    n_paths: int
    n_rows: int
    nis: float
    estimate: np.ndarray
    cov: np.ndarray
    positions: np.ndarray
    ids: list[int]
    paths: PathMeasurements
    faults: list[str] = field(default_factory=list)
    clutter: int = 0

    def __post_init__(self) -> None:
        lists = ("prior_ids", "associated", "ids", "faults")
        record(self, shapes={"prior_positions": (None, 3), "estimate": (3,), "cov": (3, 3),
                             "positions": (None, 3)},
               nonnegative=("k", "n_paths", "n_rows", "nis", "clutter"), may_be_empty=lists)  # fmt: skip


@register("italiano2026", "JAVELIN")
class Javelin:
    """Variable-dimension EKF over the UE and its virtual UEs (Algorithm 4), built from the
    roles of a :class:`~tunnelkit.tracking.javelin.roles.JavelinDesign` (default: the paper's).

    >>> trk = Javelin(initial_position=[-40.0, 1.5, -3.3])
    >>> rep = trk.step(paths, speed=10.0, heading=0.0, dt=0.1)   # doctest: +SKIP
    """

    name = "JAVELIN"

    def __init__(self, initial_position, design: JavelinDesign | None = None) -> None:
        self.design = JavelinDesign() if design is None else design
        if not isinstance(self.design, JavelinDesign):
            raise TypeError(
                f"design: expected a JavelinDesign (tracking.javelin.designs), got "
                f"{type(self.design).__name__}"
            )
        self.config = self.design.config
        p0 = vector("initial_position", initial_position, 3)
        cfg = self.config
        self.state = JavelinState.initial(
            p0, cfg.sigma_p0_ue, cfg.sigma_p0_height, odometry=cfg.odometry_sigmas
        )
        if getattr(self.design.noise, "consider", False):  # the UE's bias, uncorrelated
            self.state.C = np.zeros((self.state.dim, 4))
        self.gate = ChiSquareGate(self.config.gate_probability)
        self.k = 0
        self._last_motion: tuple[float, float] | None = None
        self._predicted: tuple | None = None  # what the last predict left for the update
        self._sites: dict[tuple, object] = {}  # the config of each serving site seen so far

    # -- the family protocol (tunnelkit.tracking.registry, "italiano2026") ----------------------
    @classmethod
    def for_drive(
        cls,
        drive,
        design: JavelinDesign | None = None,
        *,
        sigma_p0_ue: float = 1.0,
        start=None,
        sigma_p0_height: float | None = None,
    ):
        """A tracker for a simulated drive (anything with ``truth``, ``base_station``,
        ``epochs``, ``speed``, ``heading``, ``dt``): it starts from ``start`` (3,) [m], default
        the true first position (the open-sky fix the paper assumes), with ``sigma_p0_ue`` [m]
        of uncertainty (``sigma_p0_height`` for the height when given), the base station at the
        drive's reference antenna, the roles of ``design`` (default the paper's). An honest start
        (its error drawn with the covariance the tracker is told, :func:`~.runs.draw_start`) is the
        caller's to give."""
        attributes(
            "drive", drive, ("truth", "base_station"), "a simulated drive (simulation.DriveData)"
        )
        d = JavelinDesign() if design is None else design
        if not isinstance(d, JavelinDesign):
            raise TypeError(f"design: expected a JavelinDesign, got {type(d).__name__}")
        d = d.with_(
            base_station=tuple(float(v) for v in drive.base_station),
            sigma_p0_ue=sigma_p0_ue,
            sigma_p0_height=sigma_p0_height,
        )
        p0 = drive.truth[0] if start is None else vector("start", start, 3)
        return cls(p0, d)

    def track(self, drive, *, keep_reports: bool = False) -> tuple[np.ndarray, JavelinRun]:
        """UE estimates (T, 3) over ``drive``'s measurement stream and the :class:`JavelinRun`."""
        attributes("drive", drive, _DRIVE, "a simulated drive (simulation.DriveData)")
        run = self.run(
            drive.epochs, drive.speed, drive.heading, drive.dt, keep_reports=keep_reports
        )
        return run.estimates, run

    def run(self, epochs, speed, heading, dt: float, *, keep_reports: bool = False) -> JavelinRun:
        """Step through a measurement stream (:func:`~.runs.run_javelin`): into epoch k on the
        message of k-1 (eq. 62) or the ``"midpoint"`` of k-1 and k
        (:func:`.motion.midpoint_messages`); a :meth:`step` on its own."""
        if isinstance(epochs, str | bytes) or not isinstance(epochs, Sequence | np.ndarray):
            raise TypeError(
                f"epochs: expected a sequence of PathMeasurements or None, got {type(epochs).__name__}"
            )
        n = len(epochs)
        keep_reports = boolean("keep_reports", keep_reports)
        spd, hdg = messages("speed", speed), messages("heading", heading)
        if spd.size != n or hdg.size != n:
            raise ValueError(
                f"epochs, speed, heading: expected one speed and heading per epoch ({n}), got "
                f"{spd.size} and {hdg.size}"
            )
        finite_array("dt", dt, ndim=0)
        first = (spd[0], hdg[0]) if n else None  # epoch 0 reads its own message
        if self.config.motion_step == "midpoint":  # the step into k on the mean of k-1 and k
            spd, hdg = midpoint_messages(spd, hdg)
        est = np.empty((n, 3))
        cov = np.empty((n, 3, 3))
        ntr = np.empty(n, dtype=int)
        reps, faults = [], 0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", JavelinWarning)
            for k in range(n):
                v, th = (spd[k - 1], hdg[k - 1]) if k else first
                r = self.step(epochs[k], v, th, dt if k else 0.0)
                est[k], cov[k], ntr[k] = r.estimate, r.cov, len(r.ids) + 1
                faults += len(r.faults)
                if keep_reports:
                    reps.append(r)
        return JavelinRun(est, cov, ntr, reps, faults)

    # -- small pieces -------------------------------------------------------------------------
    def _motion(self, speed, heading, faults: list[str]) -> tuple[float, float, float | None]:
        ok = (
            speed is not None
            and heading is not None
            and np.isfinite(speed)
            and np.isfinite(heading)
        )
        if ok:
            self._last_motion = (float(speed), float(heading))
            return float(speed), float(heading), None
        sig = self.config.sigma_speed + self.config.sigma_speed_missing
        if self._last_motion is None:
            faults.append("speed/heading message missing, none received yet: UE assumed still")
            return 0.0, 0.0, sig
        faults.append("speed/heading message missing: last message reused with inflated noise")
        return *self._last_motion, sig

    def _paths(self, paths, faults: list[str]) -> PathMeasurements:
        if paths is None:
            faults.append("no measurement this epoch: predict only")
            return PathMeasurements.empty()
        # a PathMeasurements built directly may still hold NaN angles or d < 0 (Algorithm 1)
        clean, dropped = self.design.prefilters[0](paths, None)
        if dropped:
            faults.append(f"{dropped} path(s) failing the checks of Algorithm 1 dropped")
        return clean

    def _prefilter(
        self, meas: PathMeasurements, speed: float | None
    ) -> tuple[PathMeasurements, int]:
        """The pre-filters after Algorithm 1's check; returns the paths kept and the clutter
        count (paths the Doppler test dropped)."""
        n_clutter = 0
        for pre in self.design.prefilters[1:]:
            meas, n = pre(meas, speed)
            if isinstance(pre, DopplerClutter):
                n_clutter += n
        return meas, n_clutter

    def _epoch_config(self, meas: PathMeasurements):
        """The config this epoch's measurement model is evaluated with: the tracker's own, its
        base station replaced by the epoch's serving site where the measurements name one
        (``PathMeasurements.site``, a drive along a row of sites). The state does not change
        with the site: a virtual UE is the UE mirrored in a surface, whichever site sees it."""
        if meas.site is None:
            return self.config
        key = tuple(float(v) for v in meas.site)
        if key == self.config.base_station:
            return self.config
        if key not in self._sites:
            self._sites[key] = self.config.with_(base_station=key)
        return self._sites[key]

    def _model(self, x: np.ndarray, cfg) -> tuple[np.ndarray, np.ndarray]:
        """The curvature role's per-track predictions and Jacobians at the state ``x``
        (:func:`~.measurement.track_model`), the odometry states' columns zero."""
        n = self.state.n_odo
        if not n:  # the paper's state
            return self.design.curvature.predict(x, cfg.bs)
        from .odometrystates import kinematic, odometry_columns  # a tracker told the odometry

        pred, J = self.design.curvature.predict(kinematic(x, n), cfg.bs)
        return pred, odometry_columns(J, n)

    # -- Algorithm 4: the tracking protocol (predict, update; step does both) ----------------
    @property
    def x(self) -> np.ndarray:
        """The state: the UE's position, the odometry states when told them
        (:data:`~.state.ODOMETRY_STATES`), then every virtual UE's ``(y, z)`` [m]."""
        return self.state.x

    @property
    def P(self) -> np.ndarray:
        """The state's covariance [m^2]."""
        return self.state.P

    def predict(self, speed: float | None, heading: float | None, dt: float) -> None:
        """Predict (eq. 62-63) with the V2X message (``speed`` [m/s], ``heading`` [rad]; None
        or NaN: missing, the last one reused with a larger speed noise) over ``dt`` [s]. Two
        predictions before an update: the update sees the last message and both one's faults."""
        dt = step_seconds("dt", dt)
        optional_real("speed", speed), optional_real("heading", heading)
        if speed is not None and np.isfinite(speed):  # NaN: the message is missing
            speeds("speed", speed)
        faults: list[str] = [] if self._predicted is None else self._predicted[3]
        nu, theta, sig_nu = self._motion(speed, heading, faults)
        st, roles = self.state, self.design
        st.x, st.P = predict(
            st, nu, theta, dt, self.config, vue_motion=roles.vue_motion.name, sigma_speed=sig_nu
        )
        if st.C is not None:  # F = I: the cross-covariance only decays with the biases
            st.C = st.C * roles.noise.decay(dt)
        self._predicted = (nu, theta, sig_nu, faults)

    def step(
        self, paths: PathMeasurements | None, speed: float | None, heading: float | None, dt: float
    ) -> StepReport:
        """One epoch: :meth:`predict` with (speed, heading) over ``dt``, then :meth:`update`
        (``paths`` checked before the state moves)."""
        _check_paths(paths)
        self.predict(speed, heading, dt)
        return self._update(paths)

    def update(self, paths: PathMeasurements | None) -> StepReport:
        """Associate (Algorithm 2), manage tracks (Algorithm 3) and update (eq. 64-68) with the
        epoch's paths (None: predict only). The first epoch of a design whose initiator
        acquires starts with the first fix (:func:`~.iterated.first_fix`). Without a :meth:`predict` since
        the last update, the motion is unknown (the Doppler pre-filter and the VUE births then
        go without the UE's velocity)."""
        _check_paths(paths)
        return self._update(paths)

    def _update(self, paths) -> StepReport:  # warnings point at the caller of update or step
        roles = self.design
        nu, theta, sig_nu, motion_faults = self._predicted or (None, None, None, [])
        self._predicted = None
        faults: list[str] = []
        meas = self._paths(paths, faults)
        faults += motion_faults  # the path faults first, then the motion's (as one step reports)
        known = nu is not None and sig_nu is None
        meas, n_clutter = self._prefilter(meas, nu if known else None)
        cfg = self._epoch_config(meas)  # the serving site's measurement model
        used = None
        if self.k == 0 and getattr(roles.initiator, "acquire", False) and len(meas):
            from .iterated import first_fix  # an initiator that acquires (the array design's)

            used = first_fix(self.state, roles, meas, faults, cfg, self._model)
        st = self.state
        prior_pos, prior_ids = st.positions(), list(st.ids)
        sl = [track_slice(i, st.n_odo) for i in range(st.n_tracks)]
        prior_cov = [st.P[i, i].copy() for i in sl]
        costs, assoc, mres, nis, n_rows = None, [], None, 0.0, 0
        geometry_ok = True
        if len(meas):
            try:
                pred, J = self._model(st.x, cfg)
            except ValueError as exc:  # a track on the base station's axis: azimuth undefined
                geometry_ok = False
                faults.append(f"measurement model undefined ({exc}): predict only")
        if len(meas) and geometry_ok:
            noise = roles.noise
            if noise.needs_reported and not meas.reported:
                faults.append("no reported covariance this epoch: the fixed sigmas used")
            # Associate (Algorithm 2)
            R3 = noise.covariances(meas, cfg)
            costs, assoc = roles.associator(pred, J, st.P, meas, R3, self.gate)
            if used is not None:  # the first fix chose the UE's path (no VUE exists yet)
                assoc = [(0, used)]
            # ManageTracks (Algorithm 3)
            v_u = ue_velocity(nu, theta) if known else None
            mres = manage_tracks(st, meas, assoc, cfg, v_u, initiator=roles.initiator, noise=noise)
            # Update (eq. 64-68); the first fix's path has been used (counted once)
            if used is not None:
                mres.pairs = [(i, j) for i, j in mres.pairs if (i, j) != (0, used)]
            pred, J = self._model(st.x, cfg)
            try:
                m, left_out = roles.updater.stack(
                    st.x, st.P, pred, J, meas, mres.pairs, cfg, mres.los_path, noise, st.C
                )
                if left_out:
                    faults.append(f"{len(left_out)} pair(s) failed the joint innovation test")
                n_rows = m.z.size
                out = roles.updater.update(st.x, st.P, m, st.C)
                if n_rows and cfg.update_iterations:
                    from .iterated import iterate  # an iterated EKF (the array design's)

                    out = iterate(st, roles, out, meas, m, mres.los_path, st.C, cfg, self._model)
                x_new, P_new, nis = out[:3]
                C_new = out[3] if len(out) == 4 else st.C
                if not (np.all(np.isfinite(x_new)) and np.all(np.isfinite(P_new))):
                    raise np.linalg.LinAlgError("non-finite update")
                st.x, st.P, st.C = x_new, P_new, C_new
            except np.linalg.LinAlgError as exc:
                faults.append(f"update skipped ({exc})")
            # dynamic reflectors contribute to this epoch only
            gone = [k + 1 for k, tr in enumerate(st.transient) if tr]
            mres.dead += st.remove(gone)
        elif paths is not None and geometry_ok:
            faults.append("no usable path this epoch: predict only")
            # every VUE missed this epoch
            mres = manage_tracks(st, meas, [], cfg, initiator=roles.initiator, noise=roles.noise)
        for f in faults:
            warnings.warn(f"epoch {self.k}: {f}", JavelinWarning, stacklevel=3)
        # the report holds what the step computed (checked at its boundary): built unchecked
        rep = unchecked(
            StepReport,
            self.k,
            prior_pos,
            prior_ids,
            prior_cov,
            costs,
            assoc,
            mres,
            len(meas),
            n_rows,
            nis,
            st.ue,
            st.P[:3, :3].copy(),
            st.positions(),
            list(st.ids),
            meas,
            faults,
            n_clutter,
        )
        self.k += 1
        return rep


@dataclass
class JavelinRun:
    """UE estimates (T, 3), their covariances (T, 3, 3), and the step reports (if kept)."""

    estimates: np.ndarray
    covariances: np.ndarray
    n_tracks: np.ndarray
    reports: list[StepReport]
    faults: int

    def __post_init__(self) -> None:
        record(self, shapes={"estimates": ("T", 3), "covariances": ("T", 3, 3),
                             "n_tracks": ("T",)},
               nonnegative=("n_tracks", "faults"), may_be_empty=("reports",))  # fmt: skip


#: what :meth:`Javelin.track` reads of a drive
_DRIVE = ("epochs", "speed", "heading", "dt")


def _check_paths(paths) -> None:
    """``paths`` of one epoch: PathMeasurements or None (checked before the state moves)."""
    if paths is not None and not isinstance(paths, PathMeasurements):
        raise TypeError(f"paths: expected PathMeasurements or None, got {type(paths).__name__}")
