"""The setting of Theorems 3.1 and 3.4 and their closed-form bounds on the SR-NF array size.

The geometry (Fig. 2 of the paper): the base station's reference antenna at the origin, the
tunnel axis along x, the reflecting wall ``y = W``, the UE at ``(R, y_u, z_u)`` and its VUE
(:func:`vue`), the reference specular point (:func:`reference_specular_point`) and the arrays
(:func:`ula_positions`, :func:`ura_positions`). The bounds: :func:`mmax_2d` (eq. 25),
:func:`mmax_3d` (eq. 37), the corrected second-order :func:`mmax_nonparaxial` and the classical
Fraunhofer distance (:func:`fraunhofer_distance`, :func:`mmax_fraunhofer`). The input checks
(:func:`~tunnelkit.fresnel.mismatch.real_input`, :func:`wall_geometry`, :func:`carrier_tolerance`) are shared with the exact
search of :mod:`tunnelkit.fresnel.exact`.
"""

from __future__ import annotations

import math

import numpy as np

from .. import arrays
from .._physical import carrier, distances, phase_tolerance
from .._validate import integer
from ..budget import check_elements
from ..constants import C, wavelength
from .mismatch import real_input

__all__ = [
    "SECTION_4_1_TILT",
    "aperture",
    "carrier_tolerance",
    "fraunhofer_distance",
    "mmax_2d",
    "mmax_3d",
    "mmax_fraunhofer",
    "mmax_nonparaxial",
    "paraxial_ratio",
    "reference_specular_point",
    "second_order_mmax",
    "ula_positions",
    "ura_positions",
    "vue",
    "wall_geometry",
]

#: section 4.1: the arrays look along the tunnel, tilted 30 deg down (orientation (+-90, -30) deg)
SECTION_4_1_TILT = math.radians(30.0)

# input checks


def wall_geometry(R, W, y_u, z_u=0.0) -> tuple[np.ndarray, ...]:
    """The theorem's geometry, validated: ``R > 0``, ``W > 0``, ``y_u < W`` and finite ``z_u``
    as arrays broadcast against each other (errors name the parameter)."""
    R = real_input("R", distances("R", R), pos=True)
    W = real_input("W", distances("W", W), pos=True)
    y_u = real_input("y_u", distances("y_u", y_u))
    z_u = real_input("z_u", distances("z_u", z_u))
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


def carrier_tolerance(fc, eps_phi) -> tuple[np.ndarray, np.ndarray]:
    """The carrier ``fc > 0`` [Hz] and the phase tolerance ``eps_phi > 0`` [rad], validated."""
    eps_phi = phase_tolerance("eps_phi", real_input("eps_phi", eps_phi, pos=True))
    return real_input("fc", carrier("fc", fc)), eps_phi


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
    R, W, y_u, z_u = wall_geometry(R, W, y_u, z_u)
    return np.stack([R, 2.0 * W - y_u, z_u], axis=-1)


def reference_specular_point(R, W, y_u, z_u=0.0) -> np.ndarray:
    """Specular point ``p_s0`` of the reference antenna (origin) on the wall ``y = W``.

    It is where the segment origin -> VUE crosses the wall, at the fraction ``W / (2W - y_u)``;
    its x coordinate is eq. 32, ``x_p0 = R W / (2W - y_u)``. Shape ``(..., 3)``.
    """
    pv = vue(R, W, y_u, z_u)
    W = np.broadcast_to(real_input("W", W), pv.shape[:-1])
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
    t = float(real_input("tilt", tilt))
    check_elements("M", 16 * M * N, what=f"a {M} x {N} URA and its mismatch map")
    local = arrays.ura(N, M, wavelength(fc) / 2.0)  # element r * M + c at (c d, r d, 0)
    world = local @ arrays.rotation(0.0, -t).T
    return world.reshape(N, M, 3).transpose(1, 0, 2)


def paraxial_ratio(R, W, y_u):
    """``|2W - y_u| / R``: the paraxial expansions eq. 28 and eq. 31 assume this is << 1."""
    R, W, y_u, _ = wall_geometry(R, W, y_u)
    return _out(np.abs(2.0 * W - y_u) / R)


# ---------------------------------------------------------------------------------------------
# closed-form bounds


def mmax_2d(R, W, y_u, fc, eps_phi):
    """Theorem 3.1, eq. 25: ``Mmax <= 1 + 2 sqrt(R W eps / (lambda |W - y_u| pi))``.

    ULA with spacing ``lambda/2``. Derived with the paraxial expansions eq. 28 and eq. 31, i.e.
    assuming ``|2W - y_u| << R`` (check :func:`paraxial_ratio`). Scalars give a float; arrays
    broadcast. ``y_u == W`` raises: the bound is infinite there.
    """
    R, W, y_u, _ = wall_geometry(R, W, y_u)
    fc, eps = carrier_tolerance(fc, eps_phi)
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
    pv = real_input("p_v", p_v)
    if pv.ndim == 0 or pv.shape[-1] != 3:
        raise ValueError(f"p_v: expected 3 coordinates (R, 2W - y_u, z_u), got shape {pv.shape}")
    rho = np.linalg.norm(pv, axis=-1)
    if np.any(rho == 0):
        raise ValueError("p_v: the VUE coincides with the reference antenna (rho = 0)")
    fc, eps = carrier_tolerance(fc, eps_phi)
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
    R, W, y_u, z_u = wall_geometry(R, W, y_u, z_u)
    fc, eps = carrier_tolerance(fc, eps_phi)
    return _out(second_order_mmax(R, W, y_u, z_u, C / fc, eps))


def second_order_mmax(R, W, y_u, z_u, lam, eps):
    """The formula of :func:`mmax_nonparaxial` for a wavelength ``lam`` [m] and tolerance ``eps``
    [rad] (also the exact searches' first guess).

    The arguments are checked (:func:`wall_geometry`, ``lam > 0``, ``eps > 0``) and then used as
    given: Python floats stay floats, arrays broadcast.
    """
    wall_geometry(R, W, y_u, z_u)
    real_input("lam", lam, pos=True)
    real_input("eps", eps, pos=True)
    rho = np.sqrt(R**2 + (2.0 * W - y_u) ** 2 + z_u**2)
    return 1.0 + 2.0 * np.sqrt(eps * rho**3 * W / (lam * np.pi * np.abs(W - y_u) * (R**2 + z_u**2)))


def aperture(M, fc):
    """ULA aperture ``D = (M - 1) lambda / 2`` [m]."""
    M = real_input("M", M)
    if np.any(M < 1):
        raise ValueError(f"M: must be >= 1, got {float(np.min(M))}")
    fc = real_input("fc", carrier("fc", fc))
    return _out((M - 1.0) * (C / fc) / 2.0)


def fraunhofer_distance(D, fc):
    """The classical Fraunhofer distance ``2 D^2 / lambda`` [m] of an aperture ``D`` [m]."""
    D = real_input("D", D)
    if np.any(D < 0):
        raise ValueError(f"D: must be >= 0, got {float(np.min(D))}")
    fc = real_input("fc", carrier("fc", fc))
    return _out(2.0 * D**2 / (C / fc))


def mmax_fraunhofer(R, fc):
    """Largest ULA (spacing ``lambda/2``) whose Fraunhofer distance is ``<= R``: ``1 + sqrt(2R/lambda)``.

    The classical far-field scaling ``O(sqrt(R / lambda))`` of Remark 3.3, for comparison.
    """
    R = real_input("R", R, pos=True)
    fc = real_input("fc", carrier("fc", fc))
    return _out(1.0 + np.sqrt(2.0 * R / (C / fc)))
