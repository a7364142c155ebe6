"""Measurements of the drive: one noisy realisation of the Doppler and ToA streams (white noise
growing with range, slowly varying biases, outliers, dropped epochs, clock errors; the model is
in the package docstring) and the last GNSS fix at the tunnel entrance."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.signal import lfilter

from .._physical import speeds
from .._validate import finite_array, positive, record, rng_or_error
from ..constants import C
from .drive import Drive

__all__ = ["DopplerToaMeasurements", "GnssFix", "gnss_fix", "measure"]


@dataclass(frozen=True)
class DopplerToaMeasurements:
    """One noisy realisation: Doppler [Hz] and ToA [s] per epoch; dropped epochs are NaN in both
    (Halili's one-path scalar series over a whole drive, not JAVELIN's per-epoch paths,
    :class:`tunnelkit.tracking.javelin.PathMeasurements`).

    ``dropped`` marks them explicitly; ``outlier`` marks Doppler samples that locked on a moving
    scatterer; ``parts`` holds each error term for teaching plots.
    """

    t: np.ndarray
    doppler: np.ndarray
    toa: np.ndarray
    dropped: np.ndarray
    outlier: np.ndarray
    parts: dict[str, np.ndarray] = field(repr=False)

    def __post_init__(self) -> None:  # dropped epochs are NaN in doppler and toa
        T = ("T",)
        record(self, shapes={"t": T, "doppler": T, "toa": T, "dropped": T, "outlier": T},
               allow_nan=("doppler", "toa"))  # fmt: skip


@dataclass(frozen=True)
class GnssFix:
    """Last GNSS fix at the tunnel entrance: position and velocity with their standard deviations."""

    position: np.ndarray
    velocity: np.ndarray
    sigma_p: float
    sigma_v: float

    def __post_init__(self) -> None:
        finite_array("position", self.position, shape=(2,))
        v = speeds("velocity", finite_array("velocity", self.velocity, shape=(2,)))
        positive("sigma_p", self.sigma_p)
        positive("sigma_v", self.sigma_v)
        if np.linalg.norm(v) < 1e-6:
            raise ValueError("velocity: the GNSS speed is zero, so the heading is undefined")

    @property
    def covariance(self) -> np.ndarray:
        """Prior covariance of the state ``[x, y, v_x, v_y]`` (P_0 of Halili sec. 4)."""
        return np.diag([self.sigma_p**2, self.sigma_p**2, self.sigma_v**2, self.sigma_v**2])


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


def measure(drive: Drive, rng: np.random.Generator) -> DopplerToaMeasurements:
    """One noisy realisation of the Doppler and ToA streams (model in the module docstring)."""
    if not isinstance(drive, Drive):
        raise TypeError(
            f"drive: expected a Drive (tunnelkit.doppler_drive.make_drive()), got {type(drive).__name__}"
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
    return DopplerToaMeasurements(
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
