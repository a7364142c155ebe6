"""The one protocol every filter of the workbook follows, whatever its family.

``predict(*inputs)``
    Moves the state to the next epoch. The inputs are the family's control inputs, as
    filterpy's ``predict(u)``: none for Jiang's filters (:mod:`tunnelkit.tracking.virtual_station`,
    the UPF) and Halili's Doppler filters, the approach speed for Halili's range KF, the V2X
    ``(speed, heading, dt)`` for JAVELIN.
``update(z)``
    Takes one epoch's measurement (``None``, or NaN for a scalar, means none: the prediction
    stands) and returns what the filter estimates (a position, a speed or a distance).
``step(*inputs, z)``
    ``predict`` then ``update``, the inputs checked before the state moves.
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
