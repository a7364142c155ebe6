"""What an extraction measures along a route, as a statistical model: the design's fast
measurement route.

A :class:`PathErrorModel` holds, per epoch and candidate path slot, the true path parameters in
the tracker's measurement space ``z = [phi, psi, kappa, d]`` and the error of an estimator of
them (``crlb``, ``cov``, ``bias``, ``k_phase`` / ``k_gain``);
:func:`tunnelkit.design.errordraws.draw` turns it into one drive's measurements
(:mod:`tunnelkit.design.errordraws`, loaded when a drive is drawn, with the calibration draw, the
noise's square root and the split of the budget).

How it works, field by field: docs/internals/design.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checks import real_array
from .._validate import finite_array, nonnegative, sequence

__all__ = ["Z_NAMES", "PathErrorModel"]

#: the measured parameters of each path, in this order
Z_NAMES = ("phi", "psi", "kappa", "d")


@dataclass(frozen=True)
class PathErrorModel:
    """Per-epoch, per-path truth and estimator error along a route (docs/internals).

    Shapes: ``t`` (T,) [s]; ``exists`` (T, P) bool; ``kinds`` (P,); ``truth`` (T, P, 4) ``z``;
    ``v`` (T, P) [m/s]; ``crlb`` and ``cov`` (T, 4P, 4P) ordered path-major
    (``[phi_0, psi_0, kappa_0, d_0, phi_1, ...]``); ``bias`` (T, P, 4); ``k_phase`` and
    ``k_gain`` (T, P, 4, M) or ``None`` (no calibration sensitivity computed);
    ``phase_sigma_rad`` and ``gain_sigma_db`` the calibration error's standard deviations;
    ``unresolved`` (T, P) bool or ``None``: paths of the route geometry the model leaves out
    at an epoch because the array cannot resolve them there (absent from ``exists``: a gap in
    that path's information, not in the epoch's).
    """

    t: np.ndarray
    exists: np.ndarray
    kinds: tuple[str, ...]
    truth: np.ndarray
    v: np.ndarray
    crlb: np.ndarray
    cov: np.ndarray
    bias: np.ndarray
    k_phase: np.ndarray | None = None
    k_gain: np.ndarray | None = None
    phase_sigma_rad: float = 0.0
    gain_sigma_db: float = 0.0
    unresolved: np.ndarray | None = None

    def __post_init__(self) -> None:
        sequence("kinds", self.kinds)
        for name in ("truth", "v", "crlb", "cov", "bias"):  # NaN allowed where no path exists
            real_array(name, getattr(self, name))
        ex = np.asarray(self.exists)
        if ex.ndim != 2 or ex.dtype != bool:
            raise ValueError(f"exists: expected a (T, P) bool array, got {ex.dtype} {ex.shape}")
        T, P = ex.shape
        if len(self.kinds) != P:
            raise ValueError(f"kinds: expected {P} kinds, got {len(self.kinds)}")
        finite_array("t", self.t, shape=(T,))
        m = np.repeat(ex, 4, axis=1)
        masks = {
            "truth": ex[..., None],
            "v": ex,
            "crlb": m[:, :, None] & m[:, None, :],
            "cov": m[:, :, None] & m[:, None, :],
            "bias": ex[..., None],
        }
        shapes = {
            "truth": (T, P, 4),
            "v": (T, P),
            "crlb": (T, 4 * P, 4 * P),
            "cov": (T, 4 * P, 4 * P),
            "bias": (T, P, 4),
        }
        for name, shape in shapes.items():
            a = np.asarray(getattr(self, name), dtype=float)
            if a.shape != shape:
                raise ValueError(f"{name}: expected shape {shape}, got {a.shape}")
            if not np.all(np.isfinite(a[np.broadcast_to(masks[name], shape)])):
                raise ValueError(f"{name}: every entry of an existing path must be finite")
        for name in ("k_phase", "k_gain"):
            k = getattr(self, name)
            if k is not None and (np.ndim(k) != 4 or np.shape(k)[:3] != (T, P, 4)):
                raise ValueError(f"{name}: expected shape ({T}, {P}, 4, M), got {np.shape(k)}")
        for name, k in (("phase_sigma_rad", "k_phase"), ("gain_sigma_db", "k_gain")):
            if nonnegative(name, getattr(self, name)) > 0 and getattr(self, k) is None:
                raise ValueError(f"{name}: a calibration error needs its sensitivity {k}")
            if getattr(self, k) is not None and not np.all(np.isfinite(getattr(self, k))):
                raise ValueError(f"{k}: every entry must be finite")
        if self.unresolved is not None:
            un = np.asarray(self.unresolved)
            if un.shape != (T, P) or un.dtype != bool:
                raise ValueError(f"unresolved: expected a ({T}, {P}) bool array, got {un.shape}")
            if np.any(un & ex):
                raise ValueError("unresolved: a path the model leaves out cannot also exist")
        for name in ("crlb", "cov"):  # a covariance's variances are >= 0
            if np.any(np.diagonal(np.asarray(getattr(self, name)), axis1=1, axis2=2) < 0):
                raise ValueError(f"{name}: a variance is negative (not a covariance)")

    @property
    def n_elements(self) -> int | None:
        k = self.k_phase if self.k_phase is not None else self.k_gain
        return None if k is None else int(np.shape(k)[3])

    def budget(self) -> np.ndarray:
        """The per-path error budget (T, P, 4, 4): the second moment of the error about the
        truth, ``cov`` plus the calibration covariance over the calibration draw
        (``sigma_phi^2 K_phase K_phase^T + sigma_g^2 K_gain K_gain^T``) plus the deterministic
        bias' outer product (:func:`tunnelkit.design.errordraws.split`: the share of it one drive repeats). What an extraction that knows its array's
        calibration tolerance and its model's shortcuts (but not the draw) can report; equal to
        the ``crlb`` blocks for an ideal model."""
        T, P = self.exists.shape
        idx = np.arange(P)
        out = np.asarray(self.cov).reshape(T, P, 4, P, 4)[:, idx, :, idx, :]  # (P, T, 4, 4)
        out = np.moveaxis(out, 0, 1).copy()
        for k, sig in ((self.k_phase, self.phase_sigma_rad), (self.k_gain, self.gain_sigma_db)):
            if k is not None and sig > 0:
                out += sig**2 * (np.asarray(k) @ np.swapaxes(k, -1, -2))
        b = np.asarray(self.bias)
        out += b[..., :, None] * b[..., None, :]
        return np.where(self.exists[..., None, None], out, 0.0)
