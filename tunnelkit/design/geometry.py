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

from .._physical import carrier, speeds
from .._validate import choice, finite_array, record, sequence
from ..arrays import ArrayGeometry
from ..constants import C, wavelength
from ..propagation import Tunnel3D

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

    def __post_init__(self) -> None:
        tp, t3 = ("T", "P"), ("T", "P", 3)
        record(self, shapes={"ue": ("T", 3), "exists": tp, "source": t3, "point": t3, "gain": tp,
                             "doppler": tp, "mirror": ("P", 3, 3), "kinds": ("P",),
                             "names": ("P",), "array_index": ("T",), "origin": ("T", 3),
                             "rotation": ("T", 3, 3)})  # fmt: skip

    @property
    def length(self) -> np.ndarray:
        """Path length to the reference antenna (T, P) [m]."""
        return np.linalg.norm(self.source - self.origin[:, None, :], axis=-1)


def trace_route(
    tunnel, arrays, ue, velocity=None, *, fc: float, kinds: tuple[str, ...] = KINDS
) -> RouteGeometry:
    """:func:`tunnelkit.propagation.trace_paths` for a whole route at once (same rules).

    ``ue`` / ``velocity`` (T, 3). The array facing the vehicle is chosen per epoch as in
    :func:`~tunnelkit.propagation.select_array`; paths from behind its face are dropped. Each
    surface is traced for all epochs at once through its own methods (plane distance and mirror,
    rectangle test, reflection coefficient), so the rules are propagation's. The result differs
    from ``trace_paths`` epoch by epoch only in the last bits: the VUE velocity is
    ``mirror @ velocity`` (the matrix the bounds differentiate with) and the gains' complex
    exponentials are evaluated on arrays, which rounds differently from one path at a time
    (about 1e-12 relative at a phase of 10^4 rad).
    """
    if not isinstance(tunnel, Tunnel3D):
        raise TypeError(f"tunnel: expected a propagation.Tunnel3D, got {type(tunnel).__name__}")
    arrays = sequence("arrays", arrays)
    kinds = tuple(choice("kinds", k, KINDS) for k in sequence("kinds", kinds))
    if not arrays or not all(isinstance(a, ArrayGeometry) for a in arrays):
        raise TypeError("arrays: expected a non-empty list of arrays.ArrayGeometry")
    fc = carrier("fc", fc)
    ue = tunnel.require_inside("ue", finite_array("ue", ue, shape=(None, 3)))
    vel = (
        np.zeros_like(ue)
        if velocity is None
        else speeds("velocity", finite_array("velocity", velocity))
    )
    if vel.shape != ue.shape:
        raise ValueError(f"velocity: expected shape {ue.shape}, got {vel.shape}")
    origins = np.stack([a.origin for a in arrays])
    bores = np.stack([a.boresight for a in arrays])
    rots = np.stack([a.R for a in arrays])
    sel = np.argmax(np.einsum("ak,tak->ta", bores, ue[:, None, :] - origins[None]), axis=1)
    a0 = origins[sel]
    surfs = [s for s in tunnel.surfaces if s.kind in kinds]
    T, S = len(ue), len(surfs)
    vue, point = np.empty((T, S, 3)), np.empty((T, S, 3))
    ok = np.empty((T, S), bool)
    gamma = np.empty((T, S), complex)
    # each surface through propagation's own rules (plane, rectangle, material), all epochs at once
    for j, s in enumerate(surfs):
        pl = s.plane
        du, da = pl.signed_distance(ue), pl.signed_distance(a0)
        vue[:, j] = pl.mirror(ue)
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where((du > 0) & (da > 0), da / (da + du), 0.5)
        point[:, j] = a0 + frac[:, None] * (vue[:, j] - a0)
        ok[:, j] = (du > 0) & (da > 0) & s.contains(point[:, j], tol=1e-9)
        ok[:, j] &= _in_front(arrays, sel, point[:, j])
        ok[:, j] &= ~tunnel.blocked(ue, point[:, j]) & ~tunnel.blocked(point[:, j], a0)
        with np.errstate(divide="ignore", invalid="ignore"):
            cos_i = du / np.linalg.norm(ue - point[:, j], axis=-1)
        # rounding may give 1 + 1e-16 (as in trace_paths); a surface behind the UE has no path
        cos_i = np.clip(np.where(np.isfinite(cos_i), cos_i, 1.0), 0.0, 1.0)
        gamma[:, j] = s.reflection_coefficient(fc, cos_i)
    los_ok = ("los" in kinds) & ~tunnel.blocked(ue, a0) & _in_front(arrays, sel, ue)
    # gains: Gamma lambda / (4 pi d0) exp(-j 2 pi d0 / lambda), as propagation.trace_paths
    lam = wavelength(fc)
    n = np.array([s.plane.normal for s in surfs]).reshape(-1, 3)
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


def _in_front(arrays, sel: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``arrays[sel[t]].in_front(p[t])`` for every epoch ``t`` (grouped by array)."""
    out = np.zeros(len(p), bool)
    for i in np.unique(sel):
        rows = sel == i
        out[rows] = arrays[i].in_front(p[rows])
    return out
