"""Materials of the tunnel's surfaces: the permittivity of concrete and the Fresnel reflection
coefficients of concrete and metal (a perfect conductor)."""

from __future__ import annotations

import numbers

import numpy as np

from .._physical import carrier
from .._validate import choice, cosine

__all__ = ["MATERIALS", "concrete_permittivity", "fresnel_te", "reflection_coefficient"]

#: the surface materials: concrete (ITU-R P.2040-3) and metal (a perfect conductor)
MATERIALS = ("concrete", "metal")
_EPS0 = 8.8541878128e-12


def concrete_permittivity(fc: float) -> complex:
    """Complex relative permittivity of concrete at ``fc`` [Hz] (ITU-R P.2040-3, Table 3).

    ``eps' = 5.24``, ``sigma = 0.0462 f_GHz^0.7822`` S/m, ``eps = eps' - j sigma / (2 pi f eps0)``.
    """
    fc = carrier("fc", fc)
    sigma = 0.0462 * (fc / 1e9) ** 0.7822
    return complex(5.24, -sigma / (2 * np.pi * fc * _EPS0))


def fresnel_te(eps_r: complex, cos_i) -> np.ndarray:
    """Fresnel reflection coefficient for perpendicular (TE) polarisation.

    ``Gamma = (cos i - sqrt(eps - sin^2 i)) / (cos i + sqrt(eps - sin^2 i))``; ``cos_i`` is the
    cosine of the incidence angle from the surface normal. A perfect conductor is ``Gamma = -1``.
    """
    ci = cosine("cos_i", cos_i)
    eps = _permittivity("eps_r", eps_r)
    if eps == 1 and np.any(np.asarray(ci) == 0):
        raise ValueError(
            "eps_r, cos_i: eps_r = 1 (no boundary) at grazing incidence (cos_i = 0) is 0/0; "
            "there is no reflection to compute"
        )
    return _fresnel_te(eps, ci)


def _permittivity(name: str, eps_r) -> complex:
    """A finite (complex) relative permittivity."""
    if isinstance(eps_r, bool | np.bool_) or not isinstance(eps_r, numbers.Number):
        raise TypeError(f"{name}: expected a (complex) number, got {type(eps_r).__name__}")
    e = complex(eps_r)
    if not (np.isfinite(e.real) and np.isfinite(e.imag)):
        raise ValueError(f"{name}: must be finite, got {e}")
    if e == 0:
        raise ValueError(f"{name}: must be non-zero")
    return e


def _fresnel_te(eps_r: complex, ci) -> np.ndarray:
    """:func:`fresnel_te` on checked inputs (``ci`` in [0, 1])."""
    root = np.sqrt(eps_r - (1.0 - ci**2))
    return (ci - root) / (ci + root)


def reflection_coefficient(material: str, fc: float, cos_i) -> np.ndarray:
    """``-1`` for ``"metal"``, the TE Fresnel coefficient of concrete at ``fc`` [Hz] for
    ``"concrete"``; ``cos_i`` is the cosine of the incidence angle from the surface normal."""
    ci = cosine("cos_i", cos_i)
    fc = carrier("fc", fc)
    if choice("material", material, MATERIALS) == "metal":
        return -np.ones_like(ci) + 0j
    return _fresnel_te(concrete_permittivity(fc), ci)
