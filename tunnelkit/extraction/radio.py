"""The radio arguments every extraction entry point takes, checked in one place.

Each stage that reads the channel tensor (:func:`~tunnelkit.extraction.extract_paths`,
:func:`~tunnelkit.extraction.paper.paper_route`, :func:`~tunnelkit.extraction.coherent.resolve_coherent`,
:func:`~tunnelkit.extraction.ml.ml_paths`, :func:`~tunnelkit.extraction.ml.fit_ml`,
:func:`~tunnelkit.extraction.estimate_crlb`, ...) is called as ``(..., array, srs, ...)``:

- ``array`` — a :class:`tunnelkit.arrays.ArrayGeometry` (its ``local`` element positions are
  used) or a plain (M, 3) array of local-frame positions (``z = 0``, reference element at the
  origin);
- ``srs`` — a :class:`tunnelkit.channel.SRSConfig`: the carrier ``fc``, the tone spacing
  ``Delta f`` along axis 1 of the tensor and the symbol period ``T0`` along axis 2.
"""

from __future__ import annotations

import numpy as np

from ..arrays import ArrayGeometry, check_element_positions
from ..channel import SRSConfig

__all__ = ["MAX_CARRIER", "MIN_SYMBOL_PERIOD", "check_array", "check_srs"]

#: the radio the extraction accepts: carriers up to 1 THz, OFDM symbols of at least 1 ns
#: (5G NR's shortest, at 960 kHz subcarrier spacing, lasts about 1.1 us)
MAX_CARRIER = 1e12
MIN_SYMBOL_PERIOD = 1e-9


def check_array(array, m: int | None = None) -> np.ndarray:
    """The local element positions (M, 3) of ``array`` (an :class:`ArrayGeometry` or an (M, 3)
    array), checked as :func:`tunnelkit.arrays.check_element_positions` does, with ``M = m``
    when given; errors name ``array``."""
    if isinstance(array, ArrayGeometry):
        array = array.local
    return check_element_positions("array", array, m=m)


def check_srs(srs) -> SRSConfig:
    """``srs`` if it is a :class:`SRSConfig` with a carrier up to ``MAX_CARRIER`` and a symbol
    period of at least ``MIN_SYMBOL_PERIOD`` (else ``TypeError`` / ``ValueError`` naming ``srs``
    and the field)."""
    if not isinstance(srs, SRSConfig):
        raise TypeError(f"srs: expected a tunnelkit.channel.SRSConfig, got {type(srs).__name__}")
    if srs.fc > MAX_CARRIER:
        raise ValueError(
            f"srs: fc = {srs.fc:g} Hz is above {MAX_CARRIER:g} Hz (1 THz): not a radio carrier "
            "the eq. 1 model describes (fc is in Hz)"
        )
    if srs.symbol_period < MIN_SYMBOL_PERIOD:
        raise ValueError(
            f"srs: symbol_period = {srs.symbol_period:g} s is below {MIN_SYMBOL_PERIOD:g} s "
            f"(scs = {srs.scs:g} Hz): no OFDM numerology has symbols that short"
        )
    return srs
