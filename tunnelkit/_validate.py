"""Input checks shared by every public function.

Each helper raises ``ValueError`` or ``TypeError`` whose message starts with the offending
parameter's name, so a student sees *which* argument is wrong instead of a numpy traceback.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence

import numpy as np

__all__ = [
    "finite_array",
    "integer",
    "nonnegative",
    "positive",
    "probability",
    "rng_or_error",
    "vector",
]


def finite_array(
    name: str,
    value,
    *,
    ndim: int | None = None,
    shape: Sequence[int | None] | None = None,
    dtype=float,
) -> np.ndarray:
    """Return ``value`` as a float array, refusing NaN/inf, a wrong ``ndim`` or ``shape``.

    ``shape`` may hold ``None`` for an axis of any length; a leading ``...`` is not supported, use
    ``ndim=None`` and a trailing-axis check instead.
    """
    if value is None:
        raise TypeError(f"{name}: expected an array of numbers, got None")
    try:
        arr = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise TypeError(
            f"{name}: expected an array of numbers, got {type(value).__name__}"
        ) from exc
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: expected {ndim}-D input, got shape {arr.shape}")
    if shape is not None:
        if arr.ndim != len(shape) or any(
            s is not None and s != a for s, a in zip(shape, arr.shape)
        ):
            want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
            raise ValueError(f"{name}: expected shape {want}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or infinite values")
    return arr


def vector(name: str, value, size: int | tuple[int, ...]) -> np.ndarray:
    """A finite 1-D vector of length ``size`` (or one of the lengths in a tuple)."""
    arr = finite_array(name, value, ndim=1)
    sizes = (size,) if isinstance(size, int) else size
    if arr.shape[0] not in sizes:
        want = " or ".join(str(s) for s in sizes)
        raise ValueError(f"{name}: expected {want} coordinates, got {arr.shape[0]}")
    return arr


def _scalar(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real | np.ndarray):
        raise TypeError(f"{name}: expected a real number, got {type(value).__name__}")
    arr = np.asarray(value, dtype=float)
    if arr.ndim != 0:
        raise TypeError(f"{name}: expected a scalar, got an array of shape {arr.shape}")
    x = float(arr)
    if not np.isfinite(x):
        raise ValueError(f"{name}: must be finite, got {x}")
    return x


def positive(name: str, value) -> float:
    """A finite scalar strictly greater than zero."""
    x = _scalar(name, value)
    if x <= 0:
        raise ValueError(f"{name}: must be > 0, got {x}")
    return x


def nonnegative(name: str, value) -> float:
    """A finite scalar greater than or equal to zero."""
    x = _scalar(name, value)
    if x < 0:
        raise ValueError(f"{name}: must be >= 0, got {x}")
    return x


def probability(name: str, value, *, open_interval: bool = True) -> float:
    """A probability in (0, 1) (or [0, 1] with ``open_interval=False``)."""
    x = _scalar(name, value)
    ok = 0 < x < 1 if open_interval else 0 <= x <= 1
    if not ok:
        rng = "(0, 1)" if open_interval else "[0, 1]"
        raise ValueError(f"{name}: must lie in {rng}, got {x}")
    return x


def integer(name: str, value, *, minimum: int | None = None) -> int:
    """An integer (numpy integers accepted, floats refused) not below ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected an integer, got {value!r}")
    n = int(value)
    if minimum is not None and n < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {n}")
    return n


def rng_or_error(name: str, rng) -> np.random.Generator:
    """Insist on an explicit ``numpy.random.Generator`` (no hidden global seeding)."""
    if not isinstance(rng, np.random.Generator):
        raise TypeError(
            f"{name}: expected a numpy.random.Generator (e.g. np.random.default_rng(0)), "
            f"got {type(rng).__name__}"
        )
    return rng
