"""Bounds of a candidate array along the route: exact SR-NF validity for every surface a path
reflects on and the position error bound (PEB) from the joint Fisher information of the eq. 1
tensor, both in :func:`route_bounds` (a :class:`RouteBounds`; the traced route:
:func:`route_geometry`; the per-path CRLBs: :mod:`tunnelkit.design.pathbounds`).

Evaluated from the tensor's rank-one structure and vectorised over epochs: a whole route takes
milliseconds. How it works: docs/internals/design.md.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import boolean, finite_array, instance, positive, record
from ..constants import C, wavelength
from ..fresnel import signed_mismatch
from .geometry import RouteGeometry, trace_route
from .setup import ArraySpec, DesignSetup, parse_array

# compress_slots, theta_jacobian and theta_fim are shared with design.achievable (not exported)
__all__ = ["RouteBounds", "route_bounds", "route_geometry"]

_CLOCK = ("unknown", "known")


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
    peb: np.ndarray | None
    mismatch: np.ndarray
    used: np.ndarray
    srnf_valid: np.ndarray
    kinds: tuple[str, ...]
    eps_phi: float
    n_paths: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        tp = ("T", "P")
        record(self, shapes={"x": ("T",), "peb": ("T",), "mismatch": tp, "used": tp,
                             "srnf_valid": ("T",), "kinds": ("P",), "n_paths": ("T",)},
               positive=("eps_phi",), nonnegative=("peb", "mismatch", "n_paths"),
               allow_inf=("peb",))  # fmt: skip

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


def compress_slots(used: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def theta_jacobian(cfg, s_loc, d0, src, a0, R, g, idx, mask, clock_bias, height_known, curvature):
    """``T = d eta / d theta`` (T, 7L, n_theta) of :func:`route_bounds` (docs/internals) and
    the number of position coordinates ``n_pos``, the nuisances per path ``n_nui`` and the
    index ``base`` of the first path nuisance: ``theta = [UE position, (clock bias c b), per
    path: Re a, Im a, mu_t, (radius)]``."""
    T, L = idx.shape
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
    return Tm, n_pos, n_nui, base


def theta_fim(G_eta, Tm, mask, n_nui, base):
    """``Tm^T G_eta Tm`` with the absent (padding) paths' nuisances decoupled (unit diagonal)."""
    T = mask.shape[0]
    n_theta = Tm.shape[2]
    Gth = Tm.transpose(0, 2, 1) @ G_eta @ Tm
    pad = np.zeros((T, n_theta), bool)
    pad[:, base:] = np.repeat(~mask, n_nui, axis=1)
    Gth[:, np.arange(n_theta), np.arange(n_theta)] += pad
    return Gth


def _peb(cfg, s_loc, d0, src, a0, R, pos, take, g, idx, mask, clock_bias, height_known, curvature):
    """Per-epoch PEB from the joint eq. 1 FIM (see :func:`route_bounds`)."""
    alpha = np.sqrt(cfg.tx_power) * take(g.gain)
    mu_f = -2 * np.pi * cfg.tone_spacing * d0 / C
    mu_t = 2 * np.pi * cfg.symbol_period * take(g.doppler)
    G_eta = _fim_eta(
        s_loc, pos, alpha, mu_f, mu_t, mask, cfg.fc, cfg.n_tones, cfg.n_symbols, cfg.noise_power
    )
    Tm, n_pos, n_nui, base = theta_jacobian(
        cfg, s_loc, d0, src, a0, R, g, idx, mask, clock_bias, height_known, curvature
    )
    Gth = theta_fim(G_eta, Tm, mask, n_nui, base)
    cov = _position_covariance(Gth, n_pos)
    peb = np.sqrt(np.trace(cov, axis1=1, axis2=2))
    peb = np.where(mask.any(axis=1), peb, np.inf)
    return peb


def route_geometry(setup: DesignSetup, spec, *, epochs=None) -> RouteGeometry:
    """:func:`trace_route` of ``spec`` mounted as ``setup`` says, along its route (``epochs``:
    indices that subsample it), at its carrier and path kinds."""
    instance("setup", setup, DesignSetup)
    spec = parse_array(spec)
    traj = setup.trajectory
    sl = slice(None)
    if epochs is not None:
        sl = finite_array("epochs", epochs, ndim=1)
        n = len(traj.position)
        if sl.size == 0 or np.any(sl != np.round(sl)) or sl.min() < 0 or sl.max() >= n:
            raise ValueError(
                f"epochs: expected indices in [0, {n - 1}] of the route, got {epochs!r}"
            )
        sl = sl.astype(int)
    return trace_route(
        setup.tunnel,
        setup.arrays(spec),
        traj.position[sl],
        traj.velocity[sl],
        fc=setup.config.fc,
        kinds=setup.kinds,
    )


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
    """PEB and exact SR-NF validity of ``spec`` along ``setup``'s route (docs/internals).

    ``markings=False`` leaves the RRM paths out; ``curvature=False`` makes each path's wavefront
    radius a nuisance; ``clock_bias="known"`` drops the common delay bias; ``height_known``
    (default, as JAVELIN) bounds the horizontal position with the antenna height known.
    ``epochs`` (indices) subsamples the route; ``geometry`` reuses a :func:`trace_route`;
    ``peb=False`` computes the SR-NF part only (``RouteBounds.peb`` is then ``None``).
    """
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    spec = parse_array(spec)
    for name, flag in (("markings", markings), ("curvature", curvature),
                       ("height_known", height_known), ("peb", peb)):  # fmt: skip
        boolean(name, flag)
    if clock_bias not in _CLOCK:
        raise ValueError(f"clock_bias: expected one of {_CLOCK}, got {clock_bias!r}")
    eps_phi = positive("eps_phi", eps_phi)
    cfg = setup.config
    if geometry is None:
        geometry = route_geometry(setup, spec, epochs=epochs)
    g = instance("geometry", geometry, RouteGeometry)
    pos = spec.local(cfg.fc)
    kinds = np.array(g.kinds)
    used = g.exists & (markings | (kinds != "rrm"))[None, :]
    idx, mask = compress_slots(used)
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
