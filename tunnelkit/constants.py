"""Physical constants and unit helpers (SI units, radians inside; dB only at the edges)."""

from __future__ import annotations

import numpy as np

from ._physical import carrier
from ._validate import finite_array

#: speed of light in vacuum [m/s]
C = 299_792_458.0
#: Boltzmann constant [J/K]
K_B = 1.380649e-23


def wavelength(fc: float) -> float:
    """Carrier wavelength ``lambda = c / fc`` [m] for a carrier ``fc`` [Hz]."""
    return C / carrier("fc", fc)


def db2lin(x_db):
    """Power ratio from decibels."""
    return 10.0 ** (finite_array("x_db", x_db) / 10.0)


def lin2db(x):
    """Decibels from a positive power ratio."""
    x = finite_array("x", x)
    if np.any(x <= 0):
        raise ValueError("x: power ratios must be > 0 to be expressed in dB")
    return 10.0 * np.log10(x)


def dbm2watt(p_dbm):
    """Watts from dBm."""
    return 1e-3 * 10.0 ** (finite_array("p_dbm", p_dbm) / 10.0)


def deg(x_rad):
    """Degrees from radians (for labels and tables only)."""
    return np.degrees(finite_array("x_rad", x_rad))


def rad(x_deg):
    """Radians from degrees (sliders and presets speak degrees)."""
    return np.radians(finite_array("x_deg", x_deg))
