"""The one protocol every filter of the workbook follows, whatever its family.

``predict(*inputs)``
    Moves the state to the next epoch. The inputs are the family's control inputs, as
    filterpy's ``predict(u)``: none for Jiang's filters (:mod:`tunnelkit.tracking.virtual_station`,
    the UPF) and Halili's Doppler filters, the approach speed for Halili's range KF, the V2X
    ``(speed, heading, dt)`` for JAVELIN (two predictions before an update: the update sees
    the last message).
``update(z)``
    Takes one epoch's measurement (``None``, or NaN for a scalar, means none: the prediction
    stands). Returns: nothing for Jiang's filters (read ``x``), the position, speed or distance
    for Halili's, the epoch's :class:`~tunnelkit.tracking.javelin.StepReport` for JAVELIN.
``step(...)``
    ``predict`` then ``update``, every argument checked before the state moves, with the
    family's arguments in one call: ``step(z, first=False)`` (Jiang's; ``first``: no
    prediction), ``step(z)`` (Halili's Doppler filters), ``step(u, z)`` (the range KF),
    ``step(paths, speed, heading, dt)`` (JAVELIN); it returns what ``update`` returns (Jiang's:
    the state).
``x``, ``P``
    The state and its covariance, inspectable after any call.

The family-level conveniences (``run`` over many runs, ``for_drive`` / ``track`` over a
simulated drive, Halili's approaches that chain a Doppler filter into the range KF) are built on
these calls (:mod:`tunnelkit.tracking.registry`).
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

__all__ = ["Filter"]


@runtime_checkable
class Filter(Protocol):
    """``predict`` / ``update`` / ``step`` with an inspectable ``x`` and ``P`` (module docstring)."""

    @property
    def x(self) -> Any: ...

    @property
    def P(self) -> Any: ...

    def predict(self, *inputs) -> None: ...

    def update(self, z) -> Any: ...

    def step(self, *args) -> Any: ...
