"""The noise-free drive: the route at a gently varying speed, the line-of-sight range and Doppler,
the image-method channel of the rectangular tube and the peaks an ideal estimator finds in it
(the multipath bias), and the power-delay and Doppler profiles over the drive."""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field

import numpy as np

from .._physical import carrier, speeds
from .._validate import finite_array, instance, integer, positive, real, record, vector
from ..budget import check_elements
from ..constants import C
from ..scenarios import Trajectory
from .config import DriveConfig

__all__ = [
    "Drive",
    "channel_paths",
    "delay_doppler_profiles",
    "doppler_shift",
    "image_sources",
    "make_drive",
    "slant_range",
]


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

    def __post_init__(self) -> None:
        T = ("T",)
        record(self, shapes={"tx": (3,), "range": T, "doppler_los": T, "toa_los": T,
                             "doppler_peak": T, "toa_peak": T},
               nonnegative=("range", "toa_los"))  # fmt: skip

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
    fc, dz, tx = carrier("fc", fc), real("dz", dz), finite_array("tx", tx, shape=(2,))
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
    instance("cfg", cfg, DriveConfig)
    tx = vector("tx", tx, 3)
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
    instance("cfg", cfg, DriveConfig)
    tx = vector("tx", tx, 3)
    position = finite_array("position", position, shape=(None, 2))
    velocity = speeds("velocity", finite_array("velocity", velocity, shape=(len(position), 2)))
    src, order = image_sources(cfg, tx)
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


def delay_doppler_profiles(
    drive: Drive, *, every: int = 8, doppler_span: float = 160.0, n_bins: int = 241
) -> dict[str, np.ndarray]:
    """Synthetic power-delay and Doppler power profiles over the drive (the paper's Fig. 2).

    Incoherent sums of the image-method paths smeared by the delay (1/B) and Doppler
    (window) resolutions, in dB relative to the strongest cell. Every ``every``-th epoch.
    """
    cfg = instance("drive", drive, Drive).config
    every, n_bins = integer("every", every, minimum=1), integer("n_bins", n_bins, minimum=2)
    doppler_span = positive("doppler_span", doppler_span)
    idx = np.arange(0, len(drive.t), every)
    paths = channel_paths(cfg, drive.position[idx], drive.velocity[idx], drive.tx)
    n_paths = paths["delay"].shape[-1]
    check_elements(
        "n_bins",
        idx.size * n_bins * n_paths,
        what=f"{idx.size} epochs x {n_bins} bins x {n_paths} paths",
    )
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
