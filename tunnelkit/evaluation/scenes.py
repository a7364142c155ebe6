"""A free-space test scene in front of one array (:class:`Scene`) and a random one
(:func:`random_scene`): point sources with their gains, delays and speeds, the eq. 1 tensor they
make and its CRLB, for the extraction's tests and benchmarks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._domains import interval
from .._physical import speeds as check_speeds
from .._validate import instance, integer, nonnegative, real, record, rng_or_error
from ..arrays import check_element_positions, ura
from ..budget import check_elements
from ..channel import SRSConfig, add_noise
from ..constants import C, wavelength
from ..extraction.bounds import in_path_units, source_crlb
from ..extraction.coherent import spherical_steering

__all__ = ["Scene", "random_scene"]


@dataclass(frozen=True)
class Scene:
    """A free-space scene in front of one array: point sources (wave origins) in the local
    frame, their gains (incl. ``sqrt(P_t)``), delay-distances ``d`` [m] and speeds ``v`` [m/s];
    the radio of ``config`` (tones, symbols, noise power)."""

    sources: np.ndarray
    alpha: np.ndarray
    d: np.ndarray
    v: np.ndarray
    element_positions: np.ndarray
    config: object

    def __post_init__(self) -> None:
        shapes = {
            "sources": ("L", 3),
            "alpha": ("L",),
            "d": ("L",),
            "v": ("L",),
            "element_positions": (None, 3),
        }
        record(self, shapes=shapes, positive=("d",))
        instance("config", self.config, SRSConfig)

    @property
    def mu_f(self) -> np.ndarray:
        return -2 * np.pi * self.config.tone_spacing * self.d / C

    @property
    def mu_t(self) -> np.ndarray:
        return 2 * np.pi * self.config.fc * self.config.symbol_period * self.v / C

    def tensor(self, rng: np.random.Generator | None = None) -> np.ndarray:
        """Eq. 1 for the sources, plus ``CN(0, noise_power)`` noise when ``rng`` is given."""

        cfg = self.config
        a = spherical_steering(self.sources, self.element_positions, cfg.fc)
        f = np.exp(1j * np.arange(cfg.n_tones)[:, None] * self.mu_f[None, :])
        t = np.exp(1j * np.arange(cfg.n_symbols)[:, None] * self.mu_t[None, :])
        H = np.einsum("ml,sl,kl->msk", a * self.alpha[None, :], f, t, optimize=True)
        return H if rng is None else add_noise(H, cfg.noise_power, rng)

    def crlb(self, spatial: str = "structured") -> dict:
        """Standard deviations ``d`` [m], ``v`` [m/s], ``direction`` [rad], ``kappa`` [m]."""

        cfg = self.config
        b = source_crlb(
            self.alpha,
            self.sources,
            self.element_positions,
            self.mu_f,
            self.mu_t,
            cfg.fc,
            cfg.n_tones,
            cfg.n_symbols,
            cfg.noise_power,
            spatial=spatial,
        )
        return in_path_units(b, cfg)


def random_scene(
    rng: np.random.Generator,
    n_paths: int = 3,
    *,
    element_positions=None,
    config=None,
    ranges=(2.0, 8.0),
    max_sine: float = 0.8,
    snr_db=(-10.0, 10.0),
    spread_d: float = 30.0,
    speeds=(-20.0, 20.0),
) -> Scene:
    """Random near-field scene: ``n_paths`` sources at ``ranges`` [m] from the reference antenna
    of a 10 x 10 half-wavelength URA (default), directions with ``|u_xy| < max_sine``, per-sample
    SNR uniform in ``snr_db`` (the noise power of ``config``, default :class:`SRSConfig`), delay
    distances ``range + U(0, spread_d)`` (a clock bias and extra path length), speeds uniform."""
    rng = rng_or_error("rng", rng)
    L = integer("n_paths", n_paths, minimum=1)
    check_elements("n_paths", 16 * L, what=f"{L} paths' parameters")
    cfg = SRSConfig() if config is None else instance("config", config, SRSConfig)
    ranges = interval("ranges", ranges, lower=1e-3)
    max_sine = real("max_sine", max_sine)
    if not 0 < max_sine <= 1:
        raise ValueError(f"max_sine: must lie in (0, 1], got {max_sine}")
    snr_db = interval("snr_db", snr_db)
    spread_d = nonnegative("spread_d", spread_d)
    speeds = tuple(check_speeds("speeds", interval("speeds", speeds), vectors=False))
    pos = ura(10, 10, wavelength(cfg.fc) / 2) if element_positions is None else element_positions
    if element_positions is not None:
        pos = check_element_positions("element_positions", element_positions)
    pos = np.asarray(pos, float)
    r = rng.uniform(*ranges, L)
    rad = max_sine * np.sqrt(rng.uniform(0, 1, L))
    ang = rng.uniform(0, 2 * np.pi, L)
    u = np.column_stack([rad * np.cos(ang), rad * np.sin(ang), np.sqrt(1 - rad**2)])
    amp = np.sqrt(cfg.noise_power * 10 ** (rng.uniform(*snr_db, L) / 10))
    alpha = amp * np.exp(2j * np.pi * rng.uniform(0, 1, L))
    d = r + rng.uniform(0, spread_d, L)
    v = rng.uniform(*speeds, L)
    return Scene(u * r[:, None], alpha, d, v, pos, cfg)
