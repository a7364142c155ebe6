"""The result of an extraction: per-path estimates in one container, whatever the route."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["PathEstimates", "path_estimates"]


@dataclass(frozen=True)
class PathEstimates:
    """Per-path estimates from one tensor, sorted by ``d`` (earliest first).

    ``alpha`` complex gain (eq. 12, refined), ``d`` distance ``c tau`` including the clock bias [m]
    (eq. 14), ``v`` relative velocity ``c f_d / fc`` [m/s] (eq. 15), ``direction`` (L, 3) unit
    vectors of arrival in the array's local frame, ``kappa`` wavefront radius [m] (NaN when
    far-field), ``near_field`` (bool), ``phi``/``psi`` local azimuth and polar angle (eq. 19
    convention), ``valid`` = Algorithm 1 keeps the path (``d >= 0``), ``kappa_nf`` the raw TLS
    value, ``delta`` (L, M) unwrapped path-length offsets (eq. 16), ``mu_f``/``mu_t`` the roots.
    ``fit`` holds the maximum-likelihood stage's :class:`~tunnelkit.extraction.ml.MLFit` (noise
    power, basin test) on that route, ``None`` on the others; ``significance`` each path's
    log-likelihood ratio against noise on that route (sorted like the rest), ``None`` elsewhere;
    ``fit_ok`` the ML stage's verdict on its own fit (``MLFit.fit_ok``: no structured residual
    left, every path above the noise, every two paths resolved; ``fit.reason`` names a failed
    test), ``None`` on the routes that do not test themselves.
    """

    alpha: np.ndarray
    d: np.ndarray
    v: np.ndarray
    direction: np.ndarray
    kappa: np.ndarray
    near_field: np.ndarray
    phi: np.ndarray
    psi: np.ndarray
    valid: np.ndarray
    kappa_nf: np.ndarray
    delta: np.ndarray = field(repr=False)
    mu_f: np.ndarray = field(repr=False)
    mu_t: np.ndarray = field(repr=False)
    factors: tuple = field(repr=False)
    rel_error: float = 0.0
    n_iter: int = 0
    converged: bool = True
    fit: object = field(default=None, repr=False)
    significance: np.ndarray | None = field(default=None, repr=False)
    fit_ok: bool | None = None

    def __len__(self) -> int:
        return self.d.shape[0]

    def __getitem__(self, key: str):
        return getattr(self, key)

    def wave_origins(self) -> np.ndarray:
        """``kappa * direction`` (L, 3) in the local frame (NaN rows for far-field paths)."""
        return self.kappa[:, None] * self.direction


def path_estimates(
    alpha, d, v, ang: dict, near, delta, mu_f, mu_t, factors, rel_error, n_iter, converged
) -> PathEstimates:
    """Assemble :class:`PathEstimates` sorted by ``d``: near-field paths take the eq. 19-21
    angles and curvature of ``ang`` (:func:`angles_from_solution`), the others the far-field
    ones (``kappa`` NaN); ``delta`` is (L, M), ``factors`` the three (., L) factor matrices."""
    direction = np.where(near[:, None], ang["dir_nf"], ang["dir_ff"])
    kappa = np.where(near, ang["kappa_nf"], np.nan)
    phi = np.where(near, ang["phi_nf"], ang["phi_ff"])
    psi = np.where(near, ang["psi_nf"], ang["psi_ff"])
    o = np.argsort(d)
    return PathEstimates(
        alpha[o],
        d[o],
        v[o],
        direction[o],
        kappa[o],
        near[o],
        phi[o],
        psi[o],
        d[o] >= 0,
        ang["kappa_nf"][o],
        delta[o],
        mu_f[o],
        mu_t[o],
        tuple(B[:, o] for B in factors),
        rel_error,
        n_iter,
        converged,
    )
