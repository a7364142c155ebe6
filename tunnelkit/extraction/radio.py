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

__all__ = ["check_array", "check_srs"]


def check_array(array, m: int | None = None) -> np.ndarray:
    """The local element positions (M, 3) of ``array`` (an :class:`ArrayGeometry` or an (M, 3)
    array), checked as :func:`tunnelkit.arrays.check_element_positions` does, with ``M = m``
    when given; errors name ``array``."""
    if isinstance(array, ArrayGeometry):
        array = array.local
    return check_element_positions("array", array, m=m)


def check_srs(srs) -> SRSConfig:
    """``srs`` if it is a :class:`SRSConfig`, else ``TypeError`` naming ``srs``."""
    if not isinstance(srs, SRSConfig):
        raise TypeError(f"srs: expected a tunnelkit.channel.SRSConfig, got {type(srs).__name__}")
    return srs
