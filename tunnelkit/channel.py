"""The 5G uplink SRS channel tensor of Italiano et al. (2026), eq. 1-10, and the signal route.

**The whole signal route in one line** (scenario + epoch -> paths -> noisy tensor -> CPD ->
Algorithm 1 measurements)::

    import numpy as np, tunnelkit as tk
    from tunnelkit import channel
    route = channel.SignalRoute.from_scenario("italiano2026-straight")   # build once
    ep = route.epoch(k=10, rng=np.random.default_rng(0))                  # one SRS slot
    ep.measurements.z            # eq. 54: [phi; psi; kappa; Delta d] of the kept paths
    ep.measurements.origin       # world position of the array's reference antenna
    ep.paths                     # ground truth (tunnelkit.propagation.Path list)

or ``channel.simulate_epoch("italiano2026-straight", 10, rng)`` for a single call. Angles in
``ep.measurements`` are world-frame azimuth/elevation (eq. 46-47, 49-50) seen from ``origin``.

The tensor follows eq. 1 exactly as printed, signs included::

    H[m, s, k] = sqrt(P_t) sum_l alpha_l exp(+j 2 pi fc/c delta_lm) exp(-j 2 pi s Df tau_l)
                 exp(+j 2 pi k f_d,l T0)

with ``s`` the SRS tone index (tone spacing ``Df = comb * scs``), ``k`` the symbol index,
``T0`` the OFDM symbol period (cyclic prefix included) and ``tau_l = d_l / c + b`` where ``b`` is
the UE clock bias (truncated Gaussian, section 4.2). Noise is ``CN(0, N0)`` per element with
``N0 = k_B BW T_e``, ``T_e = T_ant + 290 (NF - 1)`` (section 4.2, taken literally: the noise of the
whole band on every tensor element). ``model="srnf"`` synthesises the SR-NF channel (wavefront
centred on the reflection point) instead of the exact physics (centred on the VUE).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._validate import finite_array, integer, nonnegative, positive, real, rng_or_error
from .arrays import ArrayGeometry
from .budget import check_elements
from .constants import K_B, C, db2lin, dbm2watt

__all__ = [
    "ChannelSnapshot",
    "Epoch",
    "Measurements",
    "SRSConfig",
    "SignalRoute",
    "add_noise",
    "channel_tensor",
    "comparison_rows",
    "match_paths",
    "path_crlb",
    "path_rows",
    "rmse_study",
    "sample_clock_bias",
    "simulate_epoch",
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
        for k in ("fc", "bandwidth", "scs", "t_ant"):
            positive(k, getattr(self, k))
        for k in ("clock_bias_sigma", "clock_bias_limit", "noise_figure_db"):
            nonnegative(k, getattr(self, k))
        real("tx_power_dbm", self.tx_power_dbm)
        integer("comb", self.comb, minimum=1)
        integer("n_symbols", self.n_symbols, minimum=2)
        integer("n_rb", self.n_rb, minimum=1)
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


def _check_paths(paths) -> list:
    """``paths`` as a non-empty list of :class:`~tunnelkit.propagation.Path` for one array."""
    from .propagation import Path

    paths = list(paths)
    if not paths:
        raise ValueError("paths: need at least one path (the vehicle is fully blocked)")
    for i, p in enumerate(paths):
        if not isinstance(p, Path):
            raise TypeError(f"paths[{i}]: expected a propagation.Path, got {type(p).__name__}")
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
) -> np.ndarray:
    """The noiseless tensor ``H`` (M x Nf x Nt) of eq. 1 / eq. 3 for a list of paths.

    Amplitudes include ``sqrt(P_t)`` (so ``|H|^2`` is a received power in W). ``model`` is
    "exact" (spherical wavefront from the VUE, eq. 2) or "srnf" (from the reflection point).
    ``n_tones`` / ``n_symbols`` override the configuration (small tensors for tests and sliders).
    """
    if not isinstance(config, SRSConfig):
        raise TypeError(f"config: expected a channel.SRSConfig, got {type(config).__name__}")
    if model not in _MODELS:
        raise ValueError(f"model: expected one of {_MODELS}, got {model!r}")
    paths = _check_paths(paths)
    bias = float(finite_array("clock_bias", clock_bias, ndim=0))
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
    bf = np.exp(-2j * np.pi * config.tone_spacing * np.arange(nf)[:, None] * tau[None, :])
    bt = np.exp(2j * np.pi * config.symbol_period * np.arange(nt)[:, None] * fd[None, :])
    return np.einsum("ml,sl,kl->msk", bs * alpha, bf, bt, optimize=True)


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
) -> ChannelSnapshot:
    """Noisy tensor for ``paths``: eq. 1 + CN(0, N0) noise, clock bias drawn from ``rng`` if None.

    ``snr_offset_db`` raises (positive) or lowers the SNR by scaling the noise power.
    """
    rng = rng_or_error("rng", rng)
    off = float(finite_array("snr_offset_db", snr_offset_db, ndim=0))
    if clock_bias is None:
        clock_bias = sample_clock_bias(rng, config.clock_bias_sigma, config.clock_bias_limit)
    H = channel_tensor(
        paths, config, clock_bias=clock_bias, model=model, n_tones=n_tones, n_symbols=n_symbols
    )
    n0 = config.noise_power / float(db2lin(off))
    return ChannelSnapshot(
        add_noise(H, n0, rng), n0, float(clock_bias), model, tuple(paths), config
    )


# --- the whole route ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Measurements:
    """Algorithm 1 output for one array, angles in the **world** frame, seen from ``origin``.

    Per kept path (sorted by ``d``; path 0 is the earliest arrival): ``phi``/``psi`` azimuth and
    elevation (eq. 46-47), ``kappa`` (NaN when far-field), ``near_field``, ``d`` (biased distance),
    ``delta_d = d - d[0]`` (eq. 52, ``delta_d[0] = 0``), ``v`` (m/s), ``direction`` (K, 3) world unit
    vectors, ``alpha``. ``z`` is eq. 54, ``[phi; psi; kappa; delta_d[1:]]``. ``index`` maps each
    kept path to its row in the raw :class:`tunnelkit.extraction.PathEstimates`.
    """

    origin: np.ndarray
    array: str
    phi: np.ndarray
    psi: np.ndarray
    kappa: np.ndarray
    near_field: np.ndarray
    d: np.ndarray
    delta_d: np.ndarray
    v: np.ndarray
    direction: np.ndarray
    alpha: np.ndarray
    index: np.ndarray

    def __len__(self) -> int:
        return self.d.shape[0]

    @property
    def z(self) -> np.ndarray:
        """Eq. 54 stacked vector ``[phi; psi; kappa; delta_d[1:]]`` (kappa NaN for far-field)."""
        return np.concatenate([self.phi, self.psi, self.kappa, self.delta_d[1:]])

    @property
    def wave_origins(self) -> np.ndarray:
        """``origin + kappa * direction`` (K, 3), NaN rows for far-field paths (Fig. 5)."""
        return self.origin + self.kappa[:, None] * self.direction


@dataclass(frozen=True)
class Epoch:
    """Everything about one simulated epoch (truth, tensor, raw estimates, measurements)."""

    k: int
    t: float
    ue: np.ndarray
    velocity: np.ndarray
    array: ArrayGeometry = field(repr=False)
    paths: list = field(repr=False)
    snapshot: ChannelSnapshot = field(repr=False)
    estimates: object = field(repr=False)
    measurements: Measurements
    truth_index: np.ndarray  # for each kept measurement, the index of the true path (-1 if none)


def measurements_from_estimates(est, array: ArrayGeometry) -> Measurements:
    """Apply Algorithm 1's checks to raw estimates and express them in the world frame."""
    from .extraction import algorithm1

    keep = algorithm1(est)
    u = array.dir_to_world(est.direction[keep]) if keep.size else np.zeros((0, 3))
    phi = np.arctan2(u[:, 1], u[:, 0])
    psi = np.arctan2(u[:, 2], np.hypot(u[:, 0], u[:, 1]))
    d = est.d[keep]
    return Measurements(
        array.origin.copy(),
        array.name,
        phi,
        psi,
        est.kappa[keep],
        est.near_field[keep],
        d,
        d - d[0] if d.size else d,
        est.v[keep],
        u,
        est.alpha[keep],
        keep,
    )


def match_paths(
    d_est,
    dir_est,
    paths,
    *,
    clock_bias: float = 0.0,
    direction_scale: float = 0.1,
    range_scale: float = 1.0,
) -> np.ndarray:
    """Assign estimates to true paths (Hungarian on range and direction); -1 where unmatched.

    Cost: ``|d_est - (length + c b)| / range_scale + ||u_est - u_true|| / direction_scale``;
    assignments costing more than 10 are refused.
    """
    from scipy.optimize import linear_sum_assignment

    d_est = np.atleast_1d(np.asarray(d_est, float))
    out = -np.ones(d_est.shape[0], dtype=int)
    if not len(paths) or not d_est.size:
        return out
    d_true = np.array([p.length for p in paths]) + C * clock_bias
    u_true = np.stack([p.direction for p in paths])
    cost = (
        np.abs(d_est[:, None] - d_true[None, :]) / range_scale
        + np.linalg.norm(np.asarray(dir_est)[:, None, :] - u_true[None], axis=-1) / direction_scale
    )
    r, c = linear_sum_assignment(cost)
    ok = cost[r, c] < 10.0
    out[r[ok]] = c[ok]
    return out


@dataclass
class SignalRoute:
    """Scenario objects built once; :meth:`epoch` runs propagation -> channel -> extraction.

    ``kinds`` selects path families (see :func:`tunnelkit.propagation.trace_paths`);
    ``n_paths=None`` means L known (the number of traced paths, as in the paper).
    """

    tunnel: object
    arrays: list
    trajectory: object
    config: SRSConfig
    model: str = "exact"
    kinds: tuple[str, ...] = ("los", "wall", "ceiling", "road", "rrm")
    snr_offset_db: float = 0.0

    @classmethod
    def from_scenario(cls, scenario, **kw) -> SignalRoute:
        """Build from a scenario name or a loaded :class:`tunnelkit.scenarios.Scenario`."""
        from . import propagation
        from .scenarios import Scenario, load_scenario

        sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
        if not isinstance(sc, Scenario):
            raise TypeError(
                f"scenario: expected a name or a Scenario, got {type(scenario).__name__}"
            )
        tun = sc.tunnel()
        return cls(
            tun,
            propagation.scenario_arrays(sc),
            sc.trajectory(tun),
            SRSConfig.from_scenario(sc),
            **kw,
        )

    def paths(self, k: int, tunnel=None) -> tuple[ArrayGeometry, list]:
        """The array facing the vehicle and the true paths at epoch ``k``."""
        from . import propagation

        k = integer("k", k, minimum=0)
        if k >= len(self.trajectory):
            raise ValueError(f"k: epoch {k} beyond the trajectory ({len(self.trajectory)} epochs)")
        ue, vel = self.trajectory.position[k], self.trajectory.velocity[k]
        arr = propagation.select_array(self.arrays, ue)
        tun = self.tunnel if tunnel is None else tunnel
        return arr, propagation.trace_paths(tun, arr, ue, vel, fc=self.config.fc, kinds=self.kinds)

    def epoch(
        self,
        k: int,
        rng: np.random.Generator,
        *,
        n_paths: int | None = None,
        tunnel=None,
        clock_bias: float | None = None,
        **extract_kw,
    ) -> Epoch:
        """Simulate SRS slot ``k``: trace, synthesise (noise, clock bias), extract, Algorithm 1."""
        from .extraction import extract_paths

        rng = rng_or_error("rng", rng)
        arr, paths = self.paths(k, tunnel)
        snap = synthesize(
            paths,
            self.config,
            rng,
            model=self.model,
            clock_bias=clock_bias,
            snr_offset_db=self.snr_offset_db,
        )
        L = len(paths) if n_paths is None else integer("n_paths", n_paths, minimum=1)
        est = extract_paths(
            snap.H,
            L,
            arr.local,
            self.config.fc,
            self.config.tone_spacing,
            self.config.symbol_period,
            **extract_kw,
        )
        meas = measurements_from_estimates(est, arr)
        truth = match_paths(meas.d, meas.direction, paths, clock_bias=snap.clock_bias)
        return Epoch(
            k,
            float(self.trajectory.t[k]),
            self.trajectory.position[k].copy(),
            self.trajectory.velocity[k].copy(),
            arr,
            paths,
            snap,
            est,
            meas,
            truth,
        )


def simulate_epoch(scenario, k: int, rng: np.random.Generator, **kw) -> Epoch:
    """One-call signal route: ``simulate_epoch("italiano2026-straight", 10, rng).measurements``.

    Keyword arguments go to :class:`SignalRoute` (``model``, ``kinds``, ``snr_offset_db``) or to
    :meth:`SignalRoute.epoch` (``n_paths``, ``tunnel``, ``clock_bias``, extraction options).
    For loops over epochs build a :class:`SignalRoute` once instead.
    """
    route_kw = {key: kw.pop(key) for key in ("model", "kinds", "snr_offset_db") if key in kw}
    return SignalRoute.from_scenario(scenario, **route_kw).epoch(k, rng, **kw)


# --- evaluation helpers (notebook 03, benchmarks) --------------------------------------------------


def path_rows(paths) -> list[dict]:
    """One table row per true path: family, surface, length, angles [deg], Doppler, gain, kappa."""
    return [
        {
            "kind": p.surface_kind,
            "surface": p.surface or "-",
            "length [m]": p.length,
            "azimuth [deg]": float(np.degrees(p.azimuth)),
            "elevation [deg]": float(np.degrees(p.elevation)),
            "v [m/s]": p.velocity,
            "Doppler [Hz]": p.doppler,
            "|gain| [dB]": float(20 * np.log10(abs(p.gain))),
            "kappa SR-NF [m]": p.kappa_srnf,
        }
        for p in paths
    ]


def comparison_rows(est, paths, array: ArrayGeometry, clock_bias: float) -> list[dict]:
    """Extracted vs true parameters, one row per estimate matched to a true path."""
    match = match_paths(est.d, array.dir_to_world(est.direction), paths, clock_bias=clock_bias)
    rows = []
    for i, j in enumerate(match):
        p = paths[j] if j >= 0 else None
        u = array.dir_to_world(est.direction[i])
        rows.append(
            {
                "est #": i,
                "true path": p.surface_kind if p else "none",
                "d est [m]": est.d[i],
                "d true [m]": (p.length + C * clock_bias) if p else np.nan,
                "v est": est.v[i],
                "v true": p.velocity if p else np.nan,
                "angle err [deg]": float(np.degrees(np.arccos(np.clip(u @ p.direction, -1, 1))))
                if p
                else np.nan,
                "kappa est [m]": est.kappa[i],
                "|VUE| [m]": p.length if p else np.nan,
                "kappa SR-NF [m]": p.kappa_srnf if p else np.nan,
            }
        )
    return rows


def path_crlb(
    paths, array: ArrayGeometry, config: SRSConfig, *, n_tones: int | None = None
) -> dict:
    """Cramér-Rao bounds for every path of one epoch at the configured SNR.

    ``d``/``v`` from the free-spatial-factor model (what a CPD fits, plus Vandermonde structure);
    ``direction`` [rad] and ``kappa`` [m] from the exact spherical model (wave origin = VUE).
    """
    from .extraction import crlb_paths

    nf = config.n_tones if n_tones is None else n_tones
    alpha = np.sqrt(config.tx_power) * np.array([p.gain for p in paths])
    src = np.stack([array.to_local(p.source) for p in paths])
    mu_f = -2 * np.pi * config.tone_spacing * np.array([p.length for p in paths]) / C
    mu_t = 2 * np.pi * config.symbol_period * np.array([p.doppler for p in paths])
    args = (
        alpha,
        src,
        array.local,
        mu_f,
        mu_t,
        config.fc,
        nf,
        config.n_symbols,
        config.noise_power,
    )
    free = crlb_paths(*args, spatial="free")
    st = crlb_paths(*args, spatial="structured")
    u = src / np.linalg.norm(src, axis=1, keepdims=True)
    rng_ = np.linalg.norm(src, axis=1)
    proj = np.eye(3)[None] - u[:, :, None] * u[:, None, :]
    ang = np.sqrt(np.einsum("lij,ljk,lki->l", proj, st["source_cov"], proj)) / rng_
    kap = np.sqrt(np.einsum("li,lij,lj->l", u, st["source_cov"], u))
    return {
        "d": C / (2 * np.pi * config.tone_spacing) * free["mu_f"],
        "v": C / (2 * np.pi * config.fc * config.symbol_period) * free["mu_t"],
        "direction": ang,
        "kappa": kap,
    }


def rmse_study(
    route: SignalRoute,
    k: int,
    n_snapshots: int,
    seed: int,
    *,
    refine: str = "joint",
    progress: bool = False,
) -> list[dict]:
    """RMSE of ``d``, ``v``, direction and ``kappa`` per true path over seeded snapshots, with CRLBs.

    Each snapshot draws noise and a clock bias; estimates are matched to true paths (Hungarian);
    ``d`` errors are taken against ``length + c b`` (the bias is part of the truth), ``kappa``
    against the VUE distance (exact physics). Unmatched paths count in ``missed``.
    """
    from .extraction import extract_paths
    from .montecarlo import spawn_rngs

    arr, paths = route.paths(k)
    cfg = route.config
    err = {i: [] for i in range(len(paths))}
    missed = np.zeros(len(paths), int)
    it = spawn_rngs(seed, n_snapshots)
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(it, desc="snapshots", leave=False)
    for r in it:
        snap = synthesize(paths, cfg, r, model=route.model, snr_offset_db=route.snr_offset_db)
        est = extract_paths(
            snap.H,
            len(paths),
            arr.local,
            cfg.fc,
            cfg.tone_spacing,
            cfg.symbol_period,
            refine=refine,
        )
        match = match_paths(
            est.d, arr.dir_to_world(est.direction), paths, clock_bias=snap.clock_bias
        )
        for i, j in enumerate(match):
            if j < 0:
                continue
            p = paths[j]
            u = arr.dir_to_world(est.direction[i])
            err[j].append(
                (
                    est.d[i] - p.length - C * snap.clock_bias,
                    est.v[i] - p.velocity,
                    np.arccos(np.clip(u @ p.direction, -1, 1)),
                    est.kappa[i] - p.length,
                )
            )
        missed += np.isin(np.arange(len(paths)), match, invert=True)
    bound = path_crlb(paths, arr, cfg)
    rows = []
    for j, p in enumerate(paths):
        e = np.array(err[j]).reshape(-1, 4)
        with np.errstate(invalid="ignore"):
            rm = np.sqrt(np.nanmean(e**2, axis=0)) if e.size else np.full(4, np.nan)
        rows.append(
            {
                "path": p.surface_kind,
                "surface": p.surface or "-",
                "matched": len(err[j]),
                "missed": int(missed[j]),
                "RMSE d [m]": rm[0],
                "CRLB d [m]": bound["d"][j],
                "RMSE v [m/s]": rm[1],
                "CRLB v [m/s]": bound["v"][j],
                "RMSE dir [deg]": float(np.degrees(rm[2])),
                "CRLB dir [deg]": float(np.degrees(bound["direction"][j])),
                "RMSE kappa [m]": rm[3],
                "CRLB kappa [m]": bound["kappa"][j],
                "far-field share": float(np.mean(np.isnan(e[:, 3]))) if e.size else np.nan,
            }
        )
    return rows
