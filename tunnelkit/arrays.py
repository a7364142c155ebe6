"""Antenna arrays: URA/ULA element positions, orientation and the array's local frame.

:func:`make_array` builds an :class:`ArrayGeometry` (elements from :func:`ura` or :func:`ula`)
in the local frame of Italiano et al. (2026), eq. 17-19: the array in its xy-plane, the reference
antenna (``m = 0``) at the origin, local ``z`` the boresight; it moves points and directions
between that frame and the world frame (:func:`rotation`). How it works:
docs/internals/channel-and-propagation.md.

    >>> from tunnelkit import arrays
    >>> arr = arrays.make_array(10, 10, fc=5.9e9, azimuth=0.0, elevation=np.radians(-30),
    ...                         origin=[0, 0, 4.8])
    >>> arr.M, arr.local.shape
    (100, (100, 3))
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from ._physical import element_spacing
from ._validate import finite_array, integer, nonnegative, positive, real, text, vector
from .budget import check_elements
from .constants import wavelength

__all__ = [
    "ArrayGeometry",
    "check_element_positions",
    "make_array",
    "rotation",
    "ula",
    "ura",
]


def ura(n_rows: int, n_cols: int, spacing: float) -> np.ndarray:
    """Element positions (M, 3) of an ``n_rows x n_cols`` URA in its local frame.

    Element ``m = r * n_cols + c`` sits at ``(c * spacing, r * spacing, 0)``; the reference antenna
    ``m = 0`` is the corner at the origin (as in Italiano eq. 17-18, where ``r_0 = 0``).
    """
    n_rows = integer("n_rows", n_rows, minimum=1)
    n_cols = integer("n_cols", n_cols, minimum=1)
    spacing = element_spacing("spacing", spacing)
    # positions (M, 3) plus the index grids and the world copy every array makes
    check_elements("n_rows, n_cols", n_rows * n_cols * 8, what=f"a {n_rows} x {n_cols} array")
    r, c = np.meshgrid(np.arange(n_rows), np.arange(n_cols), indexing="ij")
    return np.stack([c.ravel() * spacing, r.ravel() * spacing, np.zeros(r.size)], axis=-1)


def ula(n: int, spacing: float) -> np.ndarray:
    """Element positions (M, 3) of an ``n``-element ULA along the local x-axis, element 0 at 0."""
    n = integer("n", n, minimum=1)
    check_elements("n", n * 8, what=f"a {n}-element ULA")
    return ura(1, n, spacing)


def rotation(azimuth: float, elevation: float) -> np.ndarray:
    """3x3 matrix whose columns are the local x, y, z axes (z = boresight) in world coordinates.

    ``world = origin + R @ local``; ``local = R.T @ (world - origin)``.
    """
    az = real("azimuth", azimuth)
    el = real("elevation", elevation)
    if abs(el) > np.pi / 2:
        raise ValueError(f"elevation: must lie in [-pi/2, pi/2] rad, got {el}")
    ez = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    ex = np.array([-np.sin(az), np.cos(az), 0.0])
    ey = np.cross(ez, ex)
    return np.stack([ex, ey, ez], axis=1)


def check_element_positions(
    name: str, positions, m: int | None = None, *, atol: float = 1e-9
) -> np.ndarray:
    """Validate local-frame element positions: (M, 3), finite, ``z = 0``, reference at the origin.

    Raises ``ValueError`` naming ``name`` if the elements are not in the local xy-plane (the frame
    eq. 17-19 need), if element 0 is not at the origin, if two elements coincide, or if the count
    does not match ``m``. ``name`` is the caller's parameter the errors about ``positions`` name.
    """
    name = text("name", name)
    if m is not None:
        m = integer("m", m, minimum=2)
    atol = nonnegative("atol", atol)
    p = finite_array(name, positions)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (M, 3), got {p.shape}")
    if m is not None and p.shape[0] != m:
        raise ValueError(f"{name}: has {p.shape[0]} elements but the tensor has M = {m}")
    if p.shape[0] < 2:
        raise ValueError(f"{name}: need at least 2 elements, got {p.shape[0]}")
    scale = max(float(np.max(np.abs(p))), 1e-12)
    if np.max(np.abs(p[:, 2])) > atol * max(scale, 1.0):
        raise ValueError(
            f"{name}: elements must lie in the local xy-plane (z = 0); "
            f"max |z| = {np.max(np.abs(p[:, 2])):.3g} m"
        )
    if np.max(np.abs(p[0])) > atol * max(scale, 1.0):
        raise ValueError(
            f"{name}: the reference antenna (row 0) must sit at the origin, got {p[0]}"
        )
    # nearest other element of each one in the array plane: a k-d tree, O(M log M) time, O(M) memory
    d, _ = cKDTree(p[:, :2]).query(p[:, :2], k=2)
    if np.min(d[:, 1]) <= atol * scale:
        raise ValueError(f"{name}: two elements coincide")
    return p


@dataclass(frozen=True)
class ArrayGeometry:
    """A planar array placed in the world.

    ``local`` (M, 3) element positions in the local frame (z = 0, element 0 at the origin);
    ``origin`` (3,) world position of the reference antenna; ``azimuth``/``elevation`` [rad] of the
    boresight. ``name`` labels the array ("-x", "+x", ...).
    """

    local: np.ndarray
    origin: np.ndarray
    azimuth: float
    elevation: float
    name: str = ""
    R: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        loc = check_element_positions("local", self.local)
        object.__setattr__(self, "local", loc)
        object.__setattr__(self, "origin", vector("origin", self.origin, 3))
        text("name", self.name, empty=True)
        object.__setattr__(self, "R", rotation(self.azimuth, self.elevation))
        object.__setattr__(self, "azimuth", float(self.azimuth))
        object.__setattr__(self, "elevation", float(self.elevation))

    @property
    def M(self) -> int:
        """Number of elements."""
        return self.local.shape[0]

    @property
    def boresight(self) -> np.ndarray:
        """Unit boresight vector (local z) in world coordinates."""
        return self.R[:, 2]

    @property
    def world(self) -> np.ndarray:
        """Element positions (M, 3) in world coordinates."""
        return self.origin + self.local @ self.R.T

    def to_local(self, p) -> np.ndarray:
        """World point(s) (..., 3) -> local frame."""
        p = finite_array("p", p)
        return (p - self.origin) @ self.R

    def to_world(self, q) -> np.ndarray:
        """Local point(s) (..., 3) -> world frame."""
        q = finite_array("q", q)
        return self.origin + q @ self.R.T

    def dir_to_local(self, u) -> np.ndarray:
        """World direction(s) (..., 3) -> local frame (rotation only)."""
        return finite_array("u", u) @ self.R

    def dir_to_world(self, u) -> np.ndarray:
        """Local direction(s) (..., 3) -> world frame (rotation only)."""
        return finite_array("u", u) @ self.R.T

    def in_front(self, p) -> np.ndarray:
        """True where world point(s) ``p`` lie in front of the array face (local z > 0)."""
        return self.to_local(p)[..., 2] > 0


def make_array(
    n_rows: int,
    n_cols: int,
    *,
    fc: float,
    azimuth: float,
    elevation: float,
    origin=(0.0, 0.0, 0.0),
    spacing: float | None = None,
    name: str = "",
) -> ArrayGeometry:
    """A URA with ``lambda/2`` spacing (or ``spacing``) at ``origin`` looking at (azimuth, elevation).

    The paper's arrays look along the tunnel, tilted 30 deg down: ``(azimuth, elevation) =
    (0, -30 deg)`` and ``(180 deg, -30 deg)`` in our frame (the paper quotes (+-90, -30) deg in its
    simulator's frame, whose y-axis runs along the tunnel).
    """
    d = wavelength(fc) / 2 if spacing is None else positive("spacing", spacing)
    origin = vector("origin", origin, 3)
    return ArrayGeometry(ura(n_rows, n_cols, d), origin, azimuth, elevation, name=name)
