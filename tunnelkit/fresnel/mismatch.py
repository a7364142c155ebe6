"""The exact SR-NF phase mismatch at given antennas, and the input check of the package.

:func:`signed_mismatch` is the mismatch between the true wavefront (centred on the VUE) and the
SR-NF model's (centred on the reference specular point) at each antenna, from the
cancellation-free path difference :func:`path_difference` (eq. 2 / eq. 27); the design's SR-NF
check of a route (:func:`tunnelkit.design.route_bounds`) needs nothing else of the package.
:func:`real_input` checks every real input of :mod:`tunnelkit.fresnel.bounds` and
:mod:`tunnelkit.fresnel.exact`.
"""

from __future__ import annotations

import numpy as np

from .._validate import boolean, finite_array, text

__all__ = ["real_input", "signed_mismatch"]


def real_input(name: str, value, *, pos: bool = False) -> np.ndarray:
    """``value`` as a finite real scalar or array (bools and text refused, errors naming
    ``name``); ``pos`` insists on > 0 everywhere. The input check of every function here."""
    text("name", name)
    pos = boolean("pos", pos)
    if isinstance(value, bool | np.bool_):
        raise TypeError(f"{name}: expected a real number, got {value!r}")
    if isinstance(value, str | bytes):
        raise TypeError(f"{name}: expected a real number, got {type(value).__name__}")
    arr = finite_array(name, value)
    if pos and np.any(arr <= 0):
        raise ValueError(f"{name}: must be > 0, got {float(np.min(arr))}")
    return arr


def path_difference(src: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """``|src - p| - |src|`` without cancellation: ``(|p|^2 - 2 src.p) / (|src - p| + |src|)``.

    ``src`` (..., 3) broadcast against ``pos`` (..., 3); the path difference of eq. 2 / eq. 27.
    """
    num = np.sum(pos * pos, axis=-1) - 2.0 * np.sum(src * pos, axis=-1)
    den = np.linalg.norm(src - pos, axis=-1) + np.linalg.norm(src, axis=-1)
    return num / den


def signed_mismatch(pv, ps, pos, lam) -> np.ndarray:
    """Signed exact phase mismatch ``2 pi / lambda (delta*_m - delta^SR_m)`` [rad], no expansion.

    ``pv`` (..., 3): the true wavefront's centre (the VUE); ``ps`` (..., 3): the SR-NF model's
    (the reference antenna's specular point); ``pos`` (..., 3): the antennas; all relative to the
    reference antenna and broadcast against each other; ``lam`` [m] the wavelength. Each path
    difference ``|c - p| - |c|`` is evaluated in the cancellation-free form
    ``(|p|^2 - 2 c.p) / (|c - p| + |c|)``, so a mismatch of micro-radians over a metre-long path
    keeps its digits. Used by :func:`mismatch_profile` and by the design's SR-NF check of every
    path along a route (:func:`tunnelkit.design.route_bounds`).
    """
    pv, ps, pos = (finite_array(k, v) for k, v in (("pv", pv), ("ps", ps), ("pos", pos)))
    for k, v in (("pv", pv), ("ps", ps), ("pos", pos)):
        if v.ndim == 0 or v.shape[-1] != 3:
            raise ValueError(f"{k}: expected 3 coordinates in the last axis, got shape {v.shape}")
    try:
        np.broadcast_shapes(pv.shape, ps.shape, pos.shape)
    except ValueError:
        raise ValueError(
            f"pv, ps, pos: shapes {pv.shape}, {ps.shape}, {pos.shape} do not broadcast"
        ) from None
    lam = real_input("lam", lam, pos=True)
    return (2.0 * np.pi / lam) * (path_difference(pv, pos) - path_difference(ps, pos))
