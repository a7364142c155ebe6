"""The misspecified bound of eq. 1, in the factorised form the design's bounds use (Richmond &
Horowitz 2015; Fortunati et al. 2017): the first-order bias and the sandwich covariance of an
estimator that fits eq. 1 to data with a calibration error, the spatial-wideband term or dense
diffuse multipath.

:class:`EtaModes` holds the Jacobian's three modes (array, tones, symbols) and each
perturbation's scores (the spatial-wideband term's: :mod:`tunnelkit.design.wideband`);
:func:`scaled_inverse` (Jacobi-scaled inverses of stacked information matrices) and
:func:`radial_basis` (azimuth, elevation and range directions) are its helpers.

How it works: docs/internals/design.md.
"""

from __future__ import annotations

import numpy as np

from .._checks import square_matrices
from .._physical import carrier, tone_step
from .._validate import finite_array, instance, integer, positive, probability
from ..budget import check_elements
from ..channel import DiffuseSpec
from ..constants import C

__all__ = ["FRAMES", "EtaModes", "radial_basis", "scaled_inverse"]

#: the coordinates of each path's wave origin in ``eta`` (:class:`EtaModes`): ``"cartesian"``
#: the local frame's ``s_x, s_y, s_z``; ``"radial"`` displacements along the path's own
#: azimuth, elevation and range directions (:func:`radial_basis`)
FRAMES = ("cartesian", "radial")


def _pair(mu: np.ndarray, n: int) -> np.ndarray:
    """``[e^{j s mu_l}, j s e^{j s mu_l}]`` for ``s = 0..n-1``, interleaved per path: (T, n, 2L)."""
    s = np.arange(n, dtype=float)
    v = np.exp(1j * s[None, :, None] * mu[:, None, :])
    out = np.empty((*v.shape, 2), complex)
    out[..., 0] = v
    out[..., 1] = 1j * s[None, :, None] * v
    return out.reshape(mu.shape[0], n, 2 * mu.shape[1])


def _mm(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A[t] @ B[t]`` for every ``t``, one BLAS product each (numpy's batched complex matmul
    is many times slower on these shapes)."""
    out = np.empty((A.shape[0], A.shape[1], B.shape[2]), np.result_type(A, B))
    for t in range(A.shape[0]):
        np.matmul(A[t], B[t], out=out[t])
    return out


def gram(X: np.ndarray, Y: np.ndarray | None = None) -> np.ndarray:
    """``X[t]^H Y[t]`` for every ``t``."""
    return _mm(np.conj(X).transpose(0, 2, 1), X if Y is None else Y)


def scaled_inverse(G: np.ndarray, rcond: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of a stack of symmetric positive (semi-)definite matrices (T, n, n) with Jacobi
    scaling, and a (T,) flag of the singular ones (their inverse is NaN)."""
    G = square_matrices("G", G, ndim=3)
    rcond = probability("rcond", rcond, open_interval=False)
    d = np.diagonal(G, axis1=1, axis2=2)
    sc = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    Gs = sc[:, :, None] * G * sc[:, None, :]
    w, V = np.linalg.eigh(0.5 * (Gs + Gs.transpose(0, 2, 1)))
    sing = (w[:, 0] <= rcond * w[:, -1]) | np.any(d <= 0, axis=1)
    w = np.where(w > 0, w, 1.0)
    inv = (V / w[:, None, :]) @ V.transpose(0, 2, 1)
    inv = sc[:, :, None] * inv * sc[:, None, :]
    inv[sing] = np.nan
    return inv, sing


def radial_basis(s_loc) -> np.ndarray:
    """Per wave origin ``s_loc`` (..., 3) an orthonormal basis (..., 3, 3) whose columns are the
    directions of increasing azimuth, elevation and range seen from the origin (the reference
    antenna): ``[e_phi, e_psi, u]``, ``u = s / |s|``. On the vertical axis ``e_phi`` is the
    local ``y`` axis; at ``s = 0`` the identity.

    In these coordinates the Fisher information of a distant path is well conditioned after
    Jacobi scaling at any range: the range column is small (the wavefront's curvature) but
    not nearly collinear with the others, whereas in Cartesian coordinates the three columns of
    the wave origin become collinear as the range grows (their combination along ``u`` is
    second order in aperture / range), so the scaled matrix' condition number grows like
    ``(range / aperture)^2`` and the inverse is lost (4 x 4 at 28 GHz beyond about 100 m)."""
    s = finite_array("s_loc", s_loc)
    if s.ndim not in (1, 2, 3) or s.shape[-1] != 3:
        raise ValueError(f"s_loc: expected points (3,), (n, 3) or (T, n, 3), got {s.shape}")
    r = np.linalg.norm(s, axis=-1)
    u = np.where(r[..., None] > 0, s / np.where(r > 0, r, 1.0)[..., None], [1.0, 0.0, 0.0])
    phi = np.arctan2(u[..., 1], u[..., 0])
    psi = np.arctan2(u[..., 2], np.hypot(u[..., 0], u[..., 1]))
    e_phi = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)], axis=-1)
    e_psi = np.stack([-np.sin(psi) * np.cos(phi), -np.sin(psi) * np.sin(phi), np.cos(psi)], axis=-1)
    u = np.stack([np.cos(psi) * np.cos(phi), np.cos(psi) * np.sin(phi), np.sin(psi)], axis=-1)
    B = np.stack([e_phi, e_psi, u], axis=-1)
    return np.where((r > 0)[..., None, None], B, np.eye(3))


def _check_modes(s_loc, pos, alpha, mu_f, mu_t, mask, fc, n_tones, n_symbols) -> None:
    """The arguments of :class:`EtaModes`: shapes (T, L, 3), (M, 3), (T, L) each."""
    T, L, _ = finite_array("s_loc", s_loc, shape=(None, None, 3)).shape
    finite_array("pos", pos, shape=(None, 3))
    finite_array("alpha", alpha, dtype=complex, shape=(T, L))
    finite_array("mu_f", mu_f, shape=(T, L)), finite_array("mu_t", mu_t, shape=(T, L))
    if np.shape(mask) != (T, L) or np.asarray(mask).dtype != bool:
        raise ValueError(f"mask: expected a ({T}, {L}) bool array, got {np.shape(mask)}")
    carrier("fc", fc), integer("n_tones", n_tones, minimum=1)
    integer("n_symbols", n_symbols, minimum=1)
    check_elements("n_tones", T * L * n_tones, 16, f"{T} x {L} paths' tone factors")
    check_elements("n_symbols", T * L * n_symbols, 16, f"{T} x {L} paths' symbol factors")


class EtaModes:
    """The mode vectors of ``J`` for a stack of epochs (docs/internals).

    ``s_loc`` (T, L, 3) wave origins (local frame), ``pos`` (M, 3) elements, ``alpha`` (T, L)
    gains with ``sqrt(P_t)``, ``mu_f`` / ``mu_t`` (T, L), ``mask`` (T, L) the real paths (the
    others are padding and contribute nothing). Columns of ``J`` per path: ``Re a, Im a, mu_f,
    mu_t`` and three of the wave origin: ``s_x, s_y, s_z`` (``frame="cartesian"``) or, with
    ``frame="radial"``, displacements along ``basis[t, l]`` (T, L, 3, 3) (:func:`radial_basis`:
    azimuth, elevation, range), ``s = s_0 + basis @ eta_s``; a Jacobian ``d z / d s`` maps to
    these as ``d z / d s @ basis``. The range column is evaluated without cancellation
    (``(u_m - u_0) . u_0 = -|u_m - u_0|^2 / 2``), so a far path's curvature information is
    exact to rounding.
    """

    def __init__(
        self, s_loc, pos, alpha, mu_f, mu_t, mask, fc, n_tones, n_symbols, frame="cartesian"
    ):
        _check_modes(s_loc, pos, alpha, mu_f, mu_t, mask, fc, n_tones, n_symbols)
        if frame not in FRAMES:
            raise ValueError(f"frame: expected one of {FRAMES}, got {frame!r}")
        T, L, _ = s_loc.shape
        self.k0 = 2 * np.pi * fc / C
        self.n_tones, self.n_symbols = int(n_tones), int(n_symbols)
        diff = s_loc[:, None, :, :] - pos[None, :, None, :]  # (T, M, L, 3)
        rng_m = np.linalg.norm(diff, axis=-1)
        self.offset = rng_m - rng_m[:, :1]  # (T, M, L) path-length offsets delta_lm
        a = np.exp(1j * self.k0 * self.offset)
        u = diff / rng_m[..., None]
        A = np.empty((T, pos.shape[0], L, 4), complex)
        A[..., 0] = a
        du = u - u[:, :1]  # (T, M, L, 3)
        if frame == "radial":
            self.basis = radial_basis(s_loc)
            g = np.einsum("tmli,tlij->tmlj", du, self.basis)
            g[..., 2] = -0.5 * np.sum(du * du, axis=-1)  # (u_m - u_0) . u_0, cancellation-free
        else:
            self.basis = np.broadcast_to(np.eye(3), (T, L, 3, 3))
            g = du
        A[..., 1:] = 1j * self.k0 * a[..., None] * g
        self.frame = frame
        self.a = a
        self.X = A.reshape(T, pos.shape[0], 4 * L)
        self.F2 = _pair(mu_f, self.n_tones)
        self.T2 = _pair(mu_t, self.n_symbols)
        self.alpha = np.where(mask, alpha, 0.0)
        li = np.repeat(np.arange(L), 7)
        kk = np.tile(np.arange(7), L)
        self.si = 4 * li + np.array([0, 0, 0, 0, 1, 2, 3])[kk]
        self.fi = 2 * li + (kk == 2)
        self.ti = 2 * li + (kk == 3)
        coef = np.where(kk[None] == 0, 1.0 + 0j, np.where(kk[None] == 1, 1j, alpha[:, li]))
        self.coef = coef * mask[:, li]
        self._grams = None

    @property
    def grams(self):
        """``X^H X``, ``F^H F``, ``T^H T`` (cached)."""
        if self._grams is None:
            self._grams = (gram(self.X), gram(self.F2), gram(self.T2))
        return self._grams

    def assemble(self, Gs, Gf, Gt) -> np.ndarray:
        """``J_i^H (S (x) F (x) T) J_j`` (T, 7L, 7L) from the modes' matrices (complex)."""
        for name, G, own in zip(("Gs", "Gf", "Gt"), (Gs, Gf, Gt), (self.X, self.F2, self.T2)):
            finite_array(name, G, dtype=complex, shape=(own.shape[0], own.shape[2], own.shape[2]))
        si, fi, ti = self.si, self.fi, self.ti
        return (
            np.conj(self.coef)[:, :, None]
            * self.coef[:, None, :]
            * Gs[:, si[:, None], si[None, :]]
            * Gf[:, fi[:, None], fi[None, :]]
            * Gt[:, ti[:, None], ti[None, :]]
        )

    def fim(self, noise_power: float) -> np.ndarray:
        """``A = (2 / sigma^2) Re J^H J`` (T, 7L, 7L)."""
        positive("noise_power", noise_power)
        return 2.0 / noise_power * self.assemble(*self.grams).real

    def calibration_scores(self) -> np.ndarray:
        """``J^H (e_m (x) H_m)`` (T, 7L, M) complex: the inner products of ``J`` with element
        ``m``'s received noiseless tensor (a unit phase error is ``j`` times it, a unit dB gain
        error ``ln 10 / 20`` times it)."""
        _, Gf, Gt = self.grams
        L = self.alpha.shape[1]
        col = 2 * np.arange(L)  # the plain atoms f_l, t_l
        W = self.alpha[:, None, :] * Gf[:, self.fi][:, :, col] * Gt[:, self.ti][:, :, col]
        Hm = _mm(W, self.a.transpose(0, 2, 1))  # sum_l (...) alpha_l a_lm: (T, 7L, M)
        Xs = np.conj(self.X[:, :, self.si]).transpose(0, 2, 1)  # (T, 7L, M)
        return np.conj(self.coef)[:, :, None] * Xs * Hm

    def diffuse_gram(self, spec: DiffuseSpec, tone_spacing: float, tau0) -> np.ndarray:
        """``J^H C_D J / P_D`` (T, 7L, 7L) complex for unit diffuse power starting at delay
        ``tau0`` (T,) [s] (docs/internals)."""
        instance("spec", spec, DiffuseSpec), tone_step("tone_spacing", tone_spacing)
        finite_array("tau0", tau0, shape=(self.X.shape[0],))
        _, w = spec.taps(tone_spacing, self.n_tones)
        n_fft = spec.oversample * self.n_tones
        ph = np.exp(-2j * np.pi * tone_spacing * np.arange(self.n_tones)[None, :] * tau0[:, None])
        Q = np.fft.fft(np.conj(self.F2) * ph[:, :, None], n=n_fft, axis=1)[:, : w.size]  # (T,P,2L)
        Gf = _mm(Q.transpose(0, 2, 1) * w, np.conj(Q))  # sum_p w_p Q[c, p] conj(Q[c', p])
        st = self.T2.sum(axis=1)  # (T, 2L)
        Gt = np.conj(st)[:, :, None] * st[:, None, :]
        return self.assemble(self.grams[0], Gf, Gt)
