"""Fisher information and Cramer-Rao bounds for joint TOA/DOA positioning (Jiang et al. 2023).

Measurement model (Jiang eq. 5 and 11): from station ``i`` at ``(x_i, y_i)`` (the base station
itself in LOS, or a virtual station),

    d_i     = sqrt((x - x_i)^2 + (y - y_i)^2)          range,   noise sigma_d
    theta_i = atan2(y - y_i, x - x_i)                   bearing, noise sigma_theta

The Fisher information of the position is ``F = sum_i grad(theta_i) grad(theta_i)^T / sigma_theta^2
+ grad(d_i) grad(d_i)^T / sigma_d^2`` (eq. 20-27) and the bound on the position MSE is
``tr(F^-1)`` (eq. 28 / A17).

**Correction.** ``d theta_i / d x = -(y - y_i) / d_i^2`` (the paper's eq. A2 drops the minus sign),
so the angle part of ``F_xy`` is ``-(x - x_i)(y - y_i) / (sigma_theta^2 d_i^4)``; the paper's
eq. 27 / A16 prints ``+``. :func:`fim_toa_doa` implements the corrected form by default and the
printed one with ``form="paper"``; :func:`numeric_fim` is the brute-force twin both are tested
against.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ._domains import spd_matrix
from ._physical import MIN_SIGMA
from ._validate import callable_, finite_array, integer, positive, text
from .angles import wrap_angle, wrap_angle_unchecked
from .budget import check_elements

__all__ = [
    "crlb_rmse",
    "crlb_trace",
    "fim_toa_doa",
    "numeric_fim",
    "numeric_jacobian",
    "station_sigmas",
    "toa_doa",
    "toa_doa_jacobian",
    "wrap_angle",
]


def _points_and_stations(p, stations) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    p = finite_array("p", p)
    st = finite_array("stations", stations, ndim=2)
    if p.ndim == 0 or p.shape[-1] != 2:
        raise ValueError(f"p: expected 2-D position(s) with shape (..., 2), got {p.shape}")
    if st.shape[1] != 2 or st.shape[0] < 1:
        raise ValueError(f"stations: expected shape (N, 2) with N >= 1, got {st.shape}")
    dx = p[..., None, 0] - st[:, 0]
    dy = p[..., None, 1] - st[:, 1]
    d2 = dx * dx + dy * dy
    if d2.size:  # a station closer than 1e-12 of the largest coordinate (at least 1 m)
        scale = max(float(p.max()), -float(p.min()), float(st.max()), -float(st.min()), 1.0)
        if d2.min() <= (1e-12 * scale) ** 2:
            raise ValueError("p: coincides with a station, range and bearing are undefined there")
    return p, st, dx, dy


def toa_doa(p, stations) -> tuple[np.ndarray, np.ndarray]:
    """Ranges ``d`` and bearings ``theta`` from each station to ``p`` (Jiang eq. 5, 11).

    ``p`` has shape (..., 2), ``stations`` (N, 2); both outputs have shape (..., N).
    """
    _, _, dx, dy = _points_and_stations(p, stations)
    return np.hypot(dx, dy), np.arctan2(dy, dx)


def toa_doa_jacobian(p, stations) -> np.ndarray:
    """Analytic Jacobian of ``[d_1..d_N, theta_1..theta_N]`` w.r.t. ``(x, y)``: shape (..., 2N, 2).

    ``dd/dx = (x - x_i)/d``, ``dd/dy = (y - y_i)/d``, ``dtheta/dx = -(y - y_i)/d^2``,
    ``dtheta/dy = (x - x_i)/d^2`` (Jiang eq. A2-A3, A8-A9 with the sign of A2 corrected).
    """
    _, _, dx, dy = _points_and_stations(p, stations)
    d2 = dx * dx + dy * dy
    d = np.sqrt(d2)
    jd = np.stack([dx / d, dy / d], axis=-1)
    jt = np.stack([-dy / d2, dx / d2], axis=-1)
    return np.concatenate([jd, jt], axis=-2)


def station_sigmas(name: str, sigma, n: int) -> np.ndarray | None:
    """Noise level ``sigma`` as one value per station, shape (n,); ``None`` stays ``None``.

    ``sigma`` is a scalar or one value per station (shape (1,) or (n,)), every value finite and
    > 0; ``None`` leaves that measurement type out. Errors name the parameter ``name``.
    """
    n = integer("n", n, minimum=1)
    check_elements("n", n, what=f"{n} stations' sigmas")
    name = text("name", name)
    if sigma is None:
        return None
    s = finite_array(name, sigma)
    if s.ndim > 1 or (s.ndim == 1 and s.shape[0] not in (1, n)):
        raise ValueError(
            f"{name}: expected a scalar or one value per station ({n}), got shape {s.shape}"
        )
    if np.any(s <= 0):
        raise ValueError(f"{name}: must be > 0 (use None to leave this measurement out), got {s}")
    if np.any(s < MIN_SIGMA):
        raise ValueError(
            f"{name}: {float(s.min()):g} is below {MIN_SIGMA:g} (no measurement is that precise; "
            "its information would overflow)"
        )
    return np.broadcast_to(s, (n,)).astype(float)


def fim_toa_doa(p, stations, sigma_theta, sigma_d, *, form: str = "corrected") -> np.ndarray:
    """Fisher information of the position, shape (..., 2, 2) (Jiang eq. 20-27).

    ``sigma_theta`` [rad] and ``sigma_d`` [m] are scalars or one value per station; pass ``None``
    for either to drop that measurement (TOA-only or DOA-only). ``form="paper"`` reproduces the
    printed eq. 27 with its ``+`` sign on the angle term of ``F_xy``, for comparison only.
    """
    if form not in ("corrected", "paper"):
        raise ValueError(f"form: expected 'corrected' or 'paper', got {form!r}")
    _, st, dx, dy = _points_and_stations(p, stations)
    n = st.shape[0]
    st_ = station_sigmas("sigma_theta", sigma_theta, n)
    sd_ = station_sigmas("sigma_d", sigma_d, n)
    if st_ is None and sd_ is None:
        raise ValueError("sigma_theta, sigma_d: at least one measurement type is needed")
    d2 = dx * dx + dy * dy
    fxx = np.zeros(dx.shape[:-1])
    fyy = np.zeros_like(fxx)
    fxy = np.zeros_like(fxx)
    if st_ is not None:
        w = 1.0 / (st_**2 * d2 * d2)
        sign = -1.0 if form == "corrected" else 1.0
        fxx = fxx + np.sum(w * dy * dy, axis=-1)
        fyy = fyy + np.sum(w * dx * dx, axis=-1)
        fxy = fxy + sign * np.sum(w * dx * dy, axis=-1)
    if sd_ is not None:
        w = 1.0 / (sd_**2 * d2)
        fxx = fxx + np.sum(w * dx * dx, axis=-1)
        fyy = fyy + np.sum(w * dy * dy, axis=-1)
        fxy = fxy + np.sum(w * dx * dy, axis=-1)
    return np.stack([np.stack([fxx, fxy], -1), np.stack([fxy, fyy], -1)], -2)


def numeric_jacobian(
    h: Callable[[np.ndarray], np.ndarray], p, *, step: float = 1e-6, angle_mask=None
) -> np.ndarray:
    """Central-difference Jacobian of a vectorised ``h: (..., n) -> (..., m)``: shape (..., m, n).

    Components flagged in ``angle_mask`` (bool, length m) have their differences wrapped to
    ``(-pi, pi]`` so a bearing crossing the branch cut does not explode.
    """
    callable_("h", h)
    p = finite_array("p", p)
    step = positive("step", step)
    if p.ndim == 0:
        raise ValueError("p: expected a point (..., n), got a scalar")
    if angle_mask is not None:
        mask = np.asarray(angle_mask)
        if mask.dtype.kind != "b" or mask.ndim != 1:
            raise TypeError(f"angle_mask: expected a 1-D array of booleans, got {angle_mask!r:.40}")
    n = p.shape[-1]
    cols = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = step
        try:
            diff = np.asarray(h(p + e), dtype=float) - np.asarray(h(p - e), dtype=float)
        except (IndexError, ValueError, TypeError) as exc:
            raise ValueError(
                f"h: fails on p of shape {p.shape} ({type(exc).__name__}: {exc})"
            ) from None
        if angle_mask is not None:
            diff = np.where(mask, wrap_angle_unchecked(diff), diff)
        cols.append(diff / (2.0 * step))
    J = np.stack(cols, axis=-1)
    if not np.isfinite(J).all():
        raise ValueError("h: returned NaN or infinite values near p (no finite derivative)")
    return J


def numeric_fim(
    h: Callable[[np.ndarray], np.ndarray], p, R, *, step: float = 1e-6, angle_mask=None
) -> np.ndarray:
    """Brute-force Fisher information ``J^T R^-1 J`` for Gaussian noise of covariance ``R``.

    ``J`` is the central-difference Jacobian of ``h`` at ``p``; works for any measurement
    function, so every closed-form FIM in the package has a numeric twin.
    """
    R = finite_array("R", R, ndim=2)
    if R.shape[0] != R.shape[1]:
        raise ValueError(f"R: must be square, got {R.shape}")
    R = spd_matrix("R", R)
    J = numeric_jacobian(h, p, step=step, angle_mask=angle_mask)
    if J.shape[-2] != R.shape[0]:
        raise ValueError(f"R: has size {R.shape[0]} but h returns {J.shape[-2]} measurements")
    return np.swapaxes(J, -1, -2) @ np.linalg.solve(R, J)


def crlb_trace(F) -> np.ndarray:
    """``tr(F^-1)``, the bound on the position mean-square error (Jiang eq. 28 / A17)."""
    F = finite_array("F", F)
    if F.ndim < 2 or F.shape[-1] != F.shape[-2]:
        raise ValueError(f"F: expected square matrices (..., n, n), got {F.shape}")
    scale = float(np.max(np.abs(F))) if F.size else 0.0
    if np.max(np.abs(F - np.swapaxes(F, -1, -2)), initial=0.0) > 1e-9 * scale:
        raise ValueError("F: a Fisher information matrix must be symmetric")
    bad = (
        "F: singular or not positive definite Fisher information, the position is not identifiable"
    )
    if F.shape[-1] == 2:  # closed form of eq. A17, no inverse needed
        det = F[..., 0, 0] * F[..., 1, 1] - F[..., 0, 1] * F[..., 1, 0]
        if np.any(det <= 0) or np.any(F[..., 0, 0] <= 0):
            raise ValueError(bad)
        with np.errstate(over="ignore"):
            out = (F[..., 0, 0] + F[..., 1, 1]) / det
    else:
        ev = np.linalg.eigvalsh(F)
        if np.any(ev <= 0):
            raise ValueError(bad)
        with np.errstate(over="ignore", divide="ignore"):
            out = np.sum(1.0 / ev, axis=-1)
    if not np.all(np.isfinite(out)):  # an information so small its inverse overflows
        raise ValueError(bad.replace("singular", "numerically singular (the bound overflows)"))
    return out


def crlb_rmse(p, stations, sigma_theta, sigma_d) -> np.ndarray:
    """``sqrt(tr(F^-1))`` [m]: the smallest RMSE an unbiased estimator can reach at ``p``."""
    return np.sqrt(crlb_trace(fim_toa_doa(p, stations, sigma_theta, sigma_d)))
