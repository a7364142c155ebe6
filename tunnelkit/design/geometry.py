"""The image method for a whole route at once: every candidate path at every epoch.

:func:`trace_route` is the design's vectorised counterpart of
:func:`tunnelkit.propagation.trace_paths` (same rules: a reflection exists when UE and array are
on the surface's inner side, the segment from the reference antenna to the VUE crosses the
finite surface and neither leg is blocked; paths from behind the array face are dropped). It
returns a :class:`RouteGeometry`, one fixed slot per candidate path (LoS, then every surface),
which the bounds of :mod:`tunnelkit.design.bounds` evaluate for all epochs together.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import finite_array, positive
from ..arrays import ArrayGeometry
from ..constants import C, wavelength
from ..propagation import Tunnel3D, concrete_permittivity, fresnel_te

__all__ = ["KINDS", "RouteGeometry", "trace_route"]

#: the path families a design traces: the direct path and one bounce off each kind of surface
KINDS = ("los", "wall", "ceiling", "road", "rrm")


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
