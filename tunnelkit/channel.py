"""The 5G uplink SRS channel tensor of Italiano et al. (2026), eq. 1-10: synthesis only.

:func:`channel_tensor` follows eq. 1 exactly as printed, signs included (:class:`SRSConfig` the
radio); :func:`synthesize` adds the UE clock bias (:func:`sample_clock_bias`) and the noise of
section 4.2 (:func:`add_noise`). Three impairments eq. 1 leaves out, off by default: calibration
error (:func:`~tunnelkit.calibration.draw_calibration`), the spatial-wideband term
(``spatial_wideband=True``) and dense diffuse multipath (:class:`DiffuseSpec`); :class:`Impairments`
bundles them for the signal route.

How it works: docs/internals/channel-and-propagation.md.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._physical import carrier, power_dbm, subcarrier, tone_step
from ._validate import (
    choice,
    finite_array,
    integer,
    nonnegative,
    positive,
    real,
    rng_or_error,
)
from .budget import check_elements
from .constants import K_B, C, db2lin, dbm2watt

__all__ = [
    "ChannelSnapshot",
    "DiffuseSpec",
    "Impairments",
    "SRSConfig",
    "add_noise",
    "channel_tensor",
    "diffuse_tensor",
    "sample_clock_bias",
    "synthesize",
]

_MODELS = ("exact", "srnf")


@dataclass(frozen=True)
class SRSConfig:
    """Uplink SRS parameters (Italiano section 4.2 defaults).

    ``n_rb`` resource blocks of 12 subcarriers (273 for 100 MHz at 30 kHz, 3GPP TS 38.101-1);
    the SRS occupies one subcarrier in ``comb``, so ``n_tones = ceil(12 n_rb / comb)`` (410) spaced
    ``tone_spacing = comb * scs`` (240 kHz). ``symbol_period`` ``T0`` includes the normal cyclic
    prefix: ``(2048 + 144) / 2048 / scs`` (35.7 us at 30 kHz).
    """

    fc: float = 5.9e9
    bandwidth: float = 100e6
    scs: float = 30e3
    comb: int = 8
    n_symbols: int = 12
    tx_power_dbm: float = 23.0
    t_ant: float = 298.0
    noise_figure_db: float = 5.0
    n_rb: int = 273
    clock_bias_sigma: float = 50e-9
    clock_bias_limit: float = 100e-9

    def __post_init__(self) -> None:
        carrier("fc", self.fc)
        subcarrier("scs", self.scs)
        for k in ("bandwidth", "t_ant"):
            positive(k, getattr(self, k))
        if self.bandwidth >= 2 * self.fc:
            raise ValueError(
                f"bandwidth: {self.bandwidth:g} Hz around fc = {self.fc:g} Hz reaches 0 Hz (the band "
                "must lie inside (0, inf): bandwidth < 2 fc; both are in Hz)"
            )
        for k in ("clock_bias_sigma", "clock_bias_limit", "noise_figure_db"):
            nonnegative(k, getattr(self, k))
        power_dbm("tx_power_dbm", self.tx_power_dbm)
        integer("comb", self.comb, minimum=1)
        integer("n_symbols", self.n_symbols, minimum=2)
        integer("n_rb", self.n_rb, minimum=1)
        if self.n_tones < 2:
            raise ValueError(
                f"n_rb, comb: {self.n_rb} resource blocks of 12 subcarriers, one in {self.comb}, "
                f"give {self.n_tones} tone; a delay needs at least 2"
            )
        if 12 * self.n_rb * self.scs > self.bandwidth * 1.0001:
            raise ValueError(
                f"n_rb: {self.n_rb} RBs at {self.scs:g} Hz exceed the bandwidth {self.bandwidth:g} Hz"
            )
        # one antenna's tensor (complex, plus a noise draw of the same size) must fit
        check_elements(
            "n_symbols",
            2 * self.n_tones * self.n_symbols,
            itemsize=16,
            what=f"{self.n_tones} tones x {self.n_symbols} symbols per antenna",
        )

    @property
    def n_tones(self) -> int:
        """SRS tones ``Nf`` (subcarriers 0, comb, 2 comb, ...)."""
        return -(-12 * self.n_rb // self.comb)

    @property
    def tone_spacing(self) -> float:
        """Spacing of the SRS tones ``Delta f = comb * scs`` [Hz] (eq. 1, 5, 14)."""
        return self.comb * self.scs

    @property
    def symbol_period(self) -> float:
        """OFDM symbol period with normal cyclic prefix, ``T0`` [s] (eq. 1, 6, 15)."""
        return (2048 + 144) / 2048 / self.scs

    @property
    def tx_power(self) -> float:
        """Transmit power [W]."""
        return float(dbm2watt(self.tx_power_dbm))

    @property
    def noise_temperature(self) -> float:
        """``T_e = T_ant + 290 (NF - 1)`` [K]."""
        return self.t_ant + 290.0 * (float(db2lin(self.noise_figure_db)) - 1.0)

    @property
    def noise_power(self) -> float:
        """``N0 = k_B BW T_e`` [W], the variance of every noise sample (section 4.2)."""
        return K_B * self.bandwidth * self.noise_temperature

    @classmethod
    def from_scenario(cls, scenario) -> SRSConfig:
        """Read ``[radio]`` of a scenario (clock-bias keys in ns)."""
        if not (callable(getattr(scenario, "get", None)) and hasattr(scenario, "section")):
            raise TypeError(
                f"scenario: expected a loaded scenarios.Scenario (tk.load_scenario(name)), got "
                f"{type(scenario).__name__}"
            )
        g = scenario.get
        kw = {
            "fc": g("radio.fc"),
            "bandwidth": g("radio.bandwidth"),
            "scs": g("radio.scs"),
            "comb": g("radio.comb", int),
            "n_symbols": g("radio.n_symbols", int),
            "tx_power_dbm": g("radio.tx_power_dbm"),
            "t_ant": g("radio.t_ant"),
            "noise_figure_db": g("radio.noise_figure_db"),
            "clock_bias_sigma": 1e-9 * g("radio.clock_bias_sigma_ns", default=50.0),
            "clock_bias_limit": 1e-9 * g("radio.clock_bias_limit_ns", default=100.0),
        }
        if "n_rb" in scenario.section("radio"):
            kw["n_rb"] = g("radio.n_rb", int)
        return cls(**kw)


def check_clock_bias(value, config: SRSConfig) -> float:
    """A clock bias [s] the tensor can carry: within the radio's ``clock_bias_limit`` (or, with
    no limit, half the unambiguous delay ``1 / tone_spacing``: beyond it the phase ramp wraps and
    the tensor shows another bias than the one recorded)."""
    bias = float(finite_array("clock_bias", value, ndim=0))
    top = config.clock_bias_limit if config.clock_bias_limit > 0 else 0.5 / config.tone_spacing
    if abs(bias) > top * (1 + 1e-12):
        raise ValueError(
            f"clock_bias: {bias:g} s is beyond {top:g} s (the radio's clock_bias_limit, or half its "
            "unambiguous delay 1 / tone_spacing); a clock bias is given in seconds"
        )
    return bias


def sample_clock_bias(
    rng: np.random.Generator, sigma: float = 50e-9, limit: float = 100e-9, size: int | None = None
):
    """UE clock bias [s]: Gaussian ``N(0, sigma^2)`` truncated to ``[-limit, limit]`` (section 4.2)."""
    rng = rng_or_error("rng", rng)
    sigma, limit = nonnegative("sigma", sigma), nonnegative("limit", limit)
    n = 1 if size is None else integer("size", size, minimum=1)
    check_elements("size", 3 * n)
    if sigma == 0 or limit == 0:
        out = np.zeros(n)
    else:
        out = np.empty(0)
        while out.size < n:  # rejection sampling (acceptance >= 68 % for limit >= sigma)
            draw = rng.normal(0.0, sigma, size=2 * n + 4)
            out = np.concatenate([out, draw[np.abs(draw) <= limit]])
        out = out[:n]
    return float(out[0]) if size is None else out


@dataclass(frozen=True)
class DiffuseSpec:
    """Dense diffuse multipath (docs/internals): ``share`` in [0, 1) of the received power,
    exponential power-delay profile with time constant ``decay_s`` [s] (20 ns by default, a
    short concrete tunnel), taps ``oversample`` times finer than the delay resolution, ``span``
    time constants long."""

    share: float
    decay_s: float = 20e-9
    oversample: int = 4
    span: float = 10.0

    def __post_init__(self) -> None:
        share = nonnegative("share", self.share)
        if share >= 1.0:
            raise ValueError(f"share: the diffuse share must lie in [0, 1), got {share}")
        positive("decay_s", self.decay_s)
        integer("oversample", self.oversample, minimum=1)
        positive("span", self.span)

    def power(self, specular_power: float) -> float:
        """Diffuse power per tensor element [W] for a specular power ``specular_power``."""
        return self.share / (1.0 - self.share) * nonnegative("specular_power", specular_power)

    def taps(self, tone_spacing: float, n_tones: int) -> tuple[float, np.ndarray]:
        """The delay step ``dtau`` [s] and the tap weights ``w`` (P,) (sum 1) for a band of
        ``n_tones`` tones ``tone_spacing`` apart."""
        df = tone_step("tone_spacing", tone_spacing)
        nf = integer("n_tones", n_tones, minimum=1)
        n_fft = self.oversample * nf
        check_elements("n_tones", n_fft, what=f"the diffuse taps of {nf} tones")
        dtau = 1.0 / (n_fft * df)
        n_taps = int(min(max(np.ceil(self.span * self.decay_s / dtau), 1), n_fft))
        w = np.exp(-np.arange(n_taps) * dtau / self.decay_s)
        return dtau, w / w.sum()

    def tone_covariance(self, tone_spacing: float, n_tones: int, tau0: float = 0.0) -> np.ndarray:
        """``R_f`` (Nf, Nf) of a unit diffuse power starting at delay ``tau0`` [s] (closed form:
        the sum over taps)."""
        dtau, w = self.taps(tone_spacing, n_tones)
        tau = float(finite_array("tau0", tau0, ndim=0)) + dtau * np.arange(w.size)
        V = np.exp(-2j * np.pi * tone_spacing * np.arange(n_tones)[:, None] * tau[None, :])
        return (V * w) @ V.conj().T


def diffuse_tensor(
    spec: DiffuseSpec,
    shape,
    tone_spacing: float,
    tau0: float,
    specular_power: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """One realisation (M, Nf, Nt) of the dense diffuse multipath of ``spec`` (module
    docstring), starting at delay ``tau0`` [s], with diffuse power ``spec.power(specular_power)``
    per element; drawn from ``rng``."""
    if not isinstance(spec, DiffuseSpec):
        raise TypeError(f"spec: expected a channel.DiffuseSpec, got {type(spec).__name__}")
    rng = rng_or_error("rng", rng)
    m, nf, nt = (integer("shape", v, minimum=1) for v in shape)
    tau0 = float(finite_array("tau0", tau0, ndim=0))
    _, w = spec.taps(tone_spacing, nf)
    p = spec.power(specular_power)
    beta = (rng.standard_normal((m, w.size)) + 1j * rng.standard_normal((m, w.size))) * np.sqrt(
        p * w / 2
    )
    spec_f = np.fft.fft(beta, n=spec.oversample * nf, axis=1)[:, :nf]
    spec_f *= np.exp(-2j * np.pi * tone_spacing * tau0 * np.arange(nf))[None, :]
    return np.repeat(spec_f[:, :, None], nt, axis=2)


@dataclass(frozen=True)
class Impairments:
    """What a real array adds to eq. 1 (docs/internals): per-element calibration error with
    ``phase_sigma_deg`` [deg] and ``gain_sigma_db`` [dB], the ``spatial_wideband`` term and
    dense diffuse multipath ``dmc`` (a :class:`DiffuseSpec`, drawn per slot). All zero / False /
    None (the default) is eq. 1 exactly."""

    phase_sigma_deg: float = 0.0
    gain_sigma_db: float = 0.0
    spatial_wideband: bool = False
    dmc: DiffuseSpec | None = None

    def __post_init__(self) -> None:
        nonnegative("phase_sigma_deg", self.phase_sigma_deg)
        nonnegative("gain_sigma_db", self.gain_sigma_db)
        if not isinstance(self.spatial_wideband, bool):
            raise TypeError(
                f"spatial_wideband: expected True or False, got {self.spatial_wideband!r}"
            )
        if self.dmc is not None and not isinstance(self.dmc, DiffuseSpec):
            raise TypeError(f"dmc: expected a channel.DiffuseSpec or None, got {self.dmc!r}")

    @property
    def calibrated(self) -> bool:
        """True when there is no calibration error to draw."""
        return self.phase_sigma_deg == 0 and self.gain_sigma_db == 0

    def draw(self, rng: np.random.Generator, m: int) -> np.ndarray | None:
        """One array's calibration vector (:func:`~tunnelkit.calibration.draw_calibration`),
        ``None`` if calibrated."""
        from .calibration import draw_calibration  # loaded when a calibration error is drawn

        rng = rng_or_error("rng", rng)
        m = integer("m", m, minimum=1)
        if self.calibrated:
            return None
        return draw_calibration(rng, m, self.phase_sigma_deg, self.gain_sigma_db)


def check_calibration(calibration, m: int) -> np.ndarray | None:
    """``calibration`` as (M,) complex per-element gains, None if None (none applied)."""
    if calibration is None:
        return None
    g = np.asarray(calibration)
    if g.shape != (m,) or not np.all(np.isfinite(g)):
        raise ValueError(f"calibration: expected {m} finite complex gains, got shape {g.shape}")
    if np.any(g == 0):
        raise ValueError(
            "calibration: an element gain of zero (a dead element) is not a calibration error"
        )
    return g.astype(complex)


def _check_paths(paths) -> list:
    """``paths`` as a non-empty list of :class:`~tunnelkit.propagation.Path` for one array."""
    from .propagation import as_path_list

    paths = as_path_list(paths)
    m = paths[0].lengths.shape[0]
    for i, p in enumerate(paths):
        if p.lengths.shape[0] != m:
            raise ValueError(f"paths[{i}]: traced for {p.lengths.shape[0]} antennas, expected {m}")
    return paths


def channel_tensor(
    paths,
    config: SRSConfig,
    *,
    clock_bias: float = 0.0,
    model: str = "exact",
    n_tones: int | None = None,
    n_symbols: int | None = None,
    calibration=None,
    spatial_wideband: bool = False,
    dmc: DiffuseSpec | None = None,
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """The noiseless tensor ``H`` (M x Nf x Nt) of eq. 1 / eq. 3 for a list of paths.

    Amplitudes include ``sqrt(P_t)`` (so ``|H|^2`` is a received power in W). ``model`` is
    "exact" (spherical wavefront from the VUE, eq. 2) or "srnf" (from the reflection point).
    ``n_tones`` / ``n_symbols`` override the configuration (small tensors for tests and sliders).
    Impairments (docs/internals), off by default: ``calibration`` (M,) complex per-element
    gains (:func:`~tunnelkit.calibration.draw_calibration`); ``spatial_wideband`` the
    per-element delay ``tau_l + delta_lm / c`` in the frequency phase; ``dmc`` a :class:`DiffuseSpec` whose
    realisation (:func:`diffuse_tensor`, from ``rng``, starting at the first path's delay) is
    added (the tensor is then random, not noiseless).
    """
    if not isinstance(config, SRSConfig):
        raise TypeError(f"config: expected a channel.SRSConfig, got {type(config).__name__}")
    if model not in _MODELS:
        raise ValueError(f"model: expected one of {_MODELS}, got {model!r}")
    paths = _check_paths(paths)
    bias = check_clock_bias(clock_bias, config)
    if not isinstance(spatial_wideband, bool):
        raise TypeError(f"spatial_wideband: expected True or False, got {spatial_wideband!r}")
    cal = check_calibration(calibration, paths[0].lengths.shape[0])
    if dmc is not None:
        if not isinstance(dmc, DiffuseSpec):
            raise TypeError(f"dmc: expected a channel.DiffuseSpec, got {type(dmc).__name__}")
        if rng is None:
            raise ValueError("rng: diffuse multipath (dmc) is random; pass a numpy Generator")
        rng = rng_or_error("rng", rng)
    elif rng is not None:  # unused without dmc, but a wrong one is still an error
        rng = rng_or_error("rng", rng)
    nf = config.n_tones if n_tones is None else integer("n_tones", n_tones, minimum=2)
    nt = config.n_symbols if n_symbols is None else integer("n_symbols", n_symbols, minimum=2)
    m = paths[0].lengths.shape[0]
    check_elements("n_tones, n_symbols", 2 * m * nf * nt, 16, f"a {m} x {nf} x {nt} channel tensor")
    k0 = 2 * np.pi * config.fc / C
    delta = np.stack([p.delta(model) for p in paths], axis=1)  # (M, L)
    tau = (
        np.array([p.lengths[0] if model == "exact" else p.lengths_srnf[0] for p in paths]) / C
        + bias
    )
    fd = np.array([p.doppler for p in paths])
    alpha = np.sqrt(config.tx_power) * np.array([p.gain for p in paths])
    bs = np.exp(1j * k0 * delta)
    bt = np.exp(2j * np.pi * config.symbol_period * np.arange(nt)[:, None] * fd[None, :])
    bf = np.exp(-2j * np.pi * config.tone_spacing * np.arange(nf)[:, None] * tau[None, :])
    if spatial_wideband:
        # element m's delay is tau_l + delta_lm / c; the carrier phase of delta_lm at fc (the
        # band centre) is eq. 1's spatial factor, the rest is its phase at f_s - fc
        fs = config.tone_spacing * (np.arange(nf) - 0.5 * (nf - 1))  # f_s - fc
        wb = np.exp(-2j * np.pi * fs[None, :, None] * delta[:, None, :] / C)  # (M, Nf, L)
        bsf = (bs * alpha)[:, None, :] * bf[None, :, :] * wb
        H = np.einsum("msl,kl->msk", bsf, bt, optimize=True)
    else:
        H = np.einsum("ml,sl,kl->msk", bs * alpha, bf, bt, optimize=True)
    if dmc is not None and dmc.share > 0:
        p_spec = float(np.sum(np.abs(alpha) ** 2))
        H = H + diffuse_tensor(dmc, H.shape, config.tone_spacing, float(tau.min()), p_spec, rng)
    return H if cal is None else cal[:, None, None] * H


def add_noise(H, noise_power: float, rng: np.random.Generator) -> np.ndarray:
    """``H + Z`` with ``Z ~ CN(0, noise_power)`` i.i.d. (eq. 7-10 with a unit-modulus pilot)."""
    H = np.asarray(H)
    if H.ndim != 3 or not np.all(np.isfinite(H)):
        raise ValueError(f"H: expected a finite 3-D tensor, got shape {H.shape}")
    rng = rng_or_error("rng", rng)
    s = np.sqrt(nonnegative("noise_power", noise_power) / 2)
    return H + s * (rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape))


@dataclass(frozen=True)
class ChannelSnapshot:
    """One received SRS slot: noisy tensor ``H`` and what produced it."""

    H: np.ndarray = field(repr=False)
    noise_power: float
    clock_bias: float
    model: str
    paths: tuple = field(repr=False)
    config: SRSConfig = field(repr=False)

    def __post_init__(self) -> None:
        H = self.H
        if not isinstance(H, np.ndarray) or H.dtype.kind != "c":
            raise TypeError(
                f"H: expected a complex channel tensor (numpy array), got {type(H).__name__}"
                + (f" of {H.dtype}" if isinstance(H, np.ndarray) else "")
            )
        if H.ndim != 3:
            raise ValueError(f"H: expected a 3-D tensor (M x Nf x Nt), got shape {H.shape}")
        if not np.isfinite(H).all():
            raise ValueError("H: contains NaN or infinite values")
        positive("noise_power", self.noise_power)
        real("clock_bias", self.clock_bias)
        choice("model", self.model, _MODELS)
        if not isinstance(self.paths, tuple):
            raise TypeError(f"paths: expected a tuple of paths, got {type(self.paths).__name__}")
        if not isinstance(self.config, SRSConfig):
            raise TypeError(f"config: expected an SRSConfig, got {type(self.config).__name__}")

    @property
    def snr_db(self) -> np.ndarray:
        """Per-element SNR of each path ``P_t |alpha|^2 / N0`` [dB]."""
        g = np.array([abs(p.gain) ** 2 for p in self.paths]) * self.config.tx_power
        return 10 * np.log10(g / self.noise_power)


def synthesize(
    paths,
    config: SRSConfig,
    rng: np.random.Generator,
    *,
    model: str = "exact",
    clock_bias: float | None = None,
    snr_offset_db: float = 0.0,
    n_tones: int | None = None,
    n_symbols: int | None = None,
    calibration=None,
    spatial_wideband: bool = False,
    dmc: DiffuseSpec | None = None,
) -> ChannelSnapshot:
    """Noisy tensor for ``paths``: eq. 1 + CN(0, N0) noise, clock bias drawn from ``rng`` if None.

    ``snr_offset_db`` raises (positive) or lowers the SNR by scaling the noise power.
    ``calibration`` / ``spatial_wideband`` / ``dmc``: the impairments of :func:`channel_tensor`
    (off by default; the calibration vector is not drawn here, it belongs to the array; the
    diffuse multipath is drawn from ``rng`` after the clock bias and before the noise).
    """
    rng = rng_or_error("rng", rng)
    off = float(finite_array("snr_offset_db", snr_offset_db, ndim=0))
    if clock_bias is None:
        clock_bias = sample_clock_bias(rng, config.clock_bias_sigma, config.clock_bias_limit)
    H = channel_tensor(
        paths,
        config,
        clock_bias=clock_bias,
        model=model,
        n_tones=n_tones,
        n_symbols=n_symbols,
        calibration=calibration,
        spatial_wideband=spatial_wideband,
        dmc=dmc,
        rng=rng,
    )
    n0 = config.noise_power / float(db2lin(off))
    return ChannelSnapshot(
        add_noise(H, n0, rng), n0, float(clock_bias), model, tuple(paths), config
    )
