"""The baselines a tracker on a simulated drive is read against: TeNFiLoc's snapshot fixes
(:func:`tenfiloc_track`) and dead reckoning, the same drive without its radio
(:func:`without_radio`). Scoring them is :mod:`tunnelkit.simulation.scoring`'s.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from .._validate import instance
from ..tracking import registry
from .drives import DriveData

if TYPE_CHECKING:  # the baseline's class, loaded from the registry when a drive asks for it
    from ..tracking.javelin.tenfiloc import TeNFiLoc

__all__ = ["tenfiloc_track", "without_radio"]


def tenfiloc_track(
    drive: DriveData, baseline: TeNFiLoc | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """TeNFiLoc fixes per epoch (T, 3) and which epochs had a fix (:meth:`~tunnelkit.tracking.javelin.tenfiloc.TeNFiLoc.track`; the
    baseline defaults to :meth:`~tunnelkit.tracking.javelin.tenfiloc.TeNFiLoc.for_drive`)."""
    if not isinstance(drive, DriveData):
        raise TypeError(f"drive: expected a DriveData, got {type(drive).__name__}")
    cls = registry.get("italiano2026", "TeNFiLoc")
    tf = cls.for_drive(drive) if baseline is None else baseline
    if not isinstance(tf, cls):
        raise TypeError(f"baseline: expected a TeNFiLoc, got {type(tf).__name__}")
    return tf.track(drive)


def without_radio(drive: DriveData) -> DriveData:
    """The same drive with every radio measurement dropped: a tracker run on it predicts on the
    V2X speed and heading messages alone, from the same start (dead reckoning, the baseline the
    radio must beat). Copies no array; draws nothing.

    >>> without_radio("a drive")
    Traceback (most recent call last):
    ...
    TypeError: drive: expected a simulation.drives.DriveData, got str
    """
    drive = instance("drive", drive, DriveData)
    return replace(drive, epochs=[None] * len(drive.epochs))
