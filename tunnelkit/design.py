"""Size an antenna array for a tunnel: SR-NF validity, per-path CRLBs and a position error bound.

For every candidate array (ULA ``n``, URA ``n x m``, spacing in wavelengths) placed at the
scenario's base-station mount, along the scenario's route:

* **SR-NF validity for every surface a path reflects on** (walls, ceiling/roof facets, road,
  markings): the exact phase mismatch of :mod:`tunnelkit.fresnel` between the true wavefront
  (centred on the virtual UE) and the SR-NF model's (centred on the reflection point), across the
  whole array; an epoch is valid when every path it uses stays below ``eps_phi``;
* **per-path CRLBs** of delay distance, direction and curvature
  (:func:`tunnelkit.extraction.crlb_paths`, structured eq. 1 model);
* a **position error bound (PEB)**: the Fisher information of the eq. 1 tensor over each path's
  parameters ``eta_l = [Re alpha, Im alpha, mu_f, mu_t, wave origin (3)]`` (all paths jointly,
  cross terms included), mapped through the known geometry ``theta -> eta`` and reduced to the UE
  position by the Schur complement::

      J_theta = T^T J_eta T,      PEB = sqrt(trace([J_theta^-1]_pos))

  ``theta`` holds the UE position (x, y; and z unless ``height_known``), the clock bias (the
  channel adds one bias ``b`` to every path's delay, ``tau_l = d_l / c + b``; a nuisance unless
  ``clock_bias="known"``) and per-path nuisances (complex gain, Doppler ``mu_t``). The wave
  origin of the LoS path is the UE; of a specular path the UE mirrored in the known plane
  (``S_l = I - 2 n n^T``); the delay distance is ``||origin - p_0||``. *Without curvature* the
  wavefront radius of each path is one more nuisance (the array then gives directions only);
  *without markings* the RRM paths are left out.

The tensor sums are evaluated from the rank-1 structure (inner products factorise over array,
tones and symbols) and vectorised over epochs, so a whole route takes milliseconds: notebook 08's
explorer redraws from :func:`route_bounds` alone. Monte-Carlo tracker runs
(:func:`javelin_rmse`) go through :func:`tunnelkit.montecarlo.run_trials`; JAVELIN there takes
each path's covariance as the extraction reports it (the CRLB at the estimate, which the ML
route attains), so the tracker is tuned by the design itself at any carrier and size, and its
settled RMSE is set beside the PEB over the same epochs.

Conventions (ours): the mount point of ``[base_station]`` (plus each array's ``offset``) is the
array's **centre**; the reference antenna ``p_0`` (element 0, a corner) sits where that puts it.
Every element must lie inside the tunnel.

    >>> import tunnelkit as tk
    >>> setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    >>> b = tk.design.route_bounds(setup, "10x10")
    >>> float(np.median(b.peb)), b.srnf_valid.mean()          # doctest: +SKIP
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from ._validate import finite_array, integer, positive, probability
from .arrays import ArrayGeometry, rotation, ura
from .constants import C, wavelength

__all__ = [
    "ArraySpec",
    "DesignReport",
    "DesignRow",
    "DesignSetup",
    "RouteBounds",
    "RouteGeometry",
    "design_sweep",
    "javelin_config",
    "javelin_rmse",
    "parse_array",
    "path_bounds",
    "recommend",
    "route_bounds",
    "smallest_meeting",
    "trace_route",
]

KINDS = ("los", "wall", "ceiling", "road", "rrm")

#: V2X speed [m/s] and heading [rad] message noise of the Monte-Carlo drives (section 4.2)
SIGMA_SPEED, SIGMA_HEADING = 0.2, float(np.radians(1.0))
_CLOCK = ("unknown", "known")


# --- candidate arrays ---------------------------------------------------------------------------


@dataclass(frozen=True)
class ArraySpec:
    """A candidate array: ``rows x cols`` elements (``rows = 1``: a ULA across the tunnel),
    spacing ``spacing_wl`` wavelengths (0.5 by default)."""

    rows: int
    cols: int
    spacing_wl: float = 0.5

    def __post_init__(self) -> None:
        integer("rows", self.rows, minimum=1)
        integer("cols", self.cols, minimum=1)
        positive("spacing_wl", self.spacing_wl)
        if self.rows * self.cols < 2:
            raise ValueError("arrays: an array needs at least 2 elements")

    @property
    def label(self) -> str:
        """``"8x8"`` for a URA, ``"16"`` for a ULA."""
        return str(self.cols) if self.rows == 1 else f"{self.rows}x{self.cols}"

    @property
    def n_elements(self) -> int:
        return self.rows * self.cols

    def spacing(self, fc: float) -> float:
        """Element spacing [m] at ``fc``."""
        return self.spacing_wl * wavelength(fc)

    def local(self, fc: float) -> np.ndarray:
        """Element positions (M, 3) in the array's local frame, element 0 at the origin."""
        return ura(self.rows, self.cols, self.spacing(fc))

    def aperture(self, fc: float) -> float:
        """Largest distance between two elements [m] (the diagonal of a URA)."""
        return self.spacing(fc) * float(np.hypot(self.rows - 1, self.cols - 1))


_SPEC = re.compile(r"\s*(\d+)\s*(?:[xX×]\s*(\d+))?\s*")


def parse_array(text, spacing_wl: float = 0.5) -> ArraySpec:
    """``"8x8"`` -> 8 x 8 URA, ``"16"`` -> 16-element ULA, an :class:`ArraySpec` passes through.

    Anything else raises ``ValueError`` naming ``arrays``.
    """
    if isinstance(text, ArraySpec):
        return text
    if not isinstance(text, str):
        raise TypeError(f"arrays: expected a string such as '8x8', got {type(text).__name__}")
    m = _SPEC.fullmatch(text)
    if not m:
        raise ValueError(
            f"arrays: cannot read {text!r}; expected N (a ULA) or NxM (a URA), e.g. 16 or 8x8"
        )
    rows, cols = (1, int(m.group(1))) if m.group(2) is None else (int(m.group(1)), int(m.group(2)))
    if rows < 1 or cols < 1 or rows * cols < 2:
        raise ValueError(f"arrays: {text!r} has fewer than 2 elements")
    return ArraySpec(rows, cols, spacing_wl)


# --- the setup: tunnel, mount, route, radio -----------------------------------------------------


@dataclass(frozen=True)
class Mount:
    """Where one array hangs: its centre (3,) and boresight azimuth/elevation [rad]."""

    name: str
    centre: np.ndarray
    azimuth: float
    elevation: float


@dataclass(frozen=True)
class DesignSetup:
    """A scenario reduced to what a design needs: tunnel, mounts, route and radio.

    Build with :meth:`from_scenario` (overriding carrier, bandwidth, tilt, mount height);
    :meth:`arrays` places a candidate array on every mount (validated inside the tunnel).
    """

    name: str
    tunnel: object
    mounts: tuple[Mount, ...]
    trajectory: object
    config: object
    kinds: tuple[str, ...] = KINDS

    @classmethod
    def from_scenario(
        cls,
        scenario,
        *,
        fc: float | None = None,
        bandwidth: float | None = None,
        tilt_deg: float | None = None,
        mount_height: float | None = None,
    ) -> DesignSetup:
        """From a scenario name/path or a loaded scenario.

        ``fc`` [Hz] and ``bandwidth`` [Hz] replace the radio's (the SRS keeps its subcarrier
        spacing and comb and fills the band: ``n_rb = floor(bandwidth / (12 scs))``);
        ``tilt_deg`` (down-tilt, every array: elevation ``-tilt``) and ``mount_height`` [m]
        (every array's centre height) move the mount.
        """
        from . import propagation
        from .channel import SRSConfig
        from .scenarios import Scenario, load_scenario

        sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
        if not isinstance(sc, Scenario):
            raise TypeError(
                f"scenario: expected a name or a Scenario, got {type(scenario).__name__}"
            )
        tun = sc.tunnel()
        if not isinstance(tun, propagation.Tunnel3D):
            raise ValueError(
                f"scenario: {sc.name!r} has a 2-D tunnel; the design needs a 3-D tunnel "
                "(semicircular, rectangular or horseshoe)"
            )
        mounts = tuple(
            Mount(a.name, a.origin.copy(), a.azimuth, a.elevation)
            for a in propagation.scenario_arrays(sc)
        )
        setup = cls(sc.name, tun, mounts, sc.trajectory(tun), SRSConfig.from_scenario(sc))
        return setup.variant(
            fc=fc, bandwidth=bandwidth, tilt_deg=tilt_deg, mount_height=mount_height
        )

    def variant(
        self,
        *,
        fc: float | None = None,
        bandwidth: float | None = None,
        tilt_deg: float | None = None,
        mount_height: float | None = None,
    ) -> DesignSetup:
        """A copy with another carrier, bandwidth, down-tilt or mount height (``None`` keeps)."""
        cfg = self.config
        if fc is not None:
            cfg = replace(cfg, fc=positive("fc", fc))
        if bandwidth is not None:
            bw = positive("bandwidth", bandwidth)
            n_rb = int(np.floor(bw / (12 * cfg.scs) * (1 + 1e-9)))
            if n_rb < 1:
                raise ValueError(f"bandwidth: {bw:g} Hz is narrower than one resource block")
            cfg = replace(cfg, bandwidth=bw, n_rb=n_rb)
        mounts = []
        for m in self.mounts:
            el, centre = m.elevation, m.centre
            if tilt_deg is not None:
                t = float(finite_array("tilt_deg", tilt_deg, ndim=0))
                if not -90.0 <= t <= 90.0:
                    raise ValueError(f"tilt_deg: must lie in [-90, 90] deg, got {t}")
                el = -np.radians(t)
            if mount_height is not None:
                centre = centre.copy()
                centre[2] = float(finite_array("mount_height", mount_height, ndim=0))
            if not np.all(self.tunnel.contains(centre, margin=0.0)):
                raise ValueError(
                    f"mount: the base-station mount {centre.round(3).tolist()} of array "
                    f"{m.name!r} lies outside the tunnel"
                )
            mounts.append(Mount(m.name, centre, m.azimuth, float(el)))
        return replace(self, mounts=tuple(mounts), config=cfg)

    @property
    def fc(self) -> float:
        return float(self.config.fc)

    def signal_route(self, spec):
        """The measurement route of ``spec`` on this design as the Monte-Carlo drives it
        (:class:`tunnelkit.signal_route.SignalRoute`): each epoch's paths carry the CRLB at their
        estimate, and Algorithm 1 drops only what no clock bias explains."""
        from .signal_route import SignalRoute

        return SignalRoute(
            self.tunnel,
            self.arrays(parse_array(spec)),
            self.trajectory,
            self.config,
            kinds=self.kinds,
            report_covariance=True,
            bias_aware_delay_check=True,
        )

    def arrays(self, spec) -> list[ArrayGeometry]:
        """``spec`` placed, centred, on every mount; ``ValueError`` naming ``arrays`` if an
        element falls outside the tunnel (the array is wider than the cross-section there)."""
        spec = parse_array(spec)
        loc = spec.local(self.fc)
        out = []
        for m in self.mounts:
            rot = rotation(m.azimuth, m.elevation)
            origin = m.centre - rot @ loc.mean(axis=0)
            inside = self.tunnel.contains(origin + loc @ rot.T, margin=0.0)
            if not np.all(inside):
                raise ValueError(
                    f"arrays: the {spec.label} array ({spec.aperture(self.fc):.3f} m aperture at "
                    f"{self.fc / 1e9:g} GHz) centred at {m.centre.round(3).tolist()} does not fit "
                    f"inside the tunnel cross-section ({int((~inside).sum())} of {spec.n_elements} "
                    "elements outside); choose a smaller array or move the mount"
                )
            out.append(
                _placed(spec, self.fc, tuple(origin.tolist()), m.azimuth, m.elevation, m.name)
            )
        return out


@lru_cache(maxsize=64)
def _placed(spec: ArraySpec, fc: float, origin: tuple, azimuth: float, elevation: float, name: str):
    """An :class:`ArrayGeometry` (cached: its constructor checks every pair of elements)."""
    return ArrayGeometry(spec.local(fc), np.array(origin), azimuth, elevation, name=name)


# --- vectorised image method over a route -------------------------------------------------------


@dataclass(frozen=True)
class RouteGeometry:
    """Every candidate path at every epoch: slot 0 is the LoS, slot ``1 + s`` surface ``s``.

    ``exists`` (T, P); ``source`` (T, P, 3) wave origin (UE or VUE); ``point`` (T, P, 3) the
    reflection point (the UE for LoS); ``gain`` (T, P) complex amplitude without ``sqrt(P_t)``;
    ``doppler`` (T, P) [Hz]; ``mirror`` (P, 3, 3) ``d source / d UE``; ``kinds`` / ``names``
    (P,); ``array_index`` (T,) the array facing the vehicle; ``origin`` (T, 3) its reference
    antenna and ``rotation`` (T, 3, 3) its local axes.
    """

    ue: np.ndarray
    exists: np.ndarray
    source: np.ndarray
    point: np.ndarray
    gain: np.ndarray
    doppler: np.ndarray
    mirror: np.ndarray
    kinds: tuple[str, ...]
    names: tuple[str, ...]
    array_index: np.ndarray
    origin: np.ndarray
    rotation: np.ndarray

    @property
    def length(self) -> np.ndarray:
        """Path length to the reference antenna (T, P) [m]."""
        return np.linalg.norm(self.source - self.origin[:, None, :], axis=-1)


def trace_route(
    tunnel, arrays, ue, velocity=None, *, fc: float, kinds: tuple[str, ...] = KINDS
) -> RouteGeometry:
    """:func:`tunnelkit.propagation.trace_paths` for a whole route at once (same rules).

    ``ue`` / ``velocity`` (T, 3). The array facing the vehicle is chosen per epoch as in
    :func:`~tunnelkit.propagation.select_array`; paths from behind its face are dropped.
    """
    from .propagation import Tunnel3D, concrete_permittivity, fresnel_te

    if not isinstance(tunnel, Tunnel3D):
        raise TypeError(f"tunnel: expected a propagation.Tunnel3D, got {type(tunnel).__name__}")
    arrays = list(arrays)
    if not arrays or not all(isinstance(a, ArrayGeometry) for a in arrays):
        raise TypeError("arrays: expected a non-empty list of arrays.ArrayGeometry")
    fc = positive("fc", fc)
    ue = tunnel.require_inside("ue", finite_array("ue", ue, shape=(None, 3)))
    vel = np.zeros_like(ue) if velocity is None else finite_array("velocity", velocity)
    if vel.shape != ue.shape:
        raise ValueError(f"velocity: expected shape {ue.shape}, got {vel.shape}")
    origins = np.stack([a.origin for a in arrays])
    bores = np.stack([a.boresight for a in arrays])
    rots = np.stack([a.R for a in arrays])
    sel = np.argmax(np.einsum("ak,tak->ta", bores, ue[:, None, :] - origins[None]), axis=1)
    a0, bore = origins[sel], bores[sel]
    surfs = [s for s in tunnel.surfaces if s.kind in kinds]
    n = np.array([s.plane.normal for s in surfs]).reshape(-1, 3)
    off = np.array([s.plane.offset for s in surfs])
    du = ue @ n.T + off  # (T, S)
    da = a0 @ n.T + off
    vue = ue[:, None, :] - 2.0 * du[..., None] * n[None]
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where((du > 0) & (da > 0), da / (da + du), 0.5)
    point = a0[:, None, :] + frac[..., None] * (vue - a0[:, None, :])
    corner = np.array([s.corner for s in surfs]).reshape(-1, 3)
    eu = np.array([s.edge_u for s in surfs]).reshape(-1, 3)
    ev = np.array([s.edge_v for s in surfs]).reshape(-1, 3)
    rel = point - corner[None]
    ca = np.einsum("tsk,sk->ts", rel, eu) / np.sum(eu * eu, axis=1)
    cb = np.einsum("tsk,sk->ts", rel, ev) / np.sum(ev * ev, axis=1)
    tol = 1e-9
    inside = (ca >= -tol) & (ca <= 1 + tol) & (cb >= -tol) & (cb <= 1 + tol)
    ue_b = np.broadcast_to(ue[:, None, :], point.shape)
    a0_b = np.broadcast_to(a0[:, None, :], point.shape)
    front = np.einsum("tsk,tk->ts", point - a0[:, None, :], bore) > 0
    ok = (du > 0) & (da > 0) & inside & front
    ok &= ~tunnel.blocked(ue_b, point) & ~tunnel.blocked(point, a0_b)
    los_ok = ("los" in kinds) & ~tunnel.blocked(ue, a0) & (np.einsum("tk,tk->t", ue - a0, bore) > 0)
    # gains: Gamma lambda / (4 pi d0) exp(-j 2 pi d0 / lambda), as propagation._make_path
    lam = wavelength(fc)
    with np.errstate(divide="ignore", invalid="ignore"):
        cos_i = du / np.linalg.norm(ue_b - point, axis=-1)
    cos_i = np.where(np.isfinite(cos_i), cos_i, 1.0)
    gamma = np.empty_like(du, dtype=complex)
    eps_c = concrete_permittivity(fc)
    for j, s in enumerate(surfs):
        gamma[:, j] = -1.0 if s.material == "metal" else fresnel_te(eps_c, cos_i[:, j])
    source = np.concatenate([ue[:, None, :], vue], axis=1)
    pts = np.concatenate([ue[:, None, :], point], axis=1)
    exists = np.concatenate([los_ok[:, None], ok], axis=1)
    gam = np.concatenate([np.ones((len(ue), 1), complex), gamma], axis=1)
    d0 = np.linalg.norm(source - a0[:, None, :], axis=-1)
    gain = gam * lam / (4 * np.pi * d0) * np.exp(-2j * np.pi * d0 / lam)
    mirror = np.concatenate([np.eye(3)[None], np.eye(3)[None] - 2.0 * n[:, :, None] * n[:, None]])
    vsrc = np.einsum("pij,tj->tpi", mirror, vel)
    rr = np.einsum("tpk,tpk->tp", source - a0[:, None, :], vsrc) / d0
    return RouteGeometry(
        ue=ue,
        exists=exists,
        source=source,
        point=pts,
        gain=gain,
        doppler=fc * (-rr) / C,
        mirror=mirror,
        kinds=("los", *(s.kind for s in surfs)),
        names=("LoS", *(s.name for s in surfs)),
        array_index=sel,
        origin=a0,
        rotation=rots[sel],
    )


# --- bounds along the route ---------------------------------------------------------------------


@dataclass(frozen=True)
class RouteBounds:
    """Per-epoch results of :func:`route_bounds` for one array.

    ``peb`` (T,) [m] (``inf`` where the position is not identifiable; ``None`` if not asked); ``mismatch`` (T, P) exact
    SR-NF phase mismatch of each candidate path [rad] (0 for LoS and absent paths);
    ``used`` (T, P) the paths the bound combines; ``srnf_valid`` (T,) every used path below
    ``eps_phi``; ``x`` (T,) the vehicle's position along the tunnel.
    """

    spec: ArraySpec
    x: np.ndarray
    peb: np.ndarray
    mismatch: np.ndarray
    used: np.ndarray
    srnf_valid: np.ndarray
    kinds: tuple[str, ...]
    eps_phi: float
    n_paths: np.ndarray = field(repr=False)

    def surface_validity(self) -> dict[str, float]:
        """Per surface kind: share of epochs where every used path off that kind is valid."""
        out = {}
        kinds = np.array(self.kinds)
        for k in dict.fromkeys(self.kinds[1:]):
            cols = kinds == k
            used = self.used[:, cols]
            if not used.any():
                continue
            bad = (self.mismatch[:, cols] > self.eps_phi) & used
            out[k] = float(np.mean(~bad.any(axis=1)))
        return out


def _compress(used: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gather indices (T, L) of the used slots, padded; and the mask of real ones."""
    order = np.argsort(~used, axis=1, kind="stable")
    L = max(int(used.sum(axis=1).max()), 1)
    idx = order[:, :L]
    return idx, np.take_along_axis(used, idx, axis=1)


def _gram(X: np.ndarray) -> np.ndarray:
    """``X[t]^H X[t]`` for every ``t`` (small BLAS products; faster than a batched matmul)."""
    out = np.empty((X.shape[0], X.shape[2], X.shape[2]), complex)
    for t in range(X.shape[0]):
        out[t] = X[t].conj().T @ X[t]
    return out


def _vandermonde_pair(mu: np.ndarray, n: int) -> np.ndarray:
    """``[e^{j s mu_l}, j s e^{j s mu_l}]`` for ``s = 0..n-1``, interleaved per path: (T, n, 2L).

    ``e^{j s mu} = e^{j q B mu} e^{j r mu}`` with ``s = q B + r``: about ``2 sqrt(n)`` complex
    exponentials per path instead of ``n``.
    """
    T, L = mu.shape
    B = max(int(np.ceil(np.sqrt(n))), 1)
    q = np.arange(-(-n // B))
    r = np.arange(B)
    hi = np.exp(1j * (q * B)[None, :, None] * mu[:, None, :])  # (T, Q, L)
    lo = np.exp(1j * r[None, :, None] * mu[:, None, :])  # (T, B, L)
    v = (hi[:, :, None, :] * lo[:, None, :, :]).reshape(T, -1, L)[:, :n]
    out = np.empty((T, n, L, 2), complex)
    out[..., 0] = v
    out[..., 1] = 1j * np.arange(n)[None, :, None] * v
    return out.reshape(T, n, 2 * L)


def _fim_eta(s_loc, pos, alpha, mu_f, mu_t, mask, fc, n_tones, n_symbols, noise_power):
    """Joint Fisher information (T, 7L, 7L) of eq. 1 over ``eta_l = [Re a, Im a, mu_f, mu_t,
    s (3, local)]`` per path, assembled from the three modes' Gram matrices."""
    T, L, _ = s_loc.shape
    k0 = 2 * np.pi * fc / C
    diff = s_loc[:, None, :, :] - pos[None, :, None, :]  # (T, M, L, 3)
    rng_m = np.linalg.norm(diff, axis=-1)
    a = np.exp(1j * k0 * (rng_m - rng_m[:, :1]))
    u = diff / rng_m[..., None]
    da = 1j * k0 * a[..., None] * (u - u[:, :1])
    A = np.empty((T, pos.shape[0], L, 4), complex)
    A[..., 0] = a
    A[..., 1:] = da
    Gs = _gram(A.reshape(T, pos.shape[0], 4 * L))
    Gf = _gram(_vandermonde_pair(mu_f, n_tones))
    Gt = _gram(_vandermonde_pair(mu_t, n_symbols))
    li = np.repeat(np.arange(L), 7)
    kk = np.tile(np.arange(7), L)
    si = 4 * li + np.array([0, 0, 0, 0, 1, 2, 3])[kk]
    fi = 2 * li + (kk == 2)
    ti = 2 * li + (kk == 3)
    coef = np.where(kk[None] == 0, 1.0 + 0j, np.where(kk[None] == 1, 1j, alpha[:, li]))
    coef = coef * mask[:, li]
    gram = (
        np.conj(coef)[:, :, None]
        * coef[:, None, :]
        * Gs[:, si[:, None], si[None, :]]
        * Gf[:, fi[:, None], fi[None, :]]
        * Gt[:, ti[:, None], ti[None, :]]
    )
    return 2.0 / noise_power * gram.real


def _position_covariance(G: np.ndarray, n_pos: int, rcond: float = 1e-12) -> np.ndarray:
    """``[G^-1]`` (T, n_pos, n_pos) with Jacobi scaling; ``inf`` where ``G`` is singular."""
    d = np.diagonal(G, axis1=1, axis2=2)
    sc = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    Gs = sc[:, :, None] * G * sc[:, None, :]
    w, V = np.linalg.eigh(Gs)
    sing = (w[:, 0] <= rcond * w[:, -1]) | np.any(d[:, :n_pos] <= 0, axis=1)
    w = np.where(w > 0, w, 1.0)
    Vp = V[:, :n_pos, :]
    cov = (Vp / w[:, None, :]) @ Vp.transpose(0, 2, 1)
    cov = sc[:, :n_pos, None] * cov * sc[:, None, :n_pos]
    cov[sing] = np.inf
    return cov


def _peb(cfg, s_loc, d0, src, a0, R, pos, take, g, idx, mask, clock_bias, height_known, curvature):
    """Per-epoch PEB from the joint eq. 1 FIM (see :func:`route_bounds`)."""
    T, L = idx.shape
    alpha = np.sqrt(cfg.tx_power) * take(g.gain)
    mu_f = -2 * np.pi * cfg.tone_spacing * d0 / C
    mu_t = 2 * np.pi * cfg.symbol_period * take(g.doppler)
    G_eta = _fim_eta(
        s_loc, pos, alpha, mu_f, mu_t, mask, cfg.fc, cfg.n_tones, cfg.n_symbols, cfg.noise_power
    )
    # theta = [UE position, (clock bias c b), per path: Re a, Im a, mu_t, (radius)]
    n_pos = 2 if height_known else 3
    n_b = int(clock_bias == "unknown")
    n_nui = 3 + int(not curvature)
    base = n_pos + n_b
    n_theta = base + n_nui * L
    Tm = np.zeros((T, 7 * L, n_theta))
    lr = np.arange(L)
    S = g.mirror[idx]  # (T, L, 3, 3) d source / d UE (world)
    u_w = (src - a0[:, None, :]) / d0[..., None]
    dmuf = -2 * np.pi * cfg.tone_spacing / C
    Tm[:, 7 * lr, base + n_nui * lr] = 1.0
    Tm[:, 7 * lr + 1, base + n_nui * lr + 1] = 1.0
    Tm[:, 7 * lr + 3, base + n_nui * lr + 2] = 1.0
    Tm[:, 7 * lr + 2, :n_pos] = dmuf * np.einsum("tli,tlij->tlj", u_w, S)[..., :n_pos]
    if n_b:
        Tm[:, 7 * lr + 2, n_pos] = dmuf
    dsrc = np.einsum("tji,tljk->tlik", R, S)[..., :n_pos]  # R^T S: (T, L, 3, n_pos)
    for i in range(3):
        Tm[:, 7 * lr + 4 + i, :n_pos] = dsrc[:, :, i, :]
        if not curvature:
            Tm[:, 7 * lr + 4 + i, base + n_nui * lr + 3] = s_loc[:, :, i] / d0
    Gth = Tm.transpose(0, 2, 1) @ G_eta @ Tm
    # absent (padding) paths: their nuisances decouple
    pad = np.zeros((T, n_theta), bool)
    pad[:, base:] = np.repeat(~mask, n_nui, axis=1)
    Gth[:, np.arange(n_theta), np.arange(n_theta)] += pad
    cov = _position_covariance(Gth, n_pos)
    peb = np.sqrt(np.trace(cov, axis1=1, axis2=2))
    peb = np.where(mask.any(axis=1), peb, np.inf)
    return peb


def route_bounds(
    setup: DesignSetup,
    spec,
    *,
    markings: bool = True,
    curvature: bool = True,
    clock_bias: str = "unknown",
    height_known: bool = True,
    eps_phi: float = 0.15,
    geometry: RouteGeometry | None = None,
    epochs=None,
    peb: bool = True,
) -> RouteBounds:
    """PEB and exact SR-NF validity of ``spec`` along ``setup``'s route (module docstring).

    ``markings=False`` leaves the RRM paths out; ``curvature=False`` makes each path's wavefront
    radius a nuisance; ``clock_bias="known"`` drops the common delay bias; ``height_known``
    (default, as JAVELIN) bounds the horizontal position with the antenna height known.
    ``epochs`` (indices) subsamples the route; ``geometry`` reuses a :func:`trace_route`;
    ``peb=False`` computes the SR-NF part only (``RouteBounds.peb`` is then ``None``).
    """
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    spec = parse_array(spec)
    if clock_bias not in _CLOCK:
        raise ValueError(f"clock_bias: expected one of {_CLOCK}, got {clock_bias!r}")
    eps_phi = positive("eps_phi", eps_phi)
    cfg = setup.config
    traj = setup.trajectory
    sl = slice(None) if epochs is None else np.asarray(epochs, int)
    if geometry is None:
        geometry = trace_route(
            setup.tunnel,
            setup.arrays(spec),
            traj.position[sl],
            traj.velocity[sl],
            fc=cfg.fc,
            kinds=setup.kinds,
        )
    g = geometry
    pos = spec.local(cfg.fc)
    kinds = np.array(g.kinds)
    used = g.exists & (markings | (kinds != "rrm"))[None, :]
    idx, mask = _compress(used)
    take = lambda a: np.take_along_axis(a, idx[..., None] if a.ndim == 3 else idx, axis=1)  # noqa: E731
    src, pnt = take(g.source), take(g.point)
    a0, R = g.origin, g.rotation
    s_loc = np.einsum("tlj,tjk->tlk", src - a0[:, None, :], R)
    d0 = np.linalg.norm(s_loc, axis=-1)
    pe = None
    if peb:
        pe = _peb(
            cfg, s_loc, d0, src, a0, R, pos, take, g, idx, mask, clock_bias, height_known, curvature
        )
    # exact SR-NF mismatch of every used path (fresnel's cancellation-free form)
    from .fresnel import signed_mismatch

    pos_w = pos @ R.transpose(0, 2, 1)  # (T, M, 3) element offsets from p_0, world
    mis_c = np.abs(
        signed_mismatch(
            (src - a0[:, None, :])[:, None],
            (pnt - a0[:, None, :])[:, None],
            pos_w[:, :, None],
            wavelength(cfg.fc),
        )
    ).max(axis=1)
    mis_c = np.where(mask, mis_c, 0.0)
    mismatch = np.zeros(used.shape)
    np.put_along_axis(mismatch, idx, mis_c, axis=1)
    mismatch = np.where(used, mismatch, 0.0)
    valid = ~np.any(mismatch > eps_phi, axis=1)
    return RouteBounds(
        spec, g.ue[:, 0].copy(), pe, mismatch, used, valid, g.kinds, eps_phi, used.sum(axis=1)
    )


def path_bounds(setup: DesignSetup, spec, *, epochs=None) -> dict[str, np.ndarray]:
    """Per-path CRLBs along the route from :func:`tunnelkit.extraction.crlb_paths` (structured).

    Returns flat arrays over every (epoch, path): ``d`` [m] delay distance, ``direction`` [rad],
    ``kappa`` [m] (wavefront radius = distance to the VUE), ``kind`` (surface kind).
    """
    from . import extraction

    spec = parse_array(spec)
    cfg = setup.config
    traj = setup.trajectory
    sl = slice(None) if epochs is None else np.asarray(epochs, int)
    g = trace_route(
        setup.tunnel,
        setup.arrays(spec),
        traj.position[sl],
        traj.velocity[sl],
        fc=cfg.fc,
        kinds=setup.kinds,
    )
    pos = spec.local(cfg.fc)
    out = {"d": [], "direction": [], "kappa": [], "kind": []}
    for t in range(len(g.ue)):
        j = np.flatnonzero(g.exists[t])
        if not j.size:
            continue
        src = (g.source[t, j] - g.origin[t]) @ g.rotation[t]
        d0 = np.linalg.norm(src, axis=1)
        res = extraction.crlb_paths(
            np.sqrt(cfg.tx_power) * g.gain[t, j],
            src,
            pos,
            -2 * np.pi * cfg.tone_spacing * d0 / C,
            2 * np.pi * cfg.symbol_period * g.doppler[t, j],
            cfg.fc,
            cfg.n_tones,
            cfg.n_symbols,
            cfg.noise_power,
            spatial="structured",
        )
        u = src / d0[:, None]
        proj = np.eye(3)[None] - u[:, :, None] * u[:, None, :]
        cov = res["source_cov"]
        out["d"].append(C / (2 * np.pi * cfg.tone_spacing) * res["mu_f"])
        var_dir = np.einsum("lij,ljk,lki->l", proj, cov, proj)
        var_kap = np.einsum("li,lij,lj->l", u, cov, u)
        # a variance that is not positive: the parameter is not identifiable (e.g. curvature
        # with 2 x 2 elements) and the inversion lost it in round-off -> an infinite bound
        with np.errstate(invalid="ignore"):
            out["direction"].append(np.where(var_dir > 0, np.sqrt(var_dir), np.inf) / d0)
            out["kappa"].append(np.where(var_kap > 0, np.sqrt(var_kap), np.inf))
        out["kind"].append(np.array(g.kinds)[j])
    return {k: np.concatenate(v) if v else np.zeros(0) for k, v in out.items()}


# --- sweep and recommendation -------------------------------------------------------------------


@dataclass
class DesignRow:
    """One candidate array's summary (the JSON entry of ``tunnelkit design``)."""

    array: str
    n_elements: int
    aperture_m: float
    srnf_valid_share: float
    peb_median_m: float
    peb_p90_m: float
    met_share: float
    variants: dict = field(default_factory=dict)
    surfaces: dict = field(default_factory=dict)
    crlb: dict = field(default_factory=dict)
    rmse_m: float | None = None
    rmse_ci95_m: list | None = None
    sigmas: dict | None = None
    rmse_settled_m: float | None = None
    rmse_settled_ci95_m: list | None = None
    peb_rms_settled_m: float | None = None
    median_settled_m: float | None = None

    def to_json(self) -> dict:
        """The CLI's JSON entry: ``array, n_elements, aperture_m, srnf_valid_share,
        peb_median_m, peb_p90_m, rmse_m, rmse_ci95_m`` as the issue asked, then the settled
        RMSE after the start-up, its interval, the RMS PEB over the same epochs and the median
        settled error (``rmse_settled_m, rmse_settled_ci95_m, peb_rms_settled_m,
        median_settled_m``); non-finite values and
        anything not computed are null."""
        fin = lambda v: float(v) if v is not None and np.isfinite(v) else None  # noqa: E731
        ci = lambda v: None if v is None else [fin(x) for x in v]  # noqa: E731
        return {
            "array": self.array,
            "n_elements": int(self.n_elements),
            "aperture_m": fin(self.aperture_m),
            "srnf_valid_share": fin(self.srnf_valid_share),
            "peb_median_m": fin(self.peb_median_m),
            "peb_p90_m": fin(self.peb_p90_m),
            "rmse_m": fin(self.rmse_m),
            "rmse_ci95_m": ci(self.rmse_ci95_m),
            "rmse_settled_m": fin(self.rmse_settled_m),
            "rmse_settled_ci95_m": ci(self.rmse_settled_ci95_m),
            "peb_rms_settled_m": fin(self.peb_rms_settled_m),
            "median_settled_m": fin(self.median_settled_m),
        }


@dataclass
class DesignReport:
    """A sweep: rows per array, the recommendation and the settings it was made with."""

    scenario: str
    rows: list[DesignRow]
    recommendation: dict
    settings: dict

    def to_json(self) -> dict:
        return {
            "scenario": self.scenario,
            "arrays": [r.to_json() for r in self.rows],
            "recommendation": dict(self.recommendation),
        }

    def to_table(self) -> str:
        """A fixed-width text table, the recommendation and the settings below it."""
        s = self.settings
        head = (
            f"{'array':>7s} {'M':>5s} {'aperture':>9s} {'SR-NF ok':>9s} {'PEB med':>9s} "
            f"{'PEB p90':>9s} {'met':>6s} {'no curv.':>9s} {'no RRMs':>9s} {'RMSE [95% CI]':>22s}"
            f" {'settled RMSE':>12s} {'median':>9s} {'/ PEB':>7s}"
        )

        def m(v):
            return f"{100 * v:7.3g}cm" if np.isfinite(v) else "      inf"

        lines = [
            f"Array design for {self.scenario}: fc {s['fc'] / 1e9:g} GHz, bandwidth "
            f"{s['bandwidth'] / 1e6:g} MHz, target PEB <= {s['target']:g} m on "
            f"{100 * s['share']:.0f} % of the route with SR-NF valid (eps {s['eps_phi']:g} rad)",
            head,
        ]
        for r in self.rows:
            rm = (
                f"{r.rmse_m:6.3f} [{r.rmse_ci95_m[0]:.3f}, {r.rmse_ci95_m[1]:.3f}]"
                if r.rmse_m is not None
                else "-"
            )
            settled, median, ratio = "-", "-", "-"
            if r.rmse_settled_m is not None:
                settled = f"{100 * r.rmse_settled_m:9.3g} cm"
                median = f"{100 * r.median_settled_m:6.3g} cm"
                if r.peb_rms_settled_m and np.isfinite(r.peb_rms_settled_m):
                    ratio = f"{r.rmse_settled_m / r.peb_rms_settled_m:6.3g}x"
            lines.append(
                f"{r.array:>7s} {r.n_elements:5d} {100 * r.aperture_m:7.3g}cm "
                f"{100 * r.srnf_valid_share:8.1f}% "
                f"{m(r.peb_median_m)} {m(r.peb_p90_m)} {100 * r.met_share:5.1f}% "
                f"{m(r.variants.get('no_curvature', np.nan))} "
                f"{m(r.variants.get('no_markings', np.nan))} {rm:>22s} {settled:>12s} {median:>9s} {ratio:>7s}"
            )
        rec = self.recommendation
        lines.append(f"recommendation: {rec['array'] or 'none'} — {rec['reason']}")
        lines.append(
            "PEB: horizontal position bound with the antenna height known, clock bias and per-path "
            "gains/Dopplers as nuisances; 'met' = share of epochs with PEB <= target and SR-NF valid."
        )
        if any(r.rmse_m is not None for r in self.rows):
            lines.append(
                f"RMSE: JAVELIN over whole drives [m]; settled: after the first {SETTLE_S:g} s "
                "(RMSE, median error, and RMSE / RMS PEB over the same epochs)."
            )
        return "\n".join(lines)


def recommend(rows: list[DesignRow], target: float, share: float) -> dict:
    """The smallest array (fewest elements) whose ``met_share >= share``, with the reason."""
    ok = [r for r in rows if r.met_share >= share]
    if ok:
        best = min(ok, key=lambda r: (r.n_elements, r.aperture_m))
        return {
            "array": best.array,
            "reason": (
                f"smallest candidate with PEB <= {target:g} m and SR-NF valid on "
                f"{100 * best.met_share:.0f} % of the route (>= {100 * share:.0f} %); median PEB "
                f"{best.peb_median_m:.3g} m"
            ),
        }
    top = max(rows, key=lambda r: (r.met_share, -r.n_elements))
    why = ""
    if top.surfaces:
        worst = min(top.surfaces, key=top.surfaces.get)
        if top.surfaces[worst] < share:
            why = (
                f"; SR-NF binds on the {worst} (valid on {100 * top.surfaces[worst]:.0f} % of "
                f"epochs for {top.array})"
            )
    return {
        "array": None,
        "reason": (
            f"no candidate meets PEB <= {target:g} m with SR-NF valid on {100 * share:.0f} % of "
            f"the route; best is {top.array} with {100 * top.met_share:.0f} %{why}"
        ),
    }


def smallest_meeting(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    eps_phi: float = 0.15,
    epochs=None,
) -> tuple[ArraySpec | None, float]:
    """The first array of ``arrays`` (in the order given) whose PEB <= ``target`` with SR-NF
    valid on ``share`` of the route, and its met share; ``(None, best share)`` if none.

    The SR-NF part is computed first (cheap); the PEB only where SR-NF alone leaves ``share``
    within reach. Arrays that do not fit in the tunnel are skipped; ``epochs`` subsamples the
    route. For the explorer.
    """
    best = 0.0
    sl = slice(None) if epochs is None else np.asarray(epochs, int)
    for spec in (parse_array(a) for a in arrays):
        try:
            g = trace_route(
                setup.tunnel,
                setup.arrays(spec),
                setup.trajectory.position[sl],
                setup.trajectory.velocity[sl],
                fc=setup.fc,
                kinds=setup.kinds,
            )
        except ValueError:
            continue
        b = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g, peb=False)
        if b.srnf_valid.mean() < share:
            continue
        b = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g)
        met = float(np.mean((b.peb <= target) & b.srnf_valid))
        if met >= share:
            return spec, met
        best = max(best, met)
    return None, best


def _summary(b: RouteBounds, target: float) -> tuple[float, float, float]:
    peb = b.peb
    med = float(np.median(peb))
    p90 = float(np.quantile(peb, 0.9, method="higher"))
    met = float(np.mean((peb <= target) & b.srnf_valid))
    return med, p90, met


def design_sweep(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    eps_phi: float = 0.15,
    runs: int = 0,
    seed: int = 0,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    n_epochs: int | None = None,
    timeout: float | None = None,
) -> DesignReport:
    """Bounds (and with ``runs >= 2`` a JAVELIN Monte-Carlo) for each array in ``arrays``.

    ``workers`` / ``scheduler`` / ``timeout`` go to :func:`tunnelkit.montecarlo.run_trials`.
    """
    from .montecarlo import parallel_options

    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    specs = [parse_array(a) for a in arrays]
    if not specs:
        raise ValueError("arrays: give at least one candidate array")
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    runs = integer("runs", runs, minimum=0)
    if runs == 1:
        raise ValueError("runs: a 95 % interval needs at least 2 runs (or 0 for bounds only)")
    workers, scheduler = parallel_options(workers, scheduler)
    for s in specs:
        setup.arrays(s)  # fail early, naming the array that does not fit
    rows = []
    for spec in specs:
        b = route_bounds(setup, spec, eps_phi=eps_phi)
        med, p90, met = _summary(b, target)
        variants = {
            "no_curvature": float(np.median(route_bounds(setup, spec, curvature=False).peb)),
            "no_markings": float(np.median(route_bounds(setup, spec, markings=False).peb)),
            "no_curvature_no_markings": float(
                np.median(route_bounds(setup, spec, curvature=False, markings=False).peb)
            ),
        }
        pb = path_bounds(setup, spec)
        crlb = {k: float(np.median(pb[k])) for k in ("d", "direction", "kappa") if pb[k].size}
        row = DesignRow(
            spec.label,
            spec.n_elements,
            spec.aperture(setup.fc),
            float(b.srnf_valid.mean()),
            med,
            p90,
            met,
            variants,
            b.surface_validity(),
            crlb,
        )
        if runs:
            mc = javelin_rmse(
                setup,
                spec,
                runs,
                seed,
                workers=workers,
                scheduler=scheduler,
                progress=progress,
                n_epochs=n_epochs,
                crlb=crlb,
                timeout=timeout,
            )
            row.rmse_m, row.rmse_ci95_m, row.sigmas = mc["rmse_m"], mc["ci95_m"], mc["sigmas"]
            row.rmse_settled_m = mc["rmse_settled_m"]
            row.rmse_settled_ci95_m = mc["settled_ci95_m"]
            row.peb_rms_settled_m = mc["peb_rms_settled_m"]
            row.median_settled_m = mc["median_settled_m"]
        rows.append(row)
    settings = {
        "fc": setup.fc,
        "bandwidth": float(setup.config.bandwidth),
        "target": target,
        "share": share,
        "eps_phi": eps_phi,
        "runs": runs,
        "seed": seed,
    }
    return DesignReport(setup.name, rows, recommend(rows, target, share), settings)


# --- Monte-Carlo: JAVELIN on the design ---------------------------------------------------------


def javelin_config(crlb: dict, min_d: float = 0.0):
    """JAVELIN (our design, curvature centred on the VUE) for a design sweep at any carrier and
    array size: every path's measurement covariance is the one the extraction reports (the CRLB
    at its estimate, which the ML route attains: ``measurement_noise="reported"``), so no
    5.9 GHz constant enters; pairs are ranked by ``eta^2 + ln det S``
    (``association_cost="likelihood"``), so a new, wide track cannot take a path an established
    track predicts to a millimetre; and a VUE is born with the covariance of the angles that
    placed it (``birth_covariance="measured"``), not 10 m, so two new tracks a few degrees apart
    cannot swap their paths in the next epoch; and pairs whose stacked innovation is
    inconsistent are left out of the update (``update_gate=0.999``), which catches a wrong LoS
    taken by eq. 61 after the per-pair gate missed the true one. ``min_d``: Algorithm 1's delay
    check (``-c b_max`` keeps the paths a negative clock bias pushed below zero). The fixed sigmas, used only in an epoch whose Fisher information is
    singular at the estimate, are ``crlb`` (``d`` [m], ``direction`` [rad], ``kappa`` [m]; e.g.
    an upper percentile of the route's per-path bounds); ``sigma_delta_d`` is ``sqrt(2)`` times
    the delay-distance sigma (a difference of two delays).
    """
    from .tracking.javelin.experiment import OURS

    def pick(k):
        v = crlb.get(k)
        if v is None or not np.isfinite(v) or v <= 0:
            raise ValueError(f"crlb: {k!r} must be finite and > 0, got {v!r}")
        return float(v)

    ang, kap, d = pick("direction"), pick("kappa"), pick("d")
    return OURS.with_(
        kappa_model="vue",
        measurement_noise="reported",
        association_cost="likelihood",
        birth_covariance="measured",
        update_gate=0.999,
        min_d=float(min_d),
        sigma_phi=ang,
        sigma_psi=ang,
        sigma_kappa=kap,
        sigma_delta_d=float(np.sqrt(2.0) * d),
    )


def _drive(route, rng: np.random.Generator, n_epochs: int | None):
    """One LoS drive through the design's signal route (:meth:`DesignSetup.signal_route`)."""
    import warnings

    from .tracking.javelin.experiment import CONDITIONS, DriveData
    from .tracking.javelin.measurement import PathMeasurements

    traj = route.trajectory
    T = len(traj) if n_epochs is None else min(int(n_epochs), len(traj))
    epochs, faults = [], []
    n_true = np.zeros(T, int)
    bs = route.arrays[0].origin.copy()
    for k in range(T):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                ep = route.epoch(k, rng)
            except (ValueError, np.linalg.LinAlgError) as exc:
                faults.append(f"epoch {k}: extraction failed ({exc})")
                epochs.append(None)
                continue
        m = ep.measurements
        bs = m.origin.copy()
        n_true[k] = len(ep.paths)
        if m.cov is None and len(m):
            # the fit failed its residual test (or its Fisher information is singular): no
            # covariance to trust, so no measurement this epoch
            faults.append(f"epoch {k}: extraction failed its residual test")
            epochs.append(None)
            continue
        epochs.append(
            PathMeasurements.from_arrays(
                m.phi,
                m.psi,
                m.kappa,
                m.d,
                m.v,
                warn=False,
                cov=m.cov,
                sigma_d=m.sigma_d,
                min_d=route.min_d,
            )
        )
    vel = traj.velocity[:T]
    speed = np.linalg.norm(vel[:, :2], axis=1) + SIGMA_SPEED * rng.standard_normal(T)
    heading = np.arctan2(vel[:, 1], vel[:, 0]) + SIGMA_HEADING * rng.standard_normal(T)
    drive = DriveData(
        "design",
        CONDITIONS["L"],
        traj.t[:T].copy(),
        traj.position[:T].copy(),
        vel.copy(),
        speed,
        heading,
        epochs,
        n_true > 0,
        n_true,
        bs,
        faults=faults,
    )
    return drive


#: the first second of a drive is the tracker's start-up (an open-sky fix with 1 m of
#: uncertainty, the VUE tracks born over the first epochs): the settled RMSE leaves it out
SETTLE_S = 1.0


def _settled(t: np.ndarray) -> np.ndarray:
    """Indices of the epochs at least :data:`SETTLE_S` after the start."""
    return np.flatnonzero(t - t[0] >= SETTLE_S - 1e-9)


@dataclass(frozen=True)
class _JavelinTrial:
    """One Monte-Carlo run (picklable for Dask workers): a drive, JAVELIN, its 2-D RMSE over the
    whole drive, and the RMSE and median of the 2-D error over the settled epochs (NaN when the
    drive is shorter than the start-up)."""

    setup: DesignSetup
    spec: ArraySpec
    config: object
    n_epochs: int | None

    def __call__(self, rng: np.random.Generator) -> tuple[float, float, float]:
        from .tracking.javelin.experiment import evaluate

        drive = _drive(self.setup.signal_route(self.spec), rng, self.n_epochs)
        ev = evaluate(drive, self.config)
        idx = _settled(drive.t)
        e = np.linalg.norm(ev.estimates[idx, :2] - drive.truth[idx, :2], axis=1)
        rmse, med = (np.sqrt(np.mean(e**2)), np.median(e)) if idx.size else (np.nan, np.nan)
        return float(ev.metrics["rmse_2d_m"]), float(rmse), float(med)


def _t_interval(x: np.ndarray) -> tuple[float, list[float]]:
    """Mean and 95 % t-interval (clipped at 0: an RMSE is not negative)."""
    from scipy import stats

    mean = float(x.mean())
    half = float(stats.t.ppf(0.975, x.size - 1) * x.std(ddof=1) / np.sqrt(x.size))
    return mean, [max(mean - half, 0.0), mean + half]


def javelin_rmse(
    setup: DesignSetup,
    spec,
    runs: int,
    seed: int | np.random.Generator,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    n_epochs: int | None = None,
    crlb: dict | None = None,
    timeout: float | None = None,
) -> dict:
    """Monte-Carlo 2-D RMSE of JAVELIN on ``spec`` with a 95 % t-interval over ``runs`` drives
    (LoS condition, the scenario's route; the interval is clipped at 0).

    Each path's measurement covariance is the one the extraction reports (:func:`javelin_config`),
    and an epoch whose fit fails its own residual test is predict-only. ``crlb`` (default: the
    route-median per-path bounds) only sets the fixed fallback sigmas. Besides the whole-drive
    RMSE (``rmse_m``, as the paper's tables), the settled RMSE leaves out the first
    :data:`SETTLE_S` of every drive (``rmse_settled_m``, ``None`` for a shorter drive) and is set
    beside the RMS of the PEB over the same epochs (``peb_rms_settled_m``); ``median_settled_m``
    is the median over runs of each run's median settled error (the typical epoch, where the
    RMSE also counts the epochs the tracker coasts through without a measurement). Runs go through
    :func:`tunnelkit.montecarlo.run_trials` (``workers`` / ``scheduler`` / ``timeout`` passed on
    when given); ``seed`` is an int or a Generator.
    """
    from .montecarlo import run_trials

    spec = parse_array(spec)
    runs = integer("runs", runs, minimum=2)
    if not isinstance(seed, np.random.Generator):
        seed = integer("seed", seed, minimum=0)
    if crlb is None:
        pb = path_bounds(setup, spec)
        crlb = {k: float(np.median(pb[k])) for k in ("d", "direction", "kappa")}
    cfg = javelin_config(crlb, setup.signal_route(spec).min_d)
    kw = (("workers", workers), ("scheduler", scheduler), ("timeout", timeout))
    res = np.asarray(
        run_trials(
            _JavelinTrial(setup, spec, cfg, n_epochs),
            runs,
            seed,
            progress=progress,
            desc=f"JAVELIN {spec.label}",
            **{k: v for k, v in kw if v is not None},
        ),
        float,
    ).reshape(runs, 3)
    mean, ci = _t_interval(res[:, 0])
    out = {
        "rmse_m": mean,
        "ci95_m": ci,
        "runs": res[:, 0],
        "rmse_settled_m": None,
        "settled_ci95_m": None,
        "peb_rms_settled_m": None,
        "median_settled_m": None,
        "runs_settled": res[:, 1],
        "sigmas": {
            "direction_rad": cfg.sigma_phi,
            "kappa_m": cfg.sigma_kappa,
            "delta_d_m": cfg.sigma_delta_d,
        },
    }
    T = len(setup.trajectory) if n_epochs is None else min(int(n_epochs), len(setup.trajectory))
    idx = _settled(setup.trajectory.t[:T])
    if idx.size:
        out["rmse_settled_m"], out["settled_ci95_m"] = _t_interval(res[:, 1])
        out["median_settled_m"] = float(np.median(res[:, 2]))
        peb = route_bounds(setup, spec, epochs=idx).peb
        out["peb_rms_settled_m"] = float(np.sqrt(np.mean(peb**2)))
    return out
