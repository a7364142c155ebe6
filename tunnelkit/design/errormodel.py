"""What an extraction measures along a route, as a statistical model: the design's fast
measurement route.

A :class:`PathErrorModel` holds, for every epoch ``t`` and candidate path slot ``p`` of a
:class:`~tunnelkit.design.geometry.RouteGeometry`, the true path parameters in the tracker's
measurement space ``z = [phi, psi, kappa, d]`` (world-frame azimuth and elevation seen from the
array's reference antenna, wavefront radius, delay distance without clock bias) and the radial
speed ``v``, and the error of an estimator of them:

* ``crlb`` (T, 4P, 4P): the ideal bound's covariance of all paths' ``z`` jointly; this is what
  an efficient extraction *reports* (it does not know the impairments);
* ``cov`` (T, 4P, 4P): the covariance the estimator actually has under the channel's random
  terms (noise, and diffuse multipath when present): a misspecified (sandwich) bound;
* ``bias`` (T, P, 4): the deterministic bias of the misspecified estimator (e.g. the
  spatial-wideband term it does not model);
* ``k_phase`` / ``k_gain`` (T, P, 4, M): the bias per radian of each element's phase error and
  per dB of its gain error (linearised), so that one drawn calibration vector gives one array's
  bias along the whole drive.

:meth:`PathErrorModel.draw` turns it into one drive's measurements: the calibration error is
drawn once (it belongs to the array), the Gaussian error per epoch. The joint covariances keep
the correlation between paths (two paths a few centimetres apart at long range are estimated
with correlated errors). Absent slots (``exists`` False) carry zeros and are never drawn.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import finite_array, nonnegative, rng_or_error

__all__ = ["Z_NAMES", "PathErrorModel", "psd_sqrt"]

#: the measured parameters of each path, in this order
Z_NAMES = ("phi", "psi", "kappa", "d")


def psd_sqrt(S: np.ndarray) -> np.ndarray:
    """A square root ``L`` with ``L L^T = S`` of a stack of symmetric positive semi-definite
    matrices (..., n, n), through the eigendecomposition (round-off negatives set to 0)."""
    S = 0.5 * (S + np.swapaxes(S, -1, -2))
    w, V = np.linalg.eigh(S)
    return V * np.sqrt(np.clip(w, 0.0, None))[..., None, :]


@dataclass(frozen=True)
class PathErrorModel:
    """Per-epoch, per-path truth and estimator error along a route (module docstring).

    Shapes: ``t`` (T,) [s]; ``exists`` (T, P) bool; ``kinds`` (P,); ``truth`` (T, P, 4) ``z``;
    ``v`` (T, P) [m/s]; ``crlb`` and ``cov`` (T, 4P, 4P) ordered path-major
    (``[phi_0, psi_0, kappa_0, d_0, phi_1, ...]``); ``bias`` (T, P, 4); ``k_phase`` and
    ``k_gain`` (T, P, 4, M) or ``None`` (no calibration sensitivity computed);
    ``phase_sigma_rad`` and ``gain_sigma_db`` the calibration error's standard deviations.
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

    def __post_init__(self) -> None:
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

    @property
    def n_elements(self) -> int | None:
        k = self.k_phase if self.k_phase is not None else self.k_gain
        return None if k is None else int(np.shape(k)[3])

    def calibration_bias(self, phase_rad=None, gain_db=None) -> np.ndarray:
        """The bias (T, P, 4) one array's calibration error gives (linearised)."""
        T, P = self.exists.shape
        out = np.zeros((T, P, 4))
        if phase_rad is not None and self.k_phase is not None:
            out += self.k_phase @ finite_array("phase_rad", phase_rad, shape=(self.n_elements,))
        if gain_db is not None and self.k_gain is not None:
            out += self.k_gain @ finite_array("gain_db", gain_db, shape=(self.n_elements,))
        return out

    def budget(self, correlated_scale: float = 1.0) -> np.ndarray:
        """The per-path error budget (T, P, 4, 4): the second moment of the error about the
        truth, ``cov`` plus the calibration covariance over the calibration draw
        (``sigma_phi^2 K_phase K_phase^T + sigma_g^2 K_gain K_gain^T``) plus the deterministic
        bias' outer product. What an extraction that knows its array's calibration tolerance and
        its model's shortcuts (but not the draw) can report; equal to the ``crlb`` blocks for an
        ideal model. ``correlated_scale`` (>= 1) multiplies the two terms that are the same
        from one epoch to the next (calibration and bias; ``cov`` is drawn afresh every epoch):
        the white-equivalent variance of an error a filter would otherwise count once per epoch
        (:data:`tunnelkit.design.fastroute.CORRELATED_SCALE`)."""
        c = nonnegative("correlated_scale", correlated_scale)
        if c < 1.0:
            raise ValueError(f"correlated_scale: expected >= 1, got {correlated_scale!r}")
        T, P = self.exists.shape
        idx = np.arange(P)
        out = np.asarray(self.cov).reshape(T, P, 4, P, 4)[:, idx, :, idx, :]  # (P, T, 4, 4)
        out = np.moveaxis(out, 0, 1).copy()
        for k, sig in ((self.k_phase, self.phase_sigma_rad), (self.k_gain, self.gain_sigma_db)):
            if k is not None and sig > 0:
                out += c * sig**2 * (np.asarray(k) @ np.swapaxes(k, -1, -2))
        b = np.asarray(self.bias)
        out += c * (b[..., :, None] * b[..., None, :])
        return np.where(self.exists[..., None, None], out, 0.0)

    def noise_sqrt(self) -> np.ndarray:
        """A square root (T, 4P, 4P) of ``cov`` over the existing paths (absent slots zero):
        what :meth:`draw` multiplies its standard normals by. It depends on the model only, so
        a Monte-Carlo computes it once per array and hands it to every :meth:`draw`."""
        m = np.repeat(self.exists, 4, axis=1)
        return psd_sqrt(np.where(m[:, :, None] & m[:, None, :], self.cov, 0.0))

    def draw(self, rng: np.random.Generator, *, noise_sqrt: np.ndarray | None = None) -> np.ndarray:
        """One drive's measured ``z`` (T, P, 4): the truth plus the deterministic bias, one
        array's calibration bias (phase and gain errors drawn once from ``rng``) and a Gaussian
        error with covariance ``cov`` per epoch; NaN where a path does not exist.
        ``noise_sqrt``: :meth:`noise_sqrt` computed once (the same draw, without its cost)."""
        rng = rng_or_error("rng", rng)
        T, P = self.exists.shape
        M = self.n_elements
        if noise_sqrt is None:
            noise_sqrt = self.noise_sqrt()
        elif np.shape(noise_sqrt) != (T, 4 * P, 4 * P):
            raise ValueError(
                f"noise_sqrt: expected shape {(T, 4 * P, 4 * P)} (the model's noise_sqrt()), "
                f"got {np.shape(noise_sqrt)}"
            )
        phase = gain = None
        if M is not None and self.phase_sigma_rad > 0:
            phase = self.phase_sigma_rad * rng.standard_normal(M)
        if M is not None and self.gain_sigma_db > 0:
            gain = self.gain_sigma_db * rng.standard_normal(M)
        noise = (noise_sqrt @ rng.standard_normal((T, 4 * P, 1)))[..., 0].reshape(T, P, 4)
        z = self.truth + self.bias + self.calibration_bias(phase, gain) + noise
        return np.where(self.exists[..., None], z, np.nan)
