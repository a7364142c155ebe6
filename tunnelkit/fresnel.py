"""How many antennas before a reflected path stops looking like one point on the wall?

Italiano et al. 2026, section 3.1: the single-reflector near-field (SR-NF) channel model replaces
the wall-reflected path seen by antenna ``m`` (whose true wavefront is centred on the virtual UE,
VUE) by a spherical wave from one point on the wall, the specular point ``p_s0`` of the reference
antenna. The model is valid while the phase mismatch across the array stays below ``eps_phi``.

Geometry (Fig. 2 of the paper): the base station's reference antenna at the origin, the tunnel
axis along x, the reflecting wall the plane ``y = W`` (``W > 0``), the UE at ``(R, y_u, z_u)``
with ``y_u < W``, its VUE at ``(R, 2W - y_u, z_u)``. The ULA lies along y with spacing
``lambda / 2``: ``y_m = m lambda / 2``, ``m = 0 .. M-1``.

What is here:

* the paper's bounds: :func:`mmax_2d` (Theorem 3.1, eq. 25) and :func:`mmax_3d` (Theorem 3.4,
  eq. 37);
* the exact mismatch, no expansion: :func:`mismatch_profile`, :func:`phase_mismatch` (ULA),
  :func:`phase_mismatch_ura` (the URA of section 4.1) and the largest admissible array
  :func:`mmax_exact`, :func:`mmax_exact_grid`, :func:`mmax_exact_ura`;
* the corrected second-order bound :func:`mmax_nonparaxial`: eq. 41 with the SR model's own
  wavefront curvature kept (eq. 41 as printed drops it) and without the paraxial assumption
  ``|2W - y_u| << R`` behind eq. 28 and eq. 31;
* the classical Fraunhofer distance ``2 D^2 / lambda`` (:func:`fraunhofer_distance`,
  :func:`mmax_fraunhofer`) and a summary/report for design tables and the ``tunnelkit mmax``
  command.

All functions take SI units (metres, hertz, radians).
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import asdict, dataclass

import numpy as np

from . import arrays
from ._validate import finite_array, integer
from .budget import check_elements
from .constants import C, wavelength

__all__ = [
    "FC_PRESETS",
    "SECTION_4_1_TILT",
    "ApertureProfile",
    "MmaxSummary",
    "aperture",
    "aperture_profile",
    "design_report",
    "fraunhofer_distance",
    "mismatch_profile",
    "mmax_2d",
    "mmax_3d",
    "mmax_exact",
    "mmax_exact_grid",
    "mmax_exact_ura",
    "mmax_fraunhofer",
    "mmax_nonparaxial",
    "mmax_summary",
    "paraxial_ratio",
    "phase_mismatch",
    "phase_mismatch_ura",
    "reference_specular_point",
    "ula_positions",
    "ura_positions",
    "vue",
]

#: carrier presets used by the explorer, the notebook's design table and the CLI [Hz]
FC_PRESETS: dict[str, float] = {"3.5 GHz": 3.5e9, "5.9 GHz": 5.9e9, "28 GHz": 28e9}

#: section 4.1: the arrays look along the tunnel, tilted 30 deg down (orientation (+-90, -30) deg)
SECTION_4_1_TILT = math.radians(30.0)

#: the exact search stops here (an array this long is kilometres wide; see mmax_exact)
M_LIMIT = 2**20
#: the exact M x M URA search stops here by default
M_LIMIT_URA = 1024

# ---------------------------------------------------------------------------------------------
# input checks


def _real(name: str, value, *, pos: bool = False) -> np.ndarray:
    """A finite real scalar or array (bools refused); ``pos`` insists on > 0 everywhere."""
    if isinstance(value, bool | np.bool_):
        raise TypeError(f"{name}: expected a real number, got {value!r}")
    if isinstance(value, str | bytes):
        raise TypeError(f"{name}: expected a real number, got {type(value).__name__}")
    arr = finite_array(name, value)
    if pos and np.any(arr <= 0):
        raise ValueError(f"{name}: must be > 0, got {float(np.min(arr))}")
    return arr


def _geometry(R, W, y_u, z_u=0.0) -> tuple[np.ndarray, ...]:
    """Validated ``R > 0``, ``W > 0``, ``y_u < W`` and finite ``z_u`` (broadcast)."""
    R = _real("R", R, pos=True)
    W = _real("W", W, pos=True)
    y_u = _real("y_u", y_u)
    z_u = _real("z_u", z_u)
    try:
        R, W, y_u, z_u = np.broadcast_arrays(R, W, y_u, z_u)
    except ValueError as exc:
        raise ValueError(f"R, W, y_u, z_u: shapes do not broadcast ({exc})") from None
    if np.any(y_u == W):
        raise ValueError(
            "y_u: equals W, i.e. the UE lies on the reflecting plane; there |W - y_u| = 0, the "
            "SR-NF model is exact for any M and the bound (25) is infinite. Use y_u < W."
        )
    if np.any(y_u > W):
        raise ValueError(
            f"y_u: must be < W (the UE is inside the tunnel, the wall is y = W), "
            f"got y_u = {float(np.max(y_u))} > W"
        )
    return R, W, y_u, z_u


def _fc_eps(fc, eps_phi) -> tuple[np.ndarray, np.ndarray]:
    return _real("fc", fc, pos=True), _real("eps_phi", eps_phi, pos=True)


def _out(x: np.ndarray):
    """A float for scalar input, an array otherwise."""
    x = np.asarray(x)
    return float(x) if x.ndim == 0 else x


# ---------------------------------------------------------------------------------------------
# geometry


def vue(R, W, y_u, z_u=0.0) -> np.ndarray:
    """The virtual UE ``p_v = (R, 2W - y_u, z_u)``: the UE mirrored in the wall ``y = W``.

    Proof of Theorem 3.1 / 3.4. Shape ``(..., 3)`` (broadcast over the inputs).
    """
    R, W, y_u, z_u = _geometry(R, W, y_u, z_u)
    return np.stack([R, 2.0 * W - y_u, z_u], axis=-1)


def reference_specular_point(R, W, y_u, z_u=0.0) -> np.ndarray:
    """Specular point ``p_s0`` of the reference antenna (origin) on the wall ``y = W``.

    It is where the segment origin -> VUE crosses the wall, at the fraction ``W / (2W - y_u)``;
    its x coordinate is eq. 32, ``x_p0 = R W / (2W - y_u)``. Shape ``(..., 3)``.
    """
    pv = vue(R, W, y_u, z_u)
    W = np.broadcast_to(_real("W", W), pv.shape[:-1])
    return pv * (W / pv[..., 1])[..., None]


def ula_positions(M: int, fc: float) -> np.ndarray:
    """The ULA of Theorem 3.1: ``M`` antennas at ``(0, m lambda/2, 0)``; shape ``(M, 3)``.

    :func:`tunnelkit.arrays.ula` placed looking along +x (azimuth 0, elevation 0).
    """
    M = integer("M", M, minimum=1)
    check_elements("M", 8 * M, what=f"a {M}-element ULA")
    return arrays.ula(M, wavelength(fc) / 2.0) @ arrays.rotation(0.0, 0.0).T


def ura_positions(
    M: int, fc: float, *, N: int | None = None, tilt: float = SECTION_4_1_TILT
) -> np.ndarray:
    """The URA of section 4.1: ``M x N`` antennas (``N = M`` by default), spacing ``lambda/2``.

    The array looks along the tunnel (+x) tilted ``tilt`` radians downwards (section 4.1:
    orientation (90, -30) deg in the paper's simulator frame; azimuth 0, elevation ``-tilt`` in
    :mod:`tunnelkit.arrays`), so its face is spanned by ``e_y = (0, 1, 0)`` and
    ``e_v = (sin tilt, 0, cos tilt)``. The reference antenna (index (0, 0)) sits at the origin,
    element ``(m, n)`` at ``m d e_y + n d e_v``; ``m`` runs across the tunnel like the ULA of
    Theorem 3.1. Shape ``(M, N, 3)``.
    """
    M = integer("M", M, minimum=1)
    N = M if N is None else integer("N", N, minimum=1)
    t = float(_real("tilt", tilt))
    check_elements("M", 16 * M * N, what=f"a {M} x {N} URA and its mismatch map")
    local = arrays.ura(N, M, wavelength(fc) / 2.0)  # element r * M + c at (c d, r d, 0)
    world = local @ arrays.rotation(0.0, -t).T
    return world.reshape(N, M, 3).transpose(1, 0, 2)


def paraxial_ratio(R, W, y_u):
    """``|2W - y_u| / R``: the paraxial expansions eq. 28 and eq. 31 assume this is << 1."""
    R, W, y_u, _ = _geometry(R, W, y_u)
    return _out(np.abs(2.0 * W - y_u) / R)


# ---------------------------------------------------------------------------------------------
# exact mismatch


def _delta(src: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """``|src - p| - |src|`` without cancellation: ``(|p|^2 - 2 src.p) / (|src - p| + |src|)``.

    ``src`` (..., 3) broadcast against ``pos`` (..., 3); the path difference of eq. 2 / eq. 27.
    """
    num = np.sum(pos * pos, axis=-1) - 2.0 * np.sum(src * pos, axis=-1)
    den = np.linalg.norm(src - pos, axis=-1) + np.linalg.norm(src, axis=-1)
    return num / den


def _mismatch(pv: np.ndarray, ps: np.ndarray, pos: np.ndarray, lam) -> np.ndarray:
    """Signed exact phase mismatch ``2 pi / lambda (delta*_m - delta^SR_m)`` [rad]."""
    return (2.0 * np.pi / lam) * (_delta(pv, pos) - _delta(ps, pos))


def _delta_ula(src: np.ndarray, y: np.ndarray) -> np.ndarray:
    """:func:`_delta` for antennas on the y axis, ``p = (0, y, 0)``; ``src`` (n, 3), ``y`` (n, K)."""
    sx2z2 = (src[:, 0] ** 2 + src[:, 2] ** 2)[:, None]
    sy = src[:, 1][:, None]
    return (y * y - 2.0 * sy * y) / (np.sqrt(sx2z2 + (sy - y) ** 2) + np.sqrt(sx2z2 + sy * sy))


def _mismatch_ula(pv: np.ndarray, ps: np.ndarray, y: np.ndarray, lam) -> np.ndarray:
    """:func:`_mismatch` for a ULA along y (rows of geometries ``pv, ps`` (n, 3), ``y`` (n, K))."""
    return (2.0 * np.pi / lam) * (_delta_ula(pv, y) - _delta_ula(ps, y))


def mismatch_profile(positions, R, W, y_u, fc, *, z_u=0.0) -> np.ndarray:
    """Exact signed phase mismatch [rad] at each antenna, no expansion (eq. 26-33 exactly).

    ``delta*_m = |p_v - p_m| - |p_v|`` is the true reflected path length via the VUE minus the
    reference antenna's (eq. 26-27); ``delta^SR_m = |p_s0 - p_m| - |p_s0|`` is the SR-NF model's,
    with the reflector fixed at the reference antenna's specular point (eq. 29-30, 32). Returns
    ``2 pi / lambda (delta*_m - delta^SR_m)`` with the shape of ``positions[..., 0]``.
    ``positions`` are antenna coordinates (..., 3) [m] relative to the reference antenna.
    """
    pos = _real("positions", positions)
    if pos.ndim == 0 or pos.shape[-1] != 3:
        raise ValueError(
            f"positions: expected 3 coordinates in the last axis, got shape {pos.shape}"
        )
    lam = wavelength(fc)
    R, W, y_u, z_u = (
        float(v) for v in (_real("R", R), _real("W", W), _real("y_u", y_u), _real("z_u", z_u))
    )
    pv = vue(R, W, y_u, z_u)
    ps = reference_specular_point(R, W, y_u, z_u)
    return _mismatch(pv, ps, pos, lam)


def phase_mismatch(M: int, R: float, W: float, y_u: float, fc: float, *, z_u: float = 0.0) -> float:
    """Largest exact ``|2 pi / lambda (delta*_m - delta^SR_m)|`` [rad] over an ``M``-element ULA.

    The ULA of Theorem 3.1 (along y, spacing ``lambda/2``, reference antenna at the origin); the
    left-hand side of the phase constraint above eq. 34, computed from eq. 26-27 and 29-30/32
    without the Fresnel expansions eq. 28 and eq. 31. ``z_u`` (default 0, the 2-D theorem) puts
    the UE above/below the array plane.
    """
    M = integer("M", M, minimum=2)
    _geometry(R, W, y_u, z_u)
    fc = _real("fc", fc, pos=True)
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
    _geometry(R, W, y_u, z_u)
    fc = _real("fc", fc, pos=True)
    pos = ura_positions(M, float(fc), N=N, tilt=tilt)
    return float(np.max(np.abs(mismatch_profile(pos, R, W, y_u, fc, z_u=z_u))))


# ---------------------------------------------------------------------------------------------
# closed-form bounds


def mmax_2d(R, W, y_u, fc, eps_phi):
    """Theorem 3.1, eq. 25: ``Mmax <= 1 + 2 sqrt(R W eps / (lambda |W - y_u| pi))``.

    ULA with spacing ``lambda/2``. Derived with the paraxial expansions eq. 28 and eq. 31, i.e.
    assuming ``|2W - y_u| << R`` (check :func:`paraxial_ratio`). Scalars give a float; arrays
    broadcast. ``y_u == W`` raises: the bound is infinite there.
    """
    R, W, y_u, _ = _geometry(R, W, y_u)
    fc, eps = _fc_eps(fc, eps_phi)
    lam = C / fc
    return _out(1.0 + 2.0 * np.sqrt(R * W * eps / (lam * np.abs(W - y_u) * np.pi)))


def mmax_3d(p_v, fc, eps_phi):
    """Theorem 3.4, eq. 37: ``Mmax <= 1 + 2 sqrt(rho eps / (lambda pi))``, ``rho = ||p_v||`` (eq. 35).

    ``p_v`` is the VUE position ``(R, 2W - y_u, z_u)`` (shape (..., 3)). As printed, eq. 41 keeps
    only the true wavefront's curvature ``|P_perp p_m|^2 / (2 rho)`` and drops the SR model's own
    curvature, so eq. 37 is the plane-wave criterion at the VUE distance: conservative for
    ``0 <= y_u < W``, optimistic for ``y_u < 0`` (see :func:`mmax_nonparaxial` for the corrected
    form).
    """
    pv = _real("p_v", p_v)
    if pv.ndim == 0 or pv.shape[-1] != 3:
        raise ValueError(f"p_v: expected 3 coordinates (R, 2W - y_u, z_u), got shape {pv.shape}")
    rho = np.linalg.norm(pv, axis=-1)
    if np.any(rho == 0):
        raise ValueError("p_v: the VUE coincides with the reference antenna (rho = 0)")
    fc, eps = _fc_eps(fc, eps_phi)
    return _out(1.0 + 2.0 * np.sqrt(rho * eps / ((C / fc) * np.pi)))


def mmax_nonparaxial(R, W, y_u, fc, eps_phi, *, z_u=0.0):
    """Second-order bound without the paraxial assumption: eq. 41 corrected.

    The VUE and the reference specular point lie on one ray from the origin (direction ``u``), at
    distances ``rho`` and ``rho W / (2W - y_u)``. Expanding both path differences to second order
    in the aperture (eq. 40 for each), the linear terms ``-u^T p_m`` cancel exactly and

        Delta delta_m ~= -(W - y_u) / (2 rho W) ||P_perp p_m||^2 .

    For the ULA along y, ``||P_perp p_m||^2 = y_m^2 (R^2 + z_u^2) / rho^2``, so with
    ``d = lambda/2``

        Mmax <= 1 + 2 sqrt(eps rho^3 W / (lambda pi |W - y_u| (R^2 + z_u^2))),

    which tends to eq. 25 when ``rho -> R`` (paraxial, ``z_u = 0``).
    """
    R, W, y_u, z_u = _geometry(R, W, y_u, z_u)
    fc, eps = _fc_eps(fc, eps_phi)
    return _out(_nonparaxial(R, W, y_u, z_u, C / fc, eps))


def _nonparaxial(R, W, y_u, z_u, lam, eps):
    """:func:`mmax_nonparaxial` on validated inputs (also the exact searches' first guess)."""
    rho = np.sqrt(R**2 + (2.0 * W - y_u) ** 2 + z_u**2)
    return 1.0 + 2.0 * np.sqrt(eps * rho**3 * W / (lam * np.pi * np.abs(W - y_u) * (R**2 + z_u**2)))


def aperture(M, fc):
    """ULA aperture ``D = (M - 1) lambda / 2`` [m]."""
    M = _real("M", M)
    if np.any(M < 1):
        raise ValueError(f"M: must be >= 1, got {float(np.min(M))}")
    fc = _real("fc", fc, pos=True)
    return _out((M - 1.0) * (C / fc) / 2.0)


def fraunhofer_distance(D, fc):
    """The classical Fraunhofer distance ``2 D^2 / lambda`` [m] of an aperture ``D`` [m]."""
    D = _real("D", D)
    if np.any(D < 0):
        raise ValueError(f"D: must be >= 0, got {float(np.min(D))}")
    fc = _real("fc", fc, pos=True)
    return _out(2.0 * D**2 / (C / fc))


def mmax_fraunhofer(R, fc):
    """Largest ULA (spacing ``lambda/2``) whose Fraunhofer distance is ``<= R``: ``1 + sqrt(2R/lambda)``.

    The classical far-field scaling ``O(sqrt(R / lambda))`` of Remark 3.3, for comparison.
    """
    R = _real("R", R, pos=True)
    fc = _real("fc", fc, pos=True)
    return _out(1.0 + np.sqrt(2.0 * R / (C / fc)))


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
    guess = _nonparaxial(R, W, y_u, z_u, lam, eps)
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
    R, W, y_u, z_u = _geometry(R, W, y_u, z_u)
    fc, eps = _fc_eps(fc, eps_phi)
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
    R, W, y_u, z_u = (float(v) for v in _geometry(R, W, y_u, z_u))
    fc, eps = (float(v) for v in _fc_eps(fc, eps_phi))
    m_limit = integer("m_limit", m_limit, minimum=2)
    check_elements("m_limit", 16 * m_limit**2, what=f"the exact URA search up to {m_limit}^2")
    lam = C / fc
    pv = vue(R, W, y_u, z_u)
    ps = reference_specular_point(R, W, y_u, z_u)
    guess = float(_nonparaxial(R, W, y_u, z_u, lam, eps))
    K = int(min(m_limit, max(16, math.ceil(1.25 * guess) + 8)))
    while True:
        check_elements("m_limit", 16 * K * K, what=f"the exact URA search up to {K} x {K}")
        ph = np.abs(_mismatch(pv, ps, ura_positions(K, fc, tilt=tilt), lam))
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


def aperture_profile(M: int, R: float, W: float, y_u: float, fc: float) -> ApertureProfile:
    """Exact and approximate path differences of eq. 26-33 at every antenna of the ULA."""
    M = integer("M", M, minimum=2)
    R, W, y_u, _ = (float(v) for v in _geometry(R, W, y_u))
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
    d_star, d_sr = _delta(pv, pos), _delta(ps, pos)
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


@dataclass(frozen=True)
class MmaxSummary:
    """Bounds and exact values for one design point (a row of a design table)."""

    R: float
    W: float
    y_u: float
    z_u: float
    fc: float
    eps_phi: float
    paraxial_ratio: float  #: |2W - y_u| / R (eq. 25 assumes << 1)
    eq25: float  #: mmax_2d
    eq37: float  #: mmax_3d at p_v = (R, 2W - y_u, z_u)
    nonparaxial: float  #: mmax_nonparaxial
    exact: int  #: mmax_exact (ULA)
    exact_ura: int  #: mmax_exact_ura (M x M URA of section 4.1)
    fraunhofer: float  #: mmax_fraunhofer(R)
    exact_capped: bool = False  #: the ULA search hit its limit: ``exact`` is a lower bound only
    exact_ura_capped: bool = False  #: the URA search hit its limit: ``exact_ura`` is a lower bound

    @property
    def ratio(self) -> float | None:
        """eq. 25 over the exact ULA value (< 1: the bound is conservative); None when capped."""
        return None if self.exact_capped else self.eq25 / self.exact

    def as_dict(self) -> dict[str, float]:
        return {**asdict(self), "ratio": self.ratio}


def mmax_summary(
    R: float, W: float, y_u: float, fc: float, eps_phi: float, *, z_u: float = 0.0, ura: bool = True
) -> MmaxSummary:
    """All bounds and exact values for one design point (``ura=False`` skips the URA search)."""
    s = dict(R=R, W=W, y_u=y_u, fc=fc, eps_phi=eps_phi)
    R_, W_, y_, z_ = (float(v) for v in _geometry(R, W, y_u, z_u))
    exact = mmax_exact(R_, W_, y_, float(fc), float(eps_phi), z_u=z_)
    exact_ura = mmax_exact_ura(R_, W_, y_, float(fc), float(eps_phi), z_u=z_) if ura else -1
    # an exact answer is always below the search limit; equal to it means the search stopped
    return MmaxSummary(
        R=R_,
        W=W_,
        y_u=y_,
        z_u=z_,
        fc=float(fc),
        eps_phi=float(eps_phi),
        paraxial_ratio=float(paraxial_ratio(R, W, y_u)),
        eq25=float(mmax_2d(**s)),
        eq37=float(mmax_3d([R_, 2 * W_ - y_, z_], fc, eps_phi)),
        nonparaxial=float(mmax_nonparaxial(**s, z_u=z_u)),
        exact=exact,
        exact_ura=exact_ura,
        fraunhofer=float(mmax_fraunhofer(R, fc)),
        exact_capped=exact >= M_LIMIT,
        exact_ura_capped=exact_ura >= M_LIMIT_URA,
    )


def design_report(points, *, title: str = "SR-NF validity: bounds vs exact Mmax", ura: bool = True):
    """A :class:`tunnelkit.reproduce.Report` (text or JSON table), one row per design point.

    ``points`` is an iterable of dicts with keys ``R, W, y_u, fc, eps_phi`` (and optionally
    ``z_u``, ``label``).
    """
    from .reproduce import Report

    rows, recs = [], []
    for p in points:
        p = dict(p)
        label = str(p.pop("label", ""))
        s = mmax_summary(**p, ura=ura)
        recs.append(s)
        rows.append(
            [
                label,
                s.R,
                s.W,
                s.y_u,
                s.z_u,
                s.fc / 1e9,
                s.eps_phi,
                s.paraxial_ratio,
                s.eq25,
                s.eq37,
                s.nonparaxial,
                f">= {s.exact}" if s.exact_capped else s.exact,
                (f">= {s.exact_ura}" if s.exact_ura_capped else s.exact_ura) if ura else None,
                None if s.ratio is None else round(s.ratio, 3),
            ]
        )
    cols = [
        "case",
        "R [m]",
        "W [m]",
        "y_u [m]",
        "z_u [m]",
        "fc [GHz]",
        "eps [rad]",
        "(2W-y_u)/R",
        "eq.25",
        "eq.37",
        "2nd-order",
        "exact ULA",
        "exact URA MxM",
        "eq.25/exact",
    ]
    notes = [
        "eq.25: Theorem 3.1 (paraxial, assumes (2W-y_u)/R << 1); eq.37: Theorem 3.4 as printed",
        "2nd-order: eq. 41 corrected (SR curvature kept, no paraxial assumption)",
        "exact: largest M whose exact phase mismatch over the array stays <= eps (no expansion)",
    ]
    if any(s.exact_capped or s.exact_ura_capped for s in recs):
        notes.append(
            "'>= N': the exact search stopped at its limit N with the mismatch still <= eps; "
            "N is a lower bound, not the exact value (and eq.25/exact is left out)"
        )
    return Report(title=title, columns=cols, rows=rows, notes=notes)
