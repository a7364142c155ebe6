"""The three approaches of Halili et al. 2022, registered in family ``"halili2022"``, and their
runs on a drive.

:class:`EkfDS`, :class:`KfDSToA` and :class:`EkfDSKfToA` share one call protocol
(``cls(setup, fix, sigma_hz=..., q=..., adaptive=..., **kw)``, then ``step(doppler, toa)`` per
epoch or ``run(meas) -> Track``). :func:`run_approaches` runs them on one drive,
:func:`error_study` at every noise setting of the paper (:data:`SIGMAS`), :func:`mean_errors`
averaged over seeded drives.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..._validate import instance, integer, positive, record, sequence, text
from ...doppler_drive import DopplerToaMeasurements, Drive, GnssFix, gnss_fix, measure, slant_range
from ..registry import family, register
from .filters import (
    DopplerEKF,
    DopplerSetup,
    HeadingDeadReckoning,
    MeasurementWarning,
    RangeKF,
    SpeedKF,
    scalar_measurement,
)

__all__ = [
    "APPROACHES",
    "DEAD_RECKONING",
    "SIGMAS",
    "EkfDS",
    "EkfDSKfToA",
    "KfDSToA",
    "Track",
    "dead_reckoning",
    "error_study",
    "mean_errors",
    "run_approaches",
]

#: the paper's three approaches, in the order of its tables
APPROACHES = ("EKF DS", "KF DS and ToA", "EKF DS and KF ToA")
#: the baseline beside them (:func:`dead_reckoning`): the GNSS fix carried on at its velocity
DEAD_RECKONING = "dead reckoning"


@dataclass(frozen=True)
class Track:
    """Output of a run: times (T,), position estimates (T, 2) and speed estimates (T,) [m/s]."""

    t: np.ndarray
    position: np.ndarray
    speed: np.ndarray

    def __post_init__(self) -> None:
        record(self, shapes={"t": ("T",), "position": ("T", 2), "speed": ("T",)})


# --- the three approaches, registered -------------------------------------------------------------


class _Base:
    name = ""
    setup: DopplerSetup

    def step(self, doppler, toa=None) -> np.ndarray:  # pragma: no cover - interface
        raise NotImplementedError

    def speed(self) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    def run(self, meas: DopplerToaMeasurements) -> Track:
        """Run over a whole measurement stream; dropped epochs predict only (one summary warning)."""
        if not isinstance(meas, DopplerToaMeasurements):
            raise TypeError(f"meas: expected DopplerToaMeasurements, got {type(meas).__name__}")
        n = len(meas.t)
        pos = np.empty((n, 2))
        spd = np.empty(n)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", MeasurementWarning)
            for k in range(n):
                pos[k] = self.step(meas.doppler[k], meas.toa[k]) if k else self._first()
                spd[k] = self.speed()
        other = [w for w in caught if not issubclass(w.category, MeasurementWarning)]
        for w in other:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        n_bad = len(caught) - len(other)
        if n_bad:
            warnings.warn(
                f"{self.name}: {n_bad} measurement(s) dropped or rejected; "
                "predicted only at those epochs",
                MeasurementWarning,
                stacklevel=2,
            )
        return Track(t=meas.t, position=pos, speed=spd)

    def _first(self) -> np.ndarray:  # the first epoch is the GNSS fix itself
        return self._p0.copy()

    @property
    def n_rejected(self) -> int:
        """Doppler and ToA samples the gates of this approach rejected (predicted only)."""
        parts = (getattr(self, a, None) for a in ("ekf", "speed_kf", "range_kf"))
        return sum(f.n_rejected for f in parts if f is not None)


#: keywords of the gates, passed to every filter of an approach
_GATE_KEYS = ("gate", "reopen_after")


def _doppler_ekf(setup, fix, sigma_hz, q, adaptive, kw) -> DopplerEKF:
    """The EKF on Doppler shared by "EKF DS" and "EKF DS and KF ToA" (extra keywords filtered)."""
    extra = {k: v for k, v in kw.items() if k in ("a", "adaptive_form", *_GATE_KEYS)}
    return DopplerEKF(setup, fix, sigma_hz=sigma_hz, q=q, adaptive=adaptive, **extra)


@register("halili2022", "EKF DS")
class EkfDS(_Base):
    """EKF DS (sec. 4): the EKF on Doppler; the ToA is not used."""

    name = "EKF DS"

    def __init__(
        self,
        setup: DopplerSetup,
        fix: GnssFix,
        *,
        sigma_hz: float = 32.79,
        q: float = 0.5,
        adaptive: bool = False,
        **kw,
    ) -> None:
        self.setup = setup
        self.ekf = _doppler_ekf(setup, fix, sigma_hz, q, adaptive, kw)
        self._p0 = np.array(fix.position, dtype=float)

    def step(self, doppler, toa=None) -> np.ndarray:
        scalar_measurement("toa", toa)  # not used by the Doppler-only EKF, still checked
        return self.ekf.step(scalar_measurement("doppler", doppler))

    def speed(self) -> float:
        return float(np.linalg.norm(self.ekf.velocity))


class _KfToA(_Base):
    """Shared part of the two section-5 approaches: range KF + eq. 16 dead reckoning.

    Subclasses say where the approach speed comes from (``_init_speed`` and ``_approach_speed``).
    """

    def __init__(
        self,
        setup: DopplerSetup,
        fix: GnssFix,
        *,
        sigma_hz: float = 32.79,
        q: float = 0.5,
        adaptive: bool = False,
        sigma_toa: float = 3e-9,
        calibrate: bool = True,
        calibration_epochs: int = 10,
        **kw,
    ) -> None:
        self.setup = instance("setup", setup, DopplerSetup)
        instance("fix", fix, GnssFix)
        self._p0 = np.array(fix.position, dtype=float)
        d0 = float(slant_range(fix.position, setup.tx, setup.dz))
        gates = {k: v for k, v in kw.items() if k in _GATE_KEYS}
        self.range_kf = RangeKF(
            setup,
            d0,
            sigma_toa=sigma_toa,
            q=q,
            sigma_d0=fix.sigma_p,
            calibrate=calibrate,
            calibration_epochs=calibration_epochs,
            **gates,
        )
        self.dr = HeadingDeadReckoning(fix.position, fix.velocity)
        w = fix.position - setup.tx
        self._u0 = -float(fix.velocity @ w) / d0
        self._recent: list[float] = []  # the last Doppler samples, for the phase of eq. 16
        self._phase = 1.0 if self._u0 >= 0 else -1.0
        self._init_speed(setup, fix, sigma_hz, q, adaptive, kw)

    def _init_speed(self, setup, fix, sigma_hz, q, adaptive, kw) -> None:
        raise NotImplementedError

    def _approach_speed(self, doppler) -> float:
        raise NotImplementedError

    def _phase_of(self, doppler) -> float:
        """+1 approaching, -1 receding: the sign of the median of the last ``PHASE_WINDOW`` valid
        Doppler samples (a median, so one outlier cannot flip it; no filter lag at the pass)."""
        z = scalar_measurement("doppler", doppler)
        if z is not None:
            self._recent = [*self._recent[-(self.PHASE_WINDOW - 1) :], z]
            med = _median(self._recent)
            if med != 0:
                self._phase = 1.0 if med > 0 else -1.0
        return self._phase

    #: Doppler samples whose median gives the phase (approaching/receding) of eq. 16
    PHASE_WINDOW = 5

    def step(self, doppler, toa=None) -> np.ndarray:
        """Eq. 16-21 with the sign kept: a range change counts forward if it shrinks while
        approaching or grows while receding, backward otherwise (phase: :meth:`_phase_of`)."""
        phase = self._phase_of(doppler)
        u = self._approach_speed(doppler)
        d_prev = self.range_kf.distance
        d = self.range_kf.step(u, toa)
        return self.dr.step(phase * (d_prev - d))


def _median(values: list[float]) -> float:
    """``np.median`` of a few floats (no NaN): the middle one, or the mean of the two middle ones
    computed as numpy does, ``(a + b) / 2``, without numpy's overhead on a five-element list."""
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2.0


@register("halili2022", "KF DS and ToA")
class KfDSToA(_KfToA):
    """KF DS and ToA (sec. 5): KF on Doppler for the speed, KF on ToA for the distance, eq. 16."""

    name = "KF DS and ToA"

    def _init_speed(self, setup, fix, sigma_hz, q, adaptive, kw) -> None:
        extra = {k: v for k, v in kw.items() if k in ("a", "adaptive_form", *_GATE_KEYS)}
        self.speed_kf = SpeedKF(
            setup,
            self._u0,
            sigma_hz=sigma_hz,
            q=q,
            sigma_u0=fix.sigma_v,
            adaptive=adaptive,
            **extra,
        )

    def _approach_speed(self, doppler) -> float:
        return self.speed_kf.step(doppler)

    def speed(self) -> float:
        return abs(self.speed_kf.speed)


@register("halili2022", "EKF DS and KF ToA")
class EkfDSKfToA(_KfToA):
    """EKF DS and KF ToA (sec. 5, last paragraph): the EKF's approach speed drives the KF on ToA."""

    name = "EKF DS and KF ToA"

    def _init_speed(self, setup, fix, sigma_hz, q, adaptive, kw) -> None:
        self.ekf = _doppler_ekf(setup, fix, sigma_hz, q, adaptive, kw)

    def _approach_speed(self, doppler) -> float:
        self.ekf.step(doppler)
        return self.ekf.approach_speed

    def speed(self) -> float:
        return float(np.linalg.norm(self.ekf.velocity))


SIGMAS = {"103.70 Hz": 103.70, "32.79 Hz": 32.79, "10.37 Hz": 10.37, "dynamic": None}
"""The paper's measurement-noise settings (sec. 6, Fig. 4); ``None`` = adaptive R (eq. 15)."""


def run_approaches(
    drive: Drive,
    meas: DopplerToaMeasurements,
    fix: GnssFix,
    *,
    sigma_hz: float | None = 32.79,
    q: float = 0.5,
    approaches=APPROACHES,
    sigma0_hz: float = 32.79,
    **kw,
) -> dict[str, Track]:
    """Run the registered approaches on one drive; ``sigma_hz=None`` means adaptive R from ``sigma0_hz``."""
    fam = family("halili2022")
    if isinstance(approaches, str) or not isinstance(approaches, list | tuple):
        raise TypeError(f"approaches: expected a tuple of names, got {approaches!r:.60}")
    if not approaches:
        raise ValueError("approaches: expected at least one approach")
    for name in approaches:
        if name not in fam:
            raise ValueError(
                f"approaches: {name!r} is not in family 'halili2022'; members: {list(fam)}"
            )
    instance("drive", drive, Drive)
    instance("meas", meas, DopplerToaMeasurements)
    instance("fix", fix, GnssFix)
    sigma0_hz = positive("sigma0_hz", sigma0_hz)
    setup = DopplerSetup.from_drive(drive)
    adaptive = sigma_hz is None
    out = {}
    for name in approaches:
        trk = fam[name](
            setup, fix, sigma_hz=sigma0_hz if adaptive else sigma_hz, q=q, adaptive=adaptive, **kw
        )
        out[name] = trk.run(meas)
    return out


def dead_reckoning(drive: Drive, fix: GnssFix) -> np.ndarray:
    """Positions (T, 2) without the radio: the EKF's constant-velocity model from the GNSS fix
    (position and velocity at the tunnel entrance), predicting only; epoch 0 is the fix itself,
    as for the approaches. What every approach must beat on the same drive and fix."""
    instance("drive", drive, Drive)
    instance("fix", fix, GnssFix)
    ekf = DopplerEKF(DopplerSetup.from_drive(drive), fix)
    out = np.empty((len(drive.t), 2))
    out[0] = fix.position
    for k in range(1, len(drive.t)):
        ekf.predict()
        out[k] = ekf.position
    return out


def error_study(
    drive: Drive,
    rng: np.random.Generator,
    *,
    sigmas: dict | None = None,
    q: float = 0.5,
    approaches=APPROACHES,
    **kw,
) -> dict[tuple[str, str], np.ndarray]:
    """One noisy realisation of ``drive``, every approach at every sigma: position errors (T,) each.

    Keys ``(approach, sigma label)``; all settings see the same measurements and GNSS fix. The
    baseline, :func:`dead_reckoning` from the same fix, under ``(DEAD_RECKONING, "-")``.
    """
    if sigmas is not None and not isinstance(sigmas, Mapping):
        raise TypeError(f"sigmas: expected a mapping label -> sigma [Hz], got {sigmas!r:.40}")
    sigmas = SIGMAS if sigmas is None else dict(sigmas)
    meas = measure(drive, rng)
    fix = gnss_fix(drive, rng)
    out = {}
    for label, sig in sigmas.items():
        tracks = run_approaches(drive, meas, fix, sigma_hz=sig, q=q, approaches=approaches, **kw)
        for name, tr in tracks.items():
            out[(name, label)] = np.linalg.norm(tr.position - drive.position, axis=-1)
    out[(DEAD_RECKONING, "-")] = np.linalg.norm(
        dead_reckoning(drive, fix) - drive.position, axis=-1
    )
    return out


def mean_errors(
    drive: Drive,
    seeds,
    *,
    sigma_hz: float | None = 32.79,
    q: float = 0.5,
    approaches=APPROACHES,
    **kw,
) -> dict[str, float]:
    """Mean position error of each approach, averaged over drives seeded by ``seeds`` (ints).

    Each seed gives one noise realisation and GNSS fix (``numpy.random.default_rng(seed)``) shared
    by all approaches; extra keywords (``gate``, ``adaptive_form``, ...) go to the trackers.
    """
    seeds = [integer(f"seeds[{i}]", s, minimum=0) for i, s in enumerate(sequence("seeds", seeds))]
    [text(f"approaches[{i}]", a) for i, a in enumerate(sequence("approaches", approaches))]
    if not seeds:
        raise ValueError("seeds: give at least one seed")
    acc: dict[str, list[float]] = {name: [] for name in approaches}
    for seed in seeds:
        rng = np.random.default_rng(seed)
        meas = measure(drive, rng)
        fix = gnss_fix(drive, rng)
        tracks = run_approaches(
            drive, meas, fix, sigma_hz=sigma_hz, q=q, approaches=approaches, **kw
        )
        for name, tr in tracks.items():
            acc[name].append(float(np.mean(np.linalg.norm(tr.position - drive.position, axis=1))))
    return {name: float(np.mean(v)) for name, v in acc.items()}
