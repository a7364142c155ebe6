"""An array's calibration error (docs/internals/channel-and-propagation.md): each element's gain
and phase drawn once per array (:func:`draw_calibration`, what
:meth:`tunnelkit.channel.Impairments.draw` draws) and a signal route's calibrations checked
(:func:`check_route_calibration`: one per array, its gains within :data:`MAX_CALIBRATION_DB`)."""

from __future__ import annotations

import numpy as np

from ._validate import finite_array, integer, nonnegative, rng_or_error
from .budget import check_elements

__all__ = ["MAX_CALIBRATION_DB", "draw_calibration"]

#: the largest element gain error [dB] a route's calibration may hold (far beyond any drawn one:
#: :func:`draw_calibration` allows a spread of at most 40 dB)
MAX_CALIBRATION_DB = 300.0


def draw_calibration(
    rng: np.random.Generator, m: int, phase_sigma_deg: float = 0.0, gain_sigma_db: float = 0.0
) -> np.ndarray:
    """Per-element calibration error (M,) complex: ``10^(e/20) exp(j phi)`` with gain error
    ``e ~ N(0, gain_sigma_db^2)`` [dB] and phase error ``phi ~ N(0, phase_sigma_deg^2)`` [deg],
    independent over elements (the reference antenna included). Draw it once per array: it is a
    property of the hardware, not of a snapshot."""
    rng = rng_or_error("rng", rng)
    m = integer("m", m, minimum=1)
    check_elements("m", 4 * m)
    sp = nonnegative("phase_sigma_deg", phase_sigma_deg)
    sg = nonnegative("gain_sigma_db", gain_sigma_db)
    if sg > 40.0:
        raise ValueError(
            f"gain_sigma_db: a calibration gain spread of {sg:g} dB (> 40 dB) is not a calibration error"
        )
    phase = np.radians(sp) * rng.standard_normal(m)
    gain_db = sg * rng.standard_normal(m)
    return 10.0 ** (gain_db / 20.0) * np.exp(1j * phase)


def check_route_calibration(calibration: dict, sizes: dict) -> None:
    """A signal route's ``calibration`` (array name -> (M,) complex gains) against its arrays'
    ``sizes`` (name -> M): every name one of the arrays, every gain finite and within
    +-``MAX_CALIBRATION_DB`` dB."""
    for name, g in calibration.items():
        if name not in sizes:
            raise ValueError(f"calibration: {name!r} is not one of the arrays {list(sizes)}")
        g = finite_array(f"calibration[{name!r}]", g, shape=(sizes[name],), dtype=complex)
        with np.errstate(divide="ignore"):
            db = 20 * np.log10(np.abs(g))
        if not np.all(np.abs(db) <= MAX_CALIBRATION_DB):
            raise ValueError(
                f"calibration[{name!r}]: element gains of {db.min():.3g} to {db.max():.3g} dB; "
                f"a calibration error lies within +-{MAX_CALIBRATION_DB:g} dB (a dead element "
                "or a unit mistake is not one)"
            )
