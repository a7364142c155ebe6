"""The exact SR-NF phase mismatch, no expansion, and the largest array that keeps it small.

:func:`mismatch_profile`, :func:`phase_mismatch` (ULA) and :func:`phase_mismatch_ura` (the URA of
section 4.1) evaluate the exact mismatch of each antenna
(:func:`~tunnelkit.fresnel.mismatch.signed_mismatch`) in the theorem's geometry; the
brute-force searches :func:`mmax_exact`, :func:`mmax_exact_grid` and :func:`mmax_exact_ura` find
the largest admissible array, starting from the second-order guess of
:mod:`tunnelkit.fresnel.bounds`. :func:`aperture_profile` lays the proof of Theorem 3.1 out term
by term, exact beside the expansions.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass

import numpy as np

from .._physical import carrier
from .._validate import integer, record
from ..budget import check_elements
from ..constants import C, wavelength
from .bounds import (
    SECTION_4_1_TILT,
    carrier_tolerance,
    reference_specular_point,
    second_order_mmax,
    ula_positions,
    ura_positions,
    vue,
    wall_geometry,
)
from .mismatch import path_difference, real_input, signed_mismatch

__all__ = [
    "M_LIMIT",
    "M_LIMIT_URA",
    "ApertureProfile",
    "aperture_profile",
    "mismatch_profile",
    "mmax_exact",
    "mmax_exact_grid",
    "mmax_exact_ura",
    "phase_mismatch",
    "phase_mismatch_ura",
]

#: the exact search stops here (an array this long is kilometres wide; see mmax_exact)
M_LIMIT = 2**20
#: the exact M x M URA search stops here by default
M_LIMIT_URA = 1024

# exact mismatch


def _delta_ula(src: np.ndarray, y: np.ndarray) -> np.ndarray:
    """:func:`~tunnelkit.fresnel.mismatch.path_difference` for antennas on the y axis,
    ``p = (0, y, 0)``; ``src`` (n, 3), ``y`` (n, K)."""
    sx2z2 = (src[:, 0] ** 2 + src[:, 2] ** 2)[:, None]
    sy = src[:, 1][:, None]
    return (y * y - 2.0 * sy * y) / (np.sqrt(sx2z2 + (sy - y) ** 2) + np.sqrt(sx2z2 + sy * sy))


def _mismatch_ula(pv: np.ndarray, ps: np.ndarray, y: np.ndarray, lam) -> np.ndarray:
    """:func:`signed_mismatch` for a ULA along y (rows of geometries ``pv, ps`` (n, 3), ``y`` (n, K))."""
    return (2.0 * np.pi / lam) * (_delta_ula(pv, y) - _delta_ula(ps, y))


def mismatch_profile(positions, R, W, y_u, fc, *, z_u=0.0) -> np.ndarray:
    """Exact signed phase mismatch [rad] at each antenna, no expansion (eq. 26-33 exactly).

    ``delta*_m = |p_v - p_m| - |p_v|`` is the true reflected path length via the VUE minus the
    reference antenna's (eq. 26-27); ``delta^SR_m = |p_s0 - p_m| - |p_s0|`` is the SR-NF model's,
    with the reflector fixed at the reference antenna's specular point (eq. 29-30, 32). Returns
    ``2 pi / lambda (delta*_m - delta^SR_m)`` with the shape of ``positions[..., 0]``.
    ``positions`` are antenna coordinates (..., 3) [m] relative to the reference antenna.
    """
    pos = real_input("positions", positions)
    if pos.ndim == 0 or pos.shape[-1] != 3:
        raise ValueError(
            f"positions: expected 3 coordinates in the last axis, got shape {pos.shape}"
        )
    lam = wavelength(fc)
    R, W, y_u, z_u = (
        float(v)
        for v in (
            real_input("R", R),
            real_input("W", W),
            real_input("y_u", y_u),
            real_input("z_u", z_u),
        )
    )
    pv = vue(R, W, y_u, z_u)
    ps = reference_specular_point(R, W, y_u, z_u)
    return signed_mismatch(pv, ps, pos, lam)


def phase_mismatch(M: int, R: float, W: float, y_u: float, fc: float, *, z_u: float = 0.0) -> float:
    """Largest exact ``|2 pi / lambda (delta*_m - delta^SR_m)|`` [rad] over an ``M``-element ULA.

    The ULA of Theorem 3.1 (along y, spacing ``lambda/2``, reference antenna at the origin); the
    left-hand side of the phase constraint above eq. 34, computed from eq. 26-27 and 29-30/32
    without the Fresnel expansions eq. 28 and eq. 31. ``z_u`` (default 0, the 2-D theorem) puts
    the UE above/below the array plane.
    """
    M = integer("M", M, minimum=2)
    wall_geometry(R, W, y_u, z_u)
    fc = real_input("fc", carrier("fc", fc))
    return float(
        np.max(np.abs(mismatch_profile(ula_positions(M, float(fc)), R, W, y_u, fc, z_u=z_u)))
    )


def phase_mismatch_ura(
    M: int,
    R: float,
    W: float,
    y_u: float,
    fc: float,
    *,
    z_u: float = 0.0,
    N: int | None = None,
    tilt: float = SECTION_4_1_TILT,
) -> float:
    """Largest exact phase mismatch [rad] over the ``M x N`` URA of section 4.1.

    The 3-D counterpart of :func:`phase_mismatch` (Theorem 3.4's setting): UE at
    ``(R, y_u, z_u)``, wall ``y = W``, array from :func:`ura_positions`.
    """
    M = integer("M", M, minimum=2)
    wall_geometry(R, W, y_u, z_u)
    fc = real_input("fc", carrier("fc", fc))
    pos = ura_positions(M, float(fc), N=N, tilt=tilt)
    return float(np.max(np.abs(mismatch_profile(pos, R, W, y_u, fc, z_u=z_u))))


# ---------------------------------------------------------------------------------------------
# exact Mmax


def _first_exceed(phase_abs: np.ndarray, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row: whether ``phase_abs`` ever exceeds ``eps`` and the first index where it does."""
    over = phase_abs > eps[:, None]
    return over.any(axis=1), over.argmax(axis=1)


def _mmax_exact_flat(R, W, y_u, z_u, lam, eps, m_limit: int) -> np.ndarray:
    """Exact Mmax for flat arrays of geometries (ULA along y), chunked and doubling."""
    n = R.size
    out = np.zeros(n, dtype=np.int64)
    a = 2.0 * W - y_u
    pv = np.stack([R, a, z_u], axis=-1)
    ps = pv * (W / a)[:, None]
    guess = second_order_mmax(R, W, y_u, z_u, lam, eps)
    need = np.clip(np.ceil(1.25 * guess) + 8, 32, m_limit).astype(np.int64)
    order = np.argsort(need, kind="stable")
    budget = 2_000_000  # antenna-geometry pairs evaluated per block
    start = 0
    while start < n:
        # a block of rows with similar guesses (sorted), at most `budget` pairs
        stop = start + 1
        while stop < n and (stop + 1 - start) * need[order[stop]] <= budget:
            stop += 1
        rows = order[start:stop]
        K = int(need[rows[-1]])
        while rows.size:
            check_elements(
                "m_limit", rows.size * K, 80, f"the exact search up to M = {K} (10 temporaries)"
            )
            y = np.arange(K) * (lam[rows] / 2.0)[:, None]
            ph = np.abs(_mismatch_ula(pv[rows], ps[rows], y, lam[rows, None]))
            hit, first = _first_exceed(ph, eps[rows])
            out[rows[hit]] = first[hit]
            rows = rows[~hit]
            if rows.size and K >= m_limit:
                out[rows] = m_limit
                warnings.warn(
                    f"mmax_exact: the mismatch stays within eps_phi up to M = {m_limit} "
                    "(returned as a lower bound)",
                    RuntimeWarning,
                    stacklevel=3,
                )
                break
            K = min(2 * K, m_limit)
        start = stop
    return out


def mmax_exact_grid(R, W, y_u, fc, eps_phi, *, z_u=0.0, m_limit: int = M_LIMIT) -> np.ndarray:
    """:func:`mmax_exact` broadcast over arrays of geometries (maps, curves); int array."""
    R, W, y_u, z_u = wall_geometry(R, W, y_u, z_u)
    fc, eps = carrier_tolerance(fc, eps_phi)
    m_limit = integer("m_limit", m_limit, minimum=2)
    # the search may run up to m_limit antennas for one geometry (about 10 temporaries each)
    check_elements("m_limit", m_limit, 80, f"the exact search up to M = {m_limit}")
    shape = np.broadcast_shapes(R.shape, fc.shape, eps.shape)
    flat = [np.broadcast_to(v, shape).ravel().astype(float) for v in (R, W, y_u, z_u, C / fc, eps)]
    return _mmax_exact_flat(*flat, m_limit).reshape(shape)


def mmax_exact(
    R: float,
    W: float,
    y_u: float,
    fc: float,
    eps_phi: float,
    *,
    z_u: float = 0.0,
    m_limit: int = M_LIMIT,
) -> int:
    """The largest ``M`` whose exact ULA mismatch (:func:`phase_mismatch`) stays ``<= eps_phi``.

    The mismatch over ``M`` antennas is a maximum over a growing set, so it never decreases with
    ``M``: the answer is the index of the first antenna whose exact mismatch exceeds ``eps_phi``.
    Found by evaluating the exact profile up to a length guessed from :func:`mmax_nonparaxial`
    and doubling until it is exceeded (up to ``m_limit``, returned with a warning as a lower
    bound). May be 1 when even two antennas break the SR-NF model. The theorem's geometry lets
    the ULA run past the wall (``(M-1) lambda/2 > W``) for long arrays; that is not checked.
    """
    for name, v in (
        ("R", R),
        ("W", W),
        ("y_u", y_u),
        ("fc", fc),
        ("eps_phi", eps_phi),
        ("z_u", z_u),
    ):
        if not isinstance(v, numbers.Real) or isinstance(v, bool):
            raise TypeError(f"{name}: expected a real number, got {type(v).__name__}")
    return int(mmax_exact_grid(R, W, y_u, fc, eps_phi, z_u=z_u, m_limit=m_limit))


def mmax_exact_ura(
    R: float,
    W: float,
    y_u: float,
    fc: float,
    eps_phi: float,
    *,
    z_u: float = 0.0,
    tilt: float = SECTION_4_1_TILT,
    m_limit: int = M_LIMIT_URA,
) -> int:
    """The largest ``M`` such that the ``M x M`` URA of section 4.1 keeps the exact mismatch
    ``<= eps_phi`` (Theorem 3.4's setting, no expansion).

    The ``M x M`` arrays are nested (reference corner at the origin), so the running maximum over
    growing squares is monotone; the grid doubles until it is exceeded (up to ``m_limit``, i.e.
    ``m_limit**2`` antennas; returned with a warning as a lower bound).
    """
    R, W, y_u, z_u = (float(v) for v in wall_geometry(R, W, y_u, z_u))
    fc, eps = (float(v) for v in carrier_tolerance(fc, eps_phi))
    m_limit = integer("m_limit", m_limit, minimum=2)
    check_elements("m_limit", 16 * m_limit**2, what=f"the exact URA search up to {m_limit}^2")
    lam = C / fc
    pv = vue(R, W, y_u, z_u)
    ps = reference_specular_point(R, W, y_u, z_u)
    guess = float(second_order_mmax(R, W, y_u, z_u, lam, eps))
    K = int(min(m_limit, max(16, math.ceil(1.25 * guess) + 8)))
    while True:
        check_elements("m_limit", 16 * K * K, what=f"the exact URA search up to {K} x {K}")
        ph = np.abs(signed_mismatch(pv, ps, ura_positions(K, fc, tilt=tilt), lam))
        run = np.maximum.accumulate(np.maximum.accumulate(ph, axis=0), axis=1)
        over = np.diagonal(run) > eps
        if over.any():
            return int(over.argmax())
        if K >= m_limit:
            warnings.warn(
                f"mmax_exact_ura: the mismatch stays within eps_phi up to M = {m_limit} "
                "(returned as a lower bound)",
                RuntimeWarning,
                stacklevel=2,
            )
            return m_limit
        K = min(2 * K, m_limit)


# ---------------------------------------------------------------------------------------------
# the derivation, term by term, and summaries


#: every per-antenna term of :class:`ApertureProfile` has one value per element
_PROFILE_SHAPES = dict.fromkeys(
    (
        "y",
        "d_v",
        "d_p0",
        "delta_star",
        "delta_star_fresnel",
        "delta_sr",
        "delta_sr_fresnel",
        "mismatch",
        "mismatch_paraxial",
        "mismatch_second_order",
    ),
    ("M",),
)


@dataclass(frozen=True)
class ApertureProfile:
    """Every term of the proof of Theorem 3.1 across an ``M``-element ULA (2-D, ``z_u = 0``).

    Lengths in metres, phases in radians; arrays of length ``M`` indexed by antenna ``m``.
    """

    y: np.ndarray  #: antenna positions y_m = m lambda / 2
    d_v: np.ndarray  #: eq. 26-27: exact reflected path lengths |p_v - p_m|
    d_p0: np.ndarray  #: eq. 29-30: reflector-to-antenna lengths |p_s0 - p_m|
    x_p0: float  #: eq. 32: x of the reference specular point
    delta_star: np.ndarray  #: exact delta*_m = d_v,m - d_v,0
    delta_star_fresnel: np.ndarray  #: eq. 28
    delta_sr: np.ndarray  #: exact delta^SR_m = d_p0,m - d_p0,0
    delta_sr_fresnel: np.ndarray  #: eq. 31 with eq. 32
    mismatch: np.ndarray  #: exact 2 pi / lambda (delta* - delta^SR) (signed)
    mismatch_paraxial: np.ndarray  #: eq. 33 times 2 pi / lambda
    mismatch_second_order: np.ndarray  #: corrected eq. 41 (see mmax_nonparaxial), signed

    def __post_init__(self) -> None:
        record(self, shapes=_PROFILE_SHAPES, positive=("x_p0",))


def aperture_profile(M: int, R: float, W: float, y_u: float, fc: float) -> ApertureProfile:
    """Exact and approximate path differences of eq. 26-33 at every antenna of the ULA."""
    M = integer("M", M, minimum=2)
    R, W, y_u, _ = (float(v) for v in wall_geometry(R, W, y_u))
    lam = wavelength(fc)
    check_elements("M", 16 * M, what=f"{M} antennas x 16 profiles")
    y = np.arange(M) * lam / 2.0
    a = 2.0 * W - y_u
    x_p0 = R * W / a
    d_v = np.hypot(R, a - y)
    d_p0 = np.hypot(x_p0, W - y)
    pos = np.zeros((M, 3))
    pos[:, 1] = y
    pv, ps = np.array([R, a, 0.0]), np.array([x_p0, W, 0.0])
    d_star, d_sr = path_difference(pv, pos), path_difference(ps, pos)
    rho = math.hypot(R, a)
    k = 2.0 * np.pi / lam
    return ApertureProfile(
        y=y,
        d_v=d_v,
        d_p0=d_p0,
        x_p0=x_p0,
        delta_star=d_star,
        delta_star_fresnel=(y**2 - 2.0 * a * y) / (2.0 * R),
        delta_sr=d_sr,
        delta_sr_fresnel=(y**2 - 2.0 * W * y) / (2.0 * x_p0),
        mismatch=k * (d_star - d_sr),
        mismatch_paraxial=-k * (W - y_u) / (2.0 * R * W) * y**2,
        mismatch_second_order=-k * (W - y_u) / (2.0 * rho * W) * y**2 * R**2 / rho**2,
    )
