"""The one protocol every filter of the workbook follows, whatever its family: :class:`Filter`.

``predict(*inputs)`` moves the state to the next epoch (the family's control inputs);
``update(z)`` takes one epoch's measurement (``None``, or NaN for a scalar, means none: the
prediction stands); ``step(...)`` is ``predict`` then ``update``, every argument checked before
the state moves; ``x`` and ``P`` are the state and its covariance, inspectable after any call.

What each family passes and returns: docs/internals/tracking.md.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

__all__ = ["Filter"]


@runtime_checkable
class Filter(Protocol):
    """``predict`` / ``update`` / ``step`` with an inspectable ``x`` and ``P`` (docs/internals)."""

    @property
    def x(self) -> Any: ...

    @property
    def P(self) -> Any: ...

    def predict(self, *inputs) -> None: ...

    def update(self, z) -> Any: ...

    def step(self, *args) -> Any: ...
