"""A synthetic drive through a road tunnel past one roadside transmitter (Halili et al. 2022, sec. 3).

The measured Beveren-tunnel data of the paper are not public, so notebook 06 rebuilds the drive:
a straight two-lane tube (10 m wide, 5 m high), one transmitter on a wall inside it, a van at
about 90 km/h for 54 s that passes the transmitter near second 37, carrier 1.35 GHz, 80 MHz
bandwidth, one set of channel parameters every 0.8 m.

Measurement model (every term can be dialled in :class:`DriveConfig`):

* **Geometry.** x along the tunnel, y across (walls at ``y = +-width/2``), z up (floor at 0,
  ceiling at ``height``). The vehicle moves in the x-y plane at antenna height ``rx_height``; the
  transmitter sits at ``(tx_x, tx_y, tx_z)``. Ranges are 3-D: ``r = sqrt(|p - T|^2 + dz^2)``.
* **Doppler sign (pinned).** ``f_D = -(f_c / c) v . (p - T) / r``: an approaching vehicle sees a
  *positive* shift, a receding one a negative shift, zero at the closest point. (Halili eq. 5
  prints ``+v . (s - T)``, which is positive when receding; the text says the opposite.)
* **Multipath.** The image method in the rectangular cross-section gives the line of sight plus
  wall/ceiling/floor reflections up to ``max_order`` (amplitude ``reflection_coeff`` per bounce,
  free-space spreading, carrier phase). The *measured* delay is the peak of the band-limited
  channel impulse response (``sinc`` of width 1/B) and the *measured* Doppler the peak of the
  Doppler spectrum of a ``window_snapshots x snapshot_period`` window: paths closer than the
  resolution merge and pull the peak, which is the deterministic multipath bias.
* **Random errors** (drawn from an explicit ``rng``): white noise whose standard deviation grows
  with range as the SNR falls (``sigma(r) = sigma_0 sqrt(1 + (r / noise_ref_range)^2)``); a
  slowly varying Doppler bias from traffic and non-stationary scatterers (first-order
  Gauss-Markov, correlation length ``bias_corr_m`` metres of travel); a positive NLOS excess
  delay with the same correlation; occasional Doppler outliers (the peak locks on a moving
  scatterer, uniform within the Doppler span); dropped epochs (NaN in both streams).
* **Clocks.** The ToA carries an unknown offset ``clock_offset_s`` plus a drift
  ``clock_drift`` (s/s); the Doppler a residual carrier-frequency offset ``cfo_hz`` plus a random
  walk ``cfo_walk_hz`` (Hz/sqrt(s)).

The channel part is deterministic for a given configuration and is cached; each call of
:func:`measure` adds fresh noise from its ``rng``.
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import lfilter

from ._validate import finite_array, nonnegative, positive, probability, real, rng_or_error
from .constants import C
from .scenarios import (
    MAX_SAMPLES,
    Scenario,
    ScenarioError,
    Trajectory,
    load_scenario,
    register_check,
)

__all__ = [
    "IDEAL",
    "Drive",
    "DriveConfig",
    "GnssFix",
    "Measurements",
    "channel_paths",
    "delay_doppler_profiles",
    "doppler_shift",
    "gnss_fix",
    "load_drive_config",
    "make_drive",
    "measure",
    "slant_range",
]


@dataclass(frozen=True)
class DriveConfig:
    """Every knob of the synthetic drive (SI units). Defaults follow Halili et al. 2022, sec. 3.

    Values the paper does not state (transmitter mount, lane, noise and bias levels, clock
    errors) are our assumptions, chosen to be physically plausible, never fitted to its results.
    """

    # tube and placement
    width: float = 10.0
    height: float = 5.0
    lane_y: float = -2.5
    rx_height: float = 2.0
    tx_y: float = 4.5
    tx_z: float = 4.5
    pass_time: float = 37.0
    # motion: mean speed, gentle speed variation (amplitude, period), duration, sample spacing
    speed: float = 25.0
    speed_amplitude: float = 1.0
    speed_period: float = 27.0
    duration: float = 54.0
    spacing: float = 0.8
    # radio / sounder
    fc: float = 1.35e9
    bandwidth: float = 80e6
    snapshot_period: float = 975.3e-6
    window_snapshots: int = 32
    # multipath
    reflection_coeff: float = 0.6
    max_order: int = 2
    # random errors
    doppler_noise_hz: float = 8.0
    toa_noise_s: float = 1e-9
    noise_ref_range: float = 300.0
    doppler_bias_hz: float = 10.0
    toa_bias_m: float = 1.0
    bias_corr_m: float = 20.0
    outlier_prob: float = 0.02
    drop_prob: float = 0.0
    # clocks
    clock_offset_s: float = 30e-9
    clock_drift: float = 0.2e-9
    cfo_hz: float = 0.0
    cfo_walk_hz: float = 0.2
    # the initial GNSS fix at the tunnel entrance
    gnss_sigma_m: float = 2.0
    gnss_sigma_v: float = 0.2

    def __post_init__(self) -> None:
        for name in (
            "width",
            "height",
            "rx_height",
            "speed",
            "duration",
            "spacing",
            "fc",
            "bandwidth",
            "snapshot_period",
            "noise_ref_range",
            "bias_corr_m",
            "speed_period",
        ):
            positive(name, getattr(self, name))
        for name in (
            "speed_amplitude",
            "doppler_noise_hz",
            "toa_noise_s",
            "doppler_bias_hz",
            "toa_bias_m",
            "clock_offset_s",
            "cfo_walk_hz",
            "gnss_sigma_m",
            "gnss_sigma_v",
            "pass_time",
        ):
            nonnegative(name, getattr(self, name))
        for name in ("clock_drift", "cfo_hz", "lane_y", "tx_y", "tx_z"):
            finite_array(name, getattr(self, name), ndim=0)
        probability("reflection_coeff", self.reflection_coeff, open_interval=False)
        probability("outlier_prob", self.outlier_prob, open_interval=False)
        probability("drop_prob", self.drop_prob, open_interval=False)
        if (
            isinstance(self.window_snapshots, bool)
            or not isinstance(self.window_snapshots, int)
            or self.window_snapshots < 2
        ):
            raise ValueError(
                f"window_snapshots: must be an integer >= 2, got {self.window_snapshots!r}"
            )
        if (
            isinstance(self.max_order, bool)
            or not isinstance(self.max_order, int)
            or not 0 <= self.max_order <= 6
        ):
            raise ValueError(f"max_order: must be an integer in [0, 6], got {self.max_order!r}")
        if self.speed_amplitude >= self.speed:
            raise ValueError(
                f"speed_amplitude: must be below speed ({self.speed}) so the vehicle keeps moving, "
                f"got {self.speed_amplitude}"
            )
        half = self.width / 2
        if not -half < self.lane_y < half:
            raise ValueError(f"lane_y: must lie inside the tube (|y| < {half}), got {self.lane_y}")
        if not -half < self.tx_y < half:
            raise ValueError(f"tx_y: must lie inside the tube (|y| < {half}), got {self.tx_y}")
        if not 0 < self.tx_z < self.height:
            raise ValueError(
                f"tx_z: must lie between floor and ceiling (0, {self.height}), got {self.tx_z}"
            )
        if not 0 < self.rx_height < self.height:
            raise ValueError(
                f"rx_height: must lie between floor and ceiling (0, {self.height}), got {self.rx_height}"
            )
        if self.pass_time > self.duration:
            raise ValueError(
                f"pass_time: must be within the drive (<= {self.duration} s), got {self.pass_time}"
            )

    def replace(self, **changes) -> DriveConfig:
        """A copy with some fields changed (validated again)."""
        unknown = set(changes) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise ValueError(f"{sorted(unknown)[0]}: not a DriveConfig field")
        return dataclasses.replace(self, **changes)

    @property
    def dt(self) -> float:
        """Epoch period [s]: one parameter set every ``spacing`` metres at the mean speed."""
        return self.spacing / self.speed

    @property
    def doppler_resolution(self) -> float:
        """Doppler resolution of the estimation window, ``1 / (M t_s)`` [Hz] (32 x 975.3 us: 32 Hz)."""
        return 1.0 / (self.window_snapshots * self.snapshot_period)

    @property
    def delay_resolution(self) -> float:
        """Delay resolution ``1 / B`` [s] (80 MHz: 12.5 ns, 3.75 m)."""
        return 1.0 / self.bandwidth


@dataclass(frozen=True)
class Drive:
    """The noise-free drive: ground truth, line-of-sight observables and multipath-peak observables.

    ``doppler_los``/``toa_los`` are the geometric values; ``doppler_peak``/``toa_peak`` are what an
    ideal (noise-free) estimator of the strongest peak returns in the multipath channel.
    """

    config: DriveConfig
    trajectory: Trajectory
    tx: np.ndarray  # (3,) transmitter
    range: np.ndarray  # (T,) slant range [m]
    doppler_los: np.ndarray  # (T,) [Hz], approach positive
    toa_los: np.ndarray  # (T,) [s]
    doppler_peak: np.ndarray = field(repr=False)
    toa_peak: np.ndarray = field(repr=False)

    @property
    def t(self) -> np.ndarray:
        return self.trajectory.t

    @property
    def position(self) -> np.ndarray:
        return self.trajectory.position

    @property
    def velocity(self) -> np.ndarray:
        return self.trajectory.velocity

    @property
    def tx_xy(self) -> np.ndarray:
        """Transmitter position in the horizontal plane (what the filters use)."""
        return self.tx[:2]

    @property
    def dz(self) -> float:
        """Transmitter height above the receiving antenna [m] (known to the vehicle)."""
        return float(self.tx[2] - self.config.rx_height)

    @property
    def closest_index(self) -> int:
        """Epoch of the closest approach to the transmitter."""
        return int(np.argmin(self.range))


@dataclass(frozen=True)
class Measurements:
    """One noisy realisation: Doppler [Hz] and ToA [s] per epoch; dropped epochs are NaN in both.

    ``dropped`` marks them explicitly; ``outlier`` marks Doppler samples that locked on a moving
    scatterer; ``parts`` holds each error term for teaching plots.
    """

    t: np.ndarray
    doppler: np.ndarray
    toa: np.ndarray
    dropped: np.ndarray
    outlier: np.ndarray
    parts: dict[str, np.ndarray] = field(repr=False)


@dataclass(frozen=True)
class GnssFix:
    """Last GNSS fix at the tunnel entrance: position and velocity with their standard deviations."""

    position: np.ndarray
    velocity: np.ndarray
    sigma_p: float
    sigma_v: float

    def __post_init__(self) -> None:
        finite_array("position", self.position, shape=(2,))
        v = finite_array("velocity", self.velocity, shape=(2,))
        positive("sigma_p", self.sigma_p)
        positive("sigma_v", self.sigma_v)
        if np.linalg.norm(v) < 1e-6:
            raise ValueError("velocity: the GNSS speed is zero, so the heading is undefined")

    @property
    def covariance(self) -> np.ndarray:
        """Prior covariance of the state ``[x, y, v_x, v_y]`` (P_0 of Halili sec. 4)."""
        return np.diag([self.sigma_p**2, self.sigma_p**2, self.sigma_v**2, self.sigma_v**2])


# --- geometry -------------------------------------------------------------------------------------


def _planar(name: str, value) -> np.ndarray:
    a = finite_array(name, value)
    if a.ndim == 0 or a.shape[-1] != 2:
        raise ValueError(f"{name}: expected horizontal positions (..., 2), got shape {a.shape}")
    return a


def slant_range(p, tx, dz: float = 0.0) -> np.ndarray:
    """``sqrt(|p - T|^2 + dz^2)`` for horizontal positions ``p`` (..., 2) and transmitter ``tx`` (2,)."""
    w = _planar("p", p) - finite_array("tx", tx, shape=(2,))
    return np.sqrt(np.sum(w * w, axis=-1) + real("dz", dz) ** 2)


def doppler_shift(p, v, tx, fc: float, dz: float = 0.0) -> np.ndarray:
    """Doppler shift [Hz] of the line of sight, Halili eq. 5 with the sign pinned (approach > 0).

    ``f_D = -(f_c / c) v . (p - T) / r`` with ``r`` the slant range (transmitter ``dz`` above the
    receiving antenna). Vectorised over leading axes of ``p`` and ``v`` (..., 2). ``fc > 0``; a
    position at the transmitter with ``dz = 0`` (range zero) raises.
    """
    p, v = _planar("p", p), _planar("v", v)
    fc, dz, tx = positive("fc", fc), real("dz", dz), finite_array("tx", tx, shape=(2,))
    return _doppler_shift(p, v, tx, fc, dz)


def _doppler_shift(p, v, tx, fc: float, dz: float, name: str = "p") -> np.ndarray:
    """:func:`doppler_shift` on checked float inputs (filters call it every epoch)."""
    w = p - tx
    r = np.sqrt(np.sum(w * w, axis=-1) + dz * dz)
    if not np.all(r):
        raise ValueError(
            f"{name}: coincides with the transmitter (dz = 0), the Doppler is undefined"
        )
    return -(fc / C) * np.sum(v * w, axis=-1) / r


def _speed_profile(cfg: DriveConfig, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance travelled and speed: ``v(t) = v0 + A sin(2 pi t / T_p)`` (exactly integrated)."""
    w = 2 * np.pi / cfg.speed_period
    s = cfg.speed * t + cfg.speed_amplitude * (1 - np.cos(w * t)) / w
    return s, cfg.speed + cfg.speed_amplitude * np.sin(w * t)


def image_sources(cfg: DriveConfig, tx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Image transmitters of the rectangular cross-section up to ``max_order`` bounces.

    Walls at ``y = +-W/2``: images at ``y_m = m W + (-1)^m y_T``; floor/ceiling likewise about
    ``z = H/2``. Returns positions (P, 3) and bounce counts (P,), line of sight first.
    """
    n = cfg.max_order
    ms = np.arange(-n, n + 1)
    my, mz = np.meshgrid(ms, ms, indexing="ij")
    keep = (np.abs(my) + np.abs(mz)) <= n
    my, mz = my[keep], mz[keep]
    order = np.abs(my) + np.abs(mz)
    y = my * cfg.width + np.where(my % 2 == 0, 1.0, -1.0) * tx[1]
    zc = tx[2] - cfg.height / 2
    z = cfg.height / 2 + mz * cfg.height + np.where(mz % 2 == 0, 1.0, -1.0) * zc
    pos = np.stack([np.full(order.shape, tx[0]), y, z], -1)
    idx = np.argsort(order, kind="stable")
    return pos[idx], order[idx]


def channel_paths(cfg: DriveConfig, position, velocity, tx) -> dict[str, np.ndarray]:
    """Paths of the image method at each epoch: delay [s], Doppler [Hz], complex amplitude.

    ``position``/``velocity`` (T, 2) horizontal; the receiving antenna is at ``rx_height``.
    Amplitude ``(-Gamma)^k lambda / (4 pi r) exp(-j 2 pi f_c tau)`` for ``k`` bounces.
    """
    src, order = image_sources(cfg, np.asarray(tx, dtype=float))
    p3 = np.concatenate([position, np.full((len(position), 1), cfg.rx_height)], -1)
    v3 = np.concatenate([velocity, np.zeros((len(velocity), 1))], -1)
    w = p3[:, None, :] - src[None, :, :]
    r = np.linalg.norm(w, axis=-1)
    doppler = -(cfg.fc / C) * np.einsum("tk,tpk->tp", v3, w) / r
    lam = C / cfg.fc
    amp = ((-cfg.reflection_coeff) ** order)[None, :] * lam / (4 * np.pi * r)
    phase = np.exp(-2j * np.pi * np.mod(cfg.fc * r / C, 1.0))
    return {"delay": r / C, "doppler": doppler, "amplitude": amp * phase, "order": order}


def _peak(grid: np.ndarray, mag: np.ndarray) -> np.ndarray:
    """Grid maximum of each row refined by a parabola through its neighbours."""
    k = np.clip(np.argmax(mag, axis=-1), 1, grid.shape[-1] - 2)
    rows = np.arange(mag.shape[0])
    a, b, c = mag[rows, k - 1], mag[rows, k], mag[rows, k + 1]
    den = a - 2 * b + c
    off = np.where(np.abs(den) > 1e-300, 0.5 * (a - c) / np.where(den == 0, 1, den), 0.0)
    step = grid[rows, 1] - grid[rows, 0]
    return grid[rows, k] + np.clip(off, -0.5, 0.5) * step


def _peak_observables(
    cfg: DriveConfig, paths: dict, chunk: int = 256
) -> tuple[np.ndarray, np.ndarray]:
    """Noise-free peak delay and peak Doppler of the multipath channel (the multipath bias)."""
    tau, fd, a = paths["delay"], paths["doppler"], paths["amplitude"]
    T = tau.shape[0]
    toa = np.empty(T)
    dop = np.empty(T)
    res_t, res_f = cfg.delay_resolution, cfg.doppler_resolution
    ut = np.linspace(-2.0, 4.0, 241)  # delay grid in units of 1/B around the line of sight
    uf = np.linspace(-1.5, 1.5, 121)  # Doppler grid in units of the resolution around the LoS
    window = cfg.window_snapshots * cfg.snapshot_period
    for s in range(0, T, chunk):
        sl = slice(s, min(s + chunk, T))
        g_t = tau[sl, :1] + ut[None, :] * res_t
        cir = np.einsum(
            "tp,tgp->tg", a[sl], np.sinc(cfg.bandwidth * (g_t[:, :, None] - tau[sl, None, :]))
        )
        toa[sl] = _peak(g_t, np.abs(cir))
        g_f = fd[sl, :1] + uf[None, :] * res_f
        spec = np.einsum("tp,tgp->tg", a[sl], np.sinc(window * (g_f[:, :, None] - fd[sl, None, :])))
        dop[sl] = _peak(g_f, np.abs(spec))
    return toa, dop


def _config_key(cfg: DriveConfig) -> tuple:
    return dataclasses.astuple(cfg)


@functools.lru_cache(maxsize=16)
def _make_drive_cached(key: tuple) -> Drive:
    cfg = DriveConfig(*key)
    n = int(np.floor(cfg.duration / cfg.dt + 1e-9)) + 1
    t = np.arange(n) * cfg.dt
    s, v = _speed_profile(cfg, t)
    s_pass, _ = _speed_profile(cfg, np.array([cfg.pass_time]))
    pos = np.stack([s, np.full(n, cfg.lane_y)], -1)
    vel = np.stack([v, np.zeros(n)], -1)
    tx = np.array([float(s_pass[0]), cfg.tx_y, cfg.tx_z])
    dz = cfg.tx_z - cfg.rx_height
    rng_ = slant_range(pos, tx[:2], dz)
    paths = channel_paths(cfg, pos, vel, tx)
    toa_pk, dop_pk = _peak_observables(cfg, paths)
    for arr in (pos, vel, t, rng_, toa_pk, dop_pk, tx):
        arr.setflags(write=False)
    los = doppler_shift(pos, vel, tx[:2], cfg.fc, dz)
    toa_los = rng_ / C
    los.setflags(write=False)
    toa_los.setflags(write=False)
    return Drive(
        config=cfg,
        trajectory=Trajectory(t=t, position=pos, velocity=vel),
        tx=tx,
        range=rng_,
        doppler_los=los,
        toa_los=toa_los,
        doppler_peak=dop_pk,
        toa_peak=toa_pk,
    )


#: Field changes that switch every random error and clock effect off (ideal measurements):
#: ``make_drive(**IDEAL)``; multipath and the speed variation stay as configured.
IDEAL = {
    "doppler_noise_hz": 0.0,
    "toa_noise_s": 0.0,
    "doppler_bias_hz": 0.0,
    "toa_bias_m": 0.0,
    "outlier_prob": 0.0,
    "clock_offset_s": 0.0,
    "clock_drift": 0.0,
    "cfo_hz": 0.0,
    "cfo_walk_hz": 0.0,
}


def make_drive(config: DriveConfig | None = None, **changes) -> Drive:
    """The noise-free drive for ``config`` (defaults: the paper's setup) with optional field changes.

    Deterministic and cached: the same configuration returns the same object.
    """
    cfg = DriveConfig() if config is None else config
    if not isinstance(cfg, DriveConfig):
        raise TypeError(f"config: expected a DriveConfig, got {type(cfg).__name__}")
    if changes:
        cfg = cfg.replace(**changes)
    return _make_drive_cached(_config_key(cfg))


def _gauss_markov(rng: np.random.Generator, n: int, sigma: float, rho: float) -> np.ndarray:
    """Stationary first-order Gauss-Markov sequence: std ``sigma``, lag-one correlation ``rho``.

    ``x_0 = w_0``, ``x_k = rho x_{k-1} + sqrt(1 - rho^2) w_k`` with white ``w`` (one draw per epoch
    even when ``sigma`` is zero, so switching a term off does not shift the other streams).
    """
    w = rng.standard_normal(n)
    if sigma == 0:
        return np.zeros(n)
    tail = lfilter([np.sqrt(1 - rho**2)], [1, -rho], w[1:], zi=[rho * w[0]])[0]
    return sigma * np.concatenate([w[:1], tail])


def measure(drive: Drive, rng: np.random.Generator) -> Measurements:
    """One noisy realisation of the Doppler and ToA streams (model in the module docstring)."""
    if not isinstance(drive, Drive):
        raise TypeError(
            f"drive: expected a Drive (tunnelkit.drive.make_drive()), got {type(drive).__name__}"
        )
    rng = rng_or_error("rng", rng)
    cfg = drive.config
    n = len(drive.t)
    scale = np.sqrt(1 + (drive.range / cfg.noise_ref_range) ** 2)
    rho = float(np.exp(-cfg.spacing / cfg.bias_corr_m))
    white_d = cfg.doppler_noise_hz * scale * rng.standard_normal(n)
    bias_d = _gauss_markov(rng, n, cfg.doppler_bias_hz, rho)
    cfo = cfg.cfo_hz + np.concatenate(
        [[0.0], np.cumsum(cfg.cfo_walk_hz * np.sqrt(cfg.dt) * rng.standard_normal(n - 1))]
    )
    outlier = rng.random(n) < cfg.outlier_prob
    span = 1.2 * cfg.fc / C * (cfg.speed + cfg.speed_amplitude)
    doppler = drive.doppler_peak + cfo + bias_d + white_d
    doppler = np.where(outlier, rng.uniform(-span, span, n), doppler)
    white_t = cfg.toa_noise_s * scale * rng.standard_normal(n)
    nlos = np.abs(_gauss_markov(rng, n, cfg.toa_bias_m, rho)) / C
    clock = cfg.clock_offset_s + cfg.clock_drift * drive.t
    toa = drive.toa_peak + nlos + clock + white_t
    dropped = rng.random(n) < cfg.drop_prob
    doppler = np.where(dropped, np.nan, doppler)
    toa = np.where(dropped, np.nan, toa)
    parts = {
        "doppler_multipath": drive.doppler_peak - drive.doppler_los,
        "doppler_bias": bias_d,
        "doppler_white": white_d,
        "cfo": cfo,
        "toa_multipath": drive.toa_peak - drive.toa_los,
        "toa_nlos": nlos,
        "toa_white": white_t,
        "clock": clock,
    }
    return Measurements(
        t=drive.t,
        doppler=doppler,
        toa=toa,
        dropped=dropped,
        outlier=outlier & ~dropped,
        parts=parts,
    )


def gnss_fix(drive: Drive, rng: np.random.Generator) -> GnssFix:
    """The last GNSS fix at the first epoch: truth plus Gaussian errors of ``gnss_sigma_m/v``."""
    if not isinstance(drive, Drive):
        raise TypeError(f"drive: expected a Drive, got {type(drive).__name__}")
    rng = rng_or_error("rng", rng)
    cfg = drive.config
    sp = max(cfg.gnss_sigma_m, 1e-3)
    sv = max(cfg.gnss_sigma_v, 1e-3)
    p = drive.position[0] + cfg.gnss_sigma_m * rng.standard_normal(2)
    v = drive.velocity[0] + cfg.gnss_sigma_v * rng.standard_normal(2)
    return GnssFix(position=p, velocity=v, sigma_p=sp, sigma_v=sv)


def delay_doppler_profiles(
    drive: Drive, *, every: int = 8, doppler_span: float = 160.0, n_bins: int = 241
) -> dict[str, np.ndarray]:
    """Synthetic power-delay and Doppler power profiles over the drive (the paper's Fig. 2).

    Incoherent sums of the image-method paths smeared by the delay (1/B) and Doppler
    (window) resolutions, in dB relative to the strongest cell. Every ``every``-th epoch.
    """
    cfg = drive.config
    idx = np.arange(0, len(drive.t), int(every))
    paths = channel_paths(cfg, drive.position[idx], drive.velocity[idx], drive.tx)
    pw = np.abs(paths["amplitude"]) ** 2
    delays = np.linspace(0, 1.1 * float(paths["delay"].max()), n_bins)
    dops = np.linspace(-doppler_span, doppler_span, n_bins)
    # smear each path over max(resolution, bin width) so no path falls between bins
    wt = 1.0 / max(cfg.delay_resolution, delays[1] - delays[0])
    wf = 1.0 / max(cfg.doppler_resolution, dops[1] - dops[0])
    pdp = np.einsum(
        "tp,tgp->tg", pw, np.sinc(wt * (delays[None, :, None] - paths["delay"][:, None, :])) ** 2
    )
    dpp = np.einsum(
        "tp,tgp->tg", pw, np.sinc(wf * (dops[None, :, None] - paths["doppler"][:, None, :])) ** 2
    )

    def db(x):
        return 10 * np.log10(np.maximum(x / x.max(), 1e-6))

    return {
        "t": drive.t[idx],
        "delay": delays,
        "doppler": dops,
        "pdp_db": db(pdp),
        "dpp_db": db(dpp),
    }


_SECTIONS = ("tube", "transmitter", "vehicle", "radio", "multipath", "errors", "clock", "gnss")


def load_drive_config(name: str = "halili2022-drive") -> DriveConfig:
    """A :class:`DriveConfig` from a scenario preset's plain sections (``data/scenarios/<name>.toml``).

    Every key of ``[tube]``, ``[transmitter]``, ``[vehicle]``, ``[radio]``, ``[multipath]``,
    ``[errors]``, ``[clock]`` and ``[gnss]`` must be a :class:`DriveConfig` field; unknown keys are
    errors naming the key.
    """
    sc = load_scenario(name)
    if sc.family != "halili2022":
        raise ScenarioError(
            f"name: {sc.name!r} is a {sc.family!r} scenario, not a Halili drive; "
            'load_drive_config reads paper = "halili2022" files ([tube], [transmitter], ...)'
        )
    fields = {f.name: f for f in dataclasses.fields(DriveConfig)}
    kw = {}
    for sec in _SECTIONS:
        table = sc.sections.get(sec, {})
        if not isinstance(table, dict):
            raise ScenarioError(f"{sc.path.name}: [{sec}] must be a table")
        for key in table:
            if key not in fields:
                raise ScenarioError(
                    f"{sc.path.name}: unknown key '{sec}.{key}'; known: {sorted(fields)}"
                )
            kind = int if fields[key].type in ("int", int) else float
            kw[key] = sc.get(f"{sec}.{key}", kind)
    try:
        return DriveConfig(**kw)
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"{sc.path.name}: {exc}") from None


@register_check("halili2022")
def _check_tube(sc: Scenario) -> None:
    """Transmitter and vehicle inside the tube, every value a valid :class:`DriveConfig` field
    and a drive of at most ``MAX_SAMPLES`` epochs (run on load of a ``halili2022`` file)."""
    where, sec = sc.path.name, sc.sections
    w, h = sec["tube"]["width"], sec["tube"]["height"]
    for key, val, lim in (
        ("transmitter.tx_y", sec["transmitter"]["tx_y"], w / 2),
        ("vehicle.lane_y", sec["vehicle"]["lane_y"], w / 2),
    ):
        if not abs(val) < lim:
            raise ScenarioError(
                f"{where}: '{key}' = {val:g} m lies outside the {w:g} m wide tube (|y| < {lim:g})"
            )
    for key, val in (
        ("transmitter.tx_z", sec["transmitter"]["tx_z"]),
        ("vehicle.rx_height", sec["vehicle"]["rx_height"]),
    ):
        if not 0 < val < h:
            raise ScenarioError(
                f"{where}: '{key}' = {val:g} m lies outside the {h:g} m high tube (0 < z < {h:g})"
            )
    owner = {k: name for name, tab in sec.items() if isinstance(tab, dict) for k in tab}
    try:
        DriveConfig(**{k: sec[s][k] for k, s in owner.items()})
    except ValueError as exc:
        field_name, _, msg = str(exc).partition(":")
        key = f"{owner.get(field_name, '?')}.{field_name}"
        raise ScenarioError(f"{where}: '{key}': {msg.strip()}") from None
    veh = sec["vehicle"]
    n = veh["speed"] * veh["duration"] / veh["spacing"]
    if n > MAX_SAMPLES:
        raise ScenarioError(
            f"{where}: 'vehicle.spacing' {veh['spacing']:g} m gives {n:.3g} samples over the "
            f"drive (speed x duration / spacing), more than {MAX_SAMPLES:g}"
        )
