"""Physical ranges: the hard limits beyond which a value is meaningless in a road tunnel (a
vehicle, not light; a radio carrier, not a typo), each check naming the parameter and the unit
it expects, so a value in the wrong unit (GHz for Hz, kHz for Hz) is refused where it enters.

* :data:`CARRIER_HZ`: a radio carrier from 100 MHz to 300 GHz;
* :data:`SUBCARRIER_HZ`: a subcarrier spacing from 1 kHz to 1 MHz (NR: 15-960 kHz);
* :data:`TONE_SPACING_HZ`: the spacing of a sounding's tones (subcarrier spacing x comb), 1 kHz
  to 100 MHz;
* :data:`MAX_SPEED`: 150 m/s (540 km/h), above any road vehicle;
* :data:`TX_POWER_DBM`: -150 dBm to 100 dBm (10 MW);
* :data:`MAX_SPACING_M`: an antenna array's element spacing of at most 10 m;
* :data:`MAX_RANGE_M`: a measured range, a tunnel's coordinate or a target of at most 1,000 km;
* :data:`MIN_SIGMA`: a measurement's noise standard deviation of at least 1e-12 (in metres or
  radians: no measurement is that precise, and its information 1 / sigma^2 would overflow);
* :data:`MAX_START_SPREAD_M`: the spread of a tracker's entry fix, at most 1 km per axis
  (beyond, the fix says nothing of which tunnel the vehicle is in);
* :data:`MAX_STEP_S`: a tracker's time step of at most 60 s (a vehicle in a tunnel moves up to
  9 km in it: longer, no motion model holds).
"""

from __future__ import annotations

import numpy as np

from ._validate import finite_array, positive, real

__all__ = [
    "CARRIER_HZ",
    "MAX_RANGE_M",
    "MAX_SPACING_M",
    "MAX_SPEED",
    "MAX_START_SPREAD_M",
    "MAX_STEP_S",
    "MIN_SIGMA",
    "SUBCARRIER_HZ",
    "TONE_SPACING_HZ",
    "TX_POWER_DBM",
    "carrier",
    "distances",
    "element_spacing",
    "phase_tolerance",
    "power_dbm",
    "speeds",
    "start_spread",
    "step_seconds",
    "subcarrier",
    "tone_step",
]

#: a radio carrier [Hz]: 100 MHz to 300 GHz
CARRIER_HZ = (1e8, 3e11)
#: a subcarrier spacing [Hz]: 1 kHz to 1 MHz
SUBCARRIER_HZ = (1e3, 1e6)
#: the spacing of the tones a sounding occupies [Hz] (a subcarrier spacing times the comb: NR's
#: SRS up to 960 kHz x 8): 1 kHz to 100 MHz
TONE_SPACING_HZ = (1e3, 1e8)
#: the fastest road vehicle the workbook accepts [m/s] (540 km/h)
MAX_SPEED = 150.0
#: an antenna array's largest element spacing [m]
MAX_SPACING_M = 10.0
#: the longest measured range [m]
MAX_RANGE_M = 1e6
#: the smallest noise standard deviation of a measurement [m or rad]
MIN_SIGMA = 1e-12
#: the widest spread of a tracker's entry fix [m per axis]
MAX_START_SPREAD_M = 1000.0
#: a tracker's longest time step [s]
MAX_STEP_S = 60.0
#: a transmit power [dBm]
TX_POWER_DBM = (-150.0, 100.0)


def _within(name: str, value: float, lo: float, hi: float, unit: str, hint: str) -> float:
    if not lo <= value <= hi:
        raise ValueError(
            f"{name}: expected {lo:g} to {hi:g} {unit}, got {value:g}{' (' + hint + ')' if hint else ''}"
        )
    return value


def _band(name: str, value, lo: float, hi: float, unit: str, scale: str):
    """``value`` (a real scalar, or an array of them) within ``[lo, hi]`` [``unit``]; a value
    below 1000 is named as the typo of the unit ``scale`` below it (e3 or e9)."""
    if np.ndim(value) == 0:
        v = real(name, value)
        hint = f"{name} is in {unit}: did you mean {v:g}{scale}?" if 0 < v < 1e3 else ""
        return _within(name, v, lo, hi, unit, hint)
    if np.asarray(value).dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected real numbers, got dtype {np.asarray(value).dtype}")
    arr = finite_array(name, value)
    if arr.size:
        _band(name, float(arr.min()), lo, hi, unit, scale)
        _band(name, float(arr.max()), lo, hi, unit, scale)
    return arr


def carrier(name: str, value):
    """``value`` [Hz] (a scalar or an array) if a radio carrier (:data:`CARRIER_HZ`); a value in
    GHz is named as such."""
    return _band(name, value, *CARRIER_HZ, "Hz", "e9")


def subcarrier(name: str, value):
    """``value`` [Hz] (a scalar or an array) if a subcarrier spacing (:data:`SUBCARRIER_HZ`); kHz
    named as such."""
    return _band(name, value, *SUBCARRIER_HZ, "Hz", "e3")


def tone_step(name: str, value):
    """``value`` [Hz] (a scalar or an array) if the spacing of a sounding's tones
    (:data:`TONE_SPACING_HZ`); kHz named as such."""
    return _band(name, value, *TONE_SPACING_HZ, "Hz", "e3")


def power_dbm(name: str, value) -> float:
    """``value`` [dBm] within :data:`TX_POWER_DBM`."""
    return _within(name, real(name, value), *TX_POWER_DBM, "dBm", "")


def speeds(name: str, velocity, *, vectors: bool = True) -> np.ndarray:
    """``velocity`` (..., D) [m/s], finite, each speed at most :data:`MAX_SPEED`; a scalar, or
    with ``vectors=False`` every entry, is one speed (its magnitude)."""
    v = finite_array(name, velocity)
    s = np.abs(v) if v.ndim == 0 or not vectors else np.linalg.norm(v, axis=-1)
    top = float(np.max(s)) if s.size else 0.0
    if top > MAX_SPEED:
        raise ValueError(
            f"{name}: a speed of {top:.4g} m/s, above {MAX_SPEED:g} m/s ({3.6 * MAX_SPEED:g} km/h, "
            "faster than any road vehicle)"
        )
    return v


def step_seconds(name: str, value) -> float:
    """``value`` [s], a tracker's time step: 0 to :data:`MAX_STEP_S`."""
    return _within(name, real(name, value), 0.0, MAX_STEP_S, "s", "")


def _length(name: str, value, top: float) -> float:
    """``value`` [m] above 0 and at most ``top``."""
    v = positive(name, value)
    return _within(name, v, 0.0, top, "m", "")


def distances(name: str, value):
    """``value`` [m] (a scalar or an array; any sign: a coordinate) at most :data:`MAX_RANGE_M`
    from the origin: a tunnel's geometry, not the distance to the Moon."""
    v = finite_array(name, value)
    top = float(np.max(np.abs(v))) if v.size else 0.0
    if top > MAX_RANGE_M:
        raise ValueError(f"{name}: {top:.4g} m, beyond {MAX_RANGE_M:g} m (a tunnel's scale)")
    return value


def phase_tolerance(name: str, value):
    """``value`` [rad] (a scalar or an array), a phase tolerance: above 0 and at most pi (a phase
    error beyond pi is no tolerance: the phase wraps)."""
    v = finite_array(name, value)
    if v.size and not (np.all(v > 0) and np.all(v <= np.pi)):
        raise ValueError(f"{name}: a phase tolerance in (0, pi] rad, got {float(np.max(v)):g}")
    return value


def element_spacing(name: str, value) -> float:
    """``value`` [m], an element spacing: above 0, at most :data:`MAX_SPACING_M`."""
    return _length(name, value, MAX_SPACING_M)


def start_spread(name: str, value) -> float:
    """``value`` [m per axis], an entry fix's spread: above 0, at most :data:`MAX_START_SPREAD_M`."""
    return _length(name, value, MAX_START_SPREAD_M)
