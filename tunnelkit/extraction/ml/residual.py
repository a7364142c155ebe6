"""The residual test of the maximum-likelihood stage: the largest peak of the residual's
single-path periodogram against its noise-only distribution (:func:`residual_peak`,
:func:`peak_threshold`).

At the maximum-likelihood estimate of the right model the residual ``r = P_perp h`` is noise
(less ``5 L`` of its ``2 N`` real dimensions). Its single-path periodogram

    P(u, mu_f, mu_t) = |<x(u, mu_f, mu_t), r>|^2 / (N sigma^2),   x = a_far(u) o f(mu_f) o t(mu_t),

(``||x||^2 = N``, far-field steering vector ``a_far``) is then exponential with mean 1 at every
point; the ``N = M Nf Nt`` points of the DFT grid are independent, so the largest of them exceeds
``t`` with probability ``1 - (1 - e^{-t})^N ~ N e^{-t}``. A path the search missed, two paths
fitted as one, or a path in a wrong basin (a few standard deviations or more from its maximum of
the likelihood) leave a structured residual whose periodogram peaks far above that: ``c_l``
times the difference of two atoms puts a share of its energy, thousands of noise powers in the
failures this test was built on, into one beam, delay and Doppler cell. The total residual energy
(``rho``) spreads the same energy over ``N`` dimensions and misses it.

The peak is sought on a grid oversampled twice in delay and Doppler (FFT), the ``n_cells``
delay-Doppler cells with the most spatial energy, and for each of them the far-field beam scan
of :func:`tunnelkit.extraction.numerics.scan_peak` (a beam an eighth of a beamwidth apart or
closer); the oversampled maximum runs above the maximum over the ``N`` independent grid points,
so the threshold takes ``OVERSAMPLING_CELLS`` times more cells (calibrated on noise-only
tensors in the tests: the false-alarm rate stays below the stated one).
"""

from __future__ import annotations

import numpy as np
import scipy.fft

from ..._validate import integer, positive
from ..numerics import scan_grid

__all__ = ["FALSE_ALARM", "OVERSAMPLING_CELLS", "peak_threshold", "residual_peak"]

#: false-alarm rate of the residual test on a right fit (per snapshot)
FALSE_ALARM = 0.01
#: effective independent cells per grid point of the oversampled search (noise-only calibration)
OVERSAMPLING_CELLS = 16.0


def peak_threshold(n_samples: int, false_alarm: float = FALSE_ALARM) -> float:
    """The threshold ``t`` on the largest normalised periodogram peak (:func:`residual_peak`)
    exceeded by noise alone with probability ``false_alarm``: ``P(max > t) = 1 - (1 -
    e^{-t})^K = false_alarm`` with ``K = OVERSAMPLING_CELLS * n_samples`` cells."""
    n = integer("n_samples", n_samples, minimum=1)
    pfa = positive("false_alarm", false_alarm)
    if pfa >= 1.0:
        raise ValueError(f"false_alarm: expected a probability below 1, got {pfa}")
    K = OVERSAMPLING_CELLS * n
    return float(-np.log(-np.expm1(np.log1p(-pfa) / K)))


def residual_peak(R, element_positions, fc: float, noise_power: float, *, n_cells: int = 8):
    """Largest peak of the single-path periodogram of the residual ``R`` (M, Nf, Nt) in units of
    the noise power (exponential with mean 1 per point under noise) and where it lies.

    Returns ``(peak, (u_x, u_y, mu_f, mu_t), x)``: the peak, its far-field direction cosines and
    Vandermonde frequencies, and the spatial vector ``x`` (M,) of its delay-Doppler cell (a
    start for a single-source fit). ``element_positions`` (M, 3) local, ``fc`` the carrier.
    """
    R = np.asarray(R)
    if R.ndim != 3 or not np.iscomplexobj(R):
        raise ValueError(f"R: expected a complex (M, Nf, Nt) tensor, got {R.dtype} {R.shape}")
    p = np.ascontiguousarray(element_positions, float)
    if p.ndim != 2 or p.shape != (R.shape[0], 3):
        raise ValueError(f"element_positions: expected shape ({R.shape[0]}, 3), got {p.shape}")
    fc = positive("fc", fc)
    sigma2 = positive("noise_power", noise_power)
    n_cells = integer("n_cells", n_cells, minimum=1)
    M, nf, nt = R.shape
    nf2, nt2 = 2 * nf, 2 * nt
    # <f(mu) o t(nu), R[m]> = sum_s,k R conj(e^{j s mu} e^{j k nu}): the FFT at mu = 2 pi i / nf2
    Y = scipy.fft.fft2(R.astype(np.complex64), s=(nf2, nt2), axes=(1, 2), workers=1)
    E = np.einsum("mij,mij->ij", Y.real, Y.real) + np.einsum("mij,mij->ij", Y.imag, Y.imag)
    top = np.argpartition(E.ravel(), -n_cells)[-n_cells:]
    u, A = scan_grid(p, fc)
    X = Y.reshape(M, -1)[:, top].astype(complex)  # (M, n_cells)
    S = np.abs(A.conj().T @ X) ** 2  # (G, n_cells)
    g, c = np.unravel_index(int(np.argmax(S)), S.shape)
    i, j = np.unravel_index(int(top[c]), E.shape)
    peak = float(S[g, c] / (R.size * sigma2))
    mu_f = float(np.angle(np.exp(2j * np.pi * i / nf2)))
    mu_t = float(np.angle(np.exp(2j * np.pi * j / nt2)))
    return peak, (float(u[g, 0]), float(u[g, 1]), mu_f, mu_t), X[:, c]
