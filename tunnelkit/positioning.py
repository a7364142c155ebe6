"""Snapshot positioning from TOA/DOA of virtual stations (Jiang et al. 2023, section 3.2 and 4.1).

Each station ``i`` (the base station in LOS, or a virtual station) gives a range ``d_i`` and a
bearing ``theta_i``. Eq. 10 and 12 turn them into the pseudo-linear system ``H = G Z + N``
(eq. 13-17) with ``Z = [x, y, x^2 + y^2]``:

    rows 1..N  :  d_i^2 - x_i^2 - y_i^2       = -2 x_i x - 2 y_i y + (x^2 + y^2)
    rows N+1.. :  x_i sin(theta_i) - y_i cos(theta_i) = x sin(theta_i) - y cos(theta_i)

:func:`ls_toa_doa` solves it by ordinary least squares; :func:`tswls` is the two-stage weighted
least squares of eq. 29-39. Everything is vectorised over leading axes of ``d_hat`` and
``theta_hat`` so 2,000 Monte-Carlo trials are one call.
"""

from __future__ import annotations

import numpy as np

from ._domains import distinct_points
from ._physical import MAX_RANGE_M
from ._validate import finite_array, integer, rng_or_error
from .budget import check_elements
from .crlb import station_sigmas, toa_doa

__all__ = ["ls_toa_doa", "simulate_toa_doa", "toa_only_candidates", "tswls"]


_SINGULAR = (
    "stations, d_hat, theta_hat: the stations and measurements leave the position undetermined "
    "(singular least-squares system)"
)


def _inputs(stations, d_hat, theta_hat):
    # one station (or several at one place) gives 2 equations for 3 unknowns: no fix at all
    st = distinct_points("stations", stations, dim=2, minimum=2, atol=1e-9)
    d = finite_array("d_hat", d_hat)
    th = finite_array("theta_hat", theta_hat)
    n = st.shape[0]
    if d.ndim == 0 or d.shape[-1] != n:
        raise ValueError(
            f"d_hat: expected one range per station ({n}) in the last axis, got {d.shape}"
        )
    if th.shape != d.shape:
        raise ValueError(f"theta_hat: shape {th.shape} does not match d_hat {d.shape}")
    if np.any(d <= 0):
        raise ValueError("d_hat: ranges must be > 0")
    if np.any(d > MAX_RANGE_M):
        raise ValueError(f"d_hat: ranges up to {MAX_RANGE_M:g} m, got {float(d.max()):g}")
    return st, d, th


def _linear_system(st, d, th):
    """``G`` (..., 2N, 3) and ``H`` (..., 2N) of eq. 14-15."""
    s, c = np.sin(th), np.cos(th)
    xi, yi = st[:, 0], st[:, 1]
    shape = d.shape
    g_toa = np.stack(np.broadcast_arrays(-2 * xi, -2 * yi, np.ones_like(xi)), axis=-1)
    g_toa = np.broadcast_to(g_toa, (*shape, 3))
    g_doa = np.stack([s, -c, np.zeros_like(s)], axis=-1)
    G = np.concatenate([g_toa, g_doa], axis=-2)
    H = np.concatenate([d**2 - xi**2 - yi**2, xi * s - yi * c], axis=-1)
    return G, H


def _wls(G, H, w_inv_diag):
    """Batched weighted LS with a diagonal weight: returns (Z, cov(Z)=(G^T W^-1 G)^-1)."""
    GtW = np.swapaxes(G, -1, -2) * w_inv_diag[..., None, :]
    A = GtW @ G
    b = np.einsum("...ij,...j->...i", GtW, H)
    # numerically singular without being exactly so (e.g. stations 1e-253 m apart, or every
    # bearing 1e-103 rad from the axis): the inverse then overflows instead of raising
    with np.errstate(all="ignore"):
        well_posed = np.all(np.linalg.cond(A) < 1.0 / np.finfo(float).eps)
    if not well_posed:
        raise ValueError(_SINGULAR)
    A_inv = np.linalg.inv(A)
    return np.einsum("...ij,...j->...i", A_inv, b), A_inv


def ls_toa_doa(stations, d_hat, theta_hat) -> np.ndarray:
    """Ordinary least-squares solution of eq. 13 (no weighting); returns positions (..., 2)."""
    st, d, th = _inputs(stations, d_hat, theta_hat)
    G, H = _linear_system(st, d, th)
    Z, _ = _wls(G, H, np.ones(H.shape))
    return Z[..., :2]


def tswls(stations, d_hat, theta_hat, sigma_d, sigma_theta) -> np.ndarray:
    """Two-stage weighted least squares (Jiang eq. 29-39); returns positions (..., 2).

    Stage 1 (eq. 30-32): WLS of eq. 13 with ``W = B Q B``, ``B = diag(2 d_hat, d_hat)`` built from
    the measured ranges. Stage 2 (eq. 33-38): impose ``Z_3 = Z_1^2 + Z_2^2`` by WLS on the
    squares with ``W_1 = 4 B_1 cov(Z) B_1``; eq. 39 restores the signs from stage 1.

    Where stage 2 is undefined (a coordinate estimate of zero makes ``W_1`` singular, or the
    squared estimate is negative) the stage-1 coordinate is kept, never NaN.
    """
    st, d, th = _inputs(stations, d_hat, theta_hat)
    n = st.shape[0]
    sd = station_sigmas("sigma_d", sigma_d, n)
    sth = station_sigmas("sigma_theta", sigma_theta, n)
    if sd is None or sth is None:
        raise ValueError("sigma_d, sigma_theta: TSWLS needs both noise levels")
    G, H = _linear_system(st, d, th)
    w_diag = np.concatenate([(2 * d * sd) ** 2, (d * sth) ** 2], axis=-1)  # diag(B Q B), eq. 31-32
    Z, covZ = _wls(G, H, 1.0 / w_diag)
    xy = Z[..., :2]
    # stage 2
    B1 = np.concatenate([xy, np.full((*xy.shape[:-1], 1), 0.5)], axis=-1)
    W1 = 4.0 * B1[..., :, None] * covZ * B1[..., None, :]
    G1 = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    H1 = np.concatenate([xy**2, Z[..., 2:3]], axis=-1)
    scale = np.maximum(np.abs(xy).max(axis=-1), 1.0)
    ok = np.all(np.abs(xy) > 1e-6 * scale[..., None], axis=-1)
    W1 = np.where(ok[..., None, None], W1, np.eye(3))
    try:
        W1_inv = np.linalg.inv(W1)
        A = G1.T @ W1_inv @ G1
        b = np.einsum("ij,...jk,...k->...i", G1.T, W1_inv, H1)
        Z1 = np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        raise ValueError(_SINGULAR) from None
    ok2 = ok[..., None] & (Z1 >= 0)
    refined = np.sign(xy) * np.sqrt(np.where(ok2, Z1, 0.0))
    return np.where(ok2, refined, xy)


def simulate_toa_doa(
    p, stations, sigma_theta, sigma_d, rng: np.random.Generator, size: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Noisy ranges and bearings at position(s) ``p`` (Jiang eq. 1-2, 8, 11).

    Returns ``(d_hat, theta_hat)``; with ``size`` a leading axis of that many independent trials.
    """
    rng = rng_or_error("rng", rng)
    d, th = toa_doa(p, stations)
    n = d.shape[-1]
    sd = station_sigmas("sigma_d", sigma_d, n)
    sth = station_sigmas("sigma_theta", sigma_theta, n)
    if sd is None or sth is None:
        raise ValueError("sigma_d, sigma_theta: both noise levels are needed to simulate")
    shape = d.shape if size is None else (integer("size", size, minimum=1), *d.shape)
    check_elements(
        "size", 4 * int(np.prod(shape, dtype=object)), what="the noisy ranges and bearings"
    )
    d_hat = d + sd * rng.standard_normal(shape)
    th_hat = th + sth * rng.standard_normal(shape)
    return d_hat, th_hat


def toa_only_candidates(stations, d_hat) -> np.ndarray:
    """Both intersections of the first two range circles: shape (..., 2, 2).

    With TOA alone two stations give two candidate positions, mirror images in the line through
    the stations; in a tunnel with walls parallel to its axis all virtual stations lie on one
    line, so TOA alone never resolves this mirror ambiguity (DOA does).
    """
    st = finite_array("stations", stations, ndim=2)
    if st.shape[0] < 2 or st.shape[1] != 2:
        raise ValueError(f"stations: need at least two 2-D stations, got {st.shape}")
    d = finite_array("d_hat", d_hat)
    if d.ndim == 0 or d.shape[-1] < 2:
        raise ValueError("d_hat: need at least two ranges in the last axis")
    p0, p1 = st[0], st[1]
    base = float(np.linalg.norm(p1 - p0))
    if base == 0:
        raise ValueError("stations: the first two stations coincide")
    if d.min() < 0:
        raise ValueError(f"d_hat: ranges must be >= 0, got {float(d.min())}")
    r0, r1 = d[..., 0], d[..., 1]
    a = (r0**2 - r1**2 + base**2) / (2 * base)
    h2 = r0**2 - a**2
    if np.any(h2 < 0):
        raise ValueError("d_hat: the range circles do not intersect (inconsistent ranges)")
    h = np.sqrt(h2)
    u = (p1 - p0) / base
    v = np.array([-u[1], u[0]])
    mid = p0 + a[..., None] * u
    return np.stack([mid + h[..., None] * v, mid - h[..., None] * v], axis=-2)
