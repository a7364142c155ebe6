"""More input checks of the validation layer (:mod:`tunnelkit._validate`): values where NaN
or infinity mean something (a missed epoch, a bound never met), stacks of matrices, signs,
lists of objects and duck-typed records. Each raises ``ValueError`` or ``TypeError`` whose
message starts with the offending parameter's name."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import MISSING as _MISSING
from dataclasses import fields

import numpy as np

from ._validate import finite_array, instance, nonnegative, real, sequence

__all__ = [
    "attributes",
    "bound",
    "bound_array",
    "items",
    "numeric_array",
    "optional_real",
    "real_array",
    "series",
    "sign",
    "square_matrices",
    "unchecked",
]


def real_array(name: str, value, *, ndim: int | None = None) -> np.ndarray:
    """A real float array where NaN and +-inf are values (a missed epoch, no estimate): text,
    booleans, complex numbers and ``None`` refused, a wrong ``ndim`` named."""
    if value is None or isinstance(value, str | bytes | bool | np.bool_):
        raise TypeError(f"{name}: expected real numbers, got {type(value).__name__}")
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):  # ragged nested lists
        raise TypeError(
            f"{name}: expected an array of numbers, got {type(value).__name__}"
        ) from None
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected real numbers, got dtype {arr.dtype}")
    arr = arr.astype(float, copy=False)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: expected {ndim}-D input, got shape {arr.shape}")
    return arr


def series(name: str, value, *, finite: bool = False) -> np.ndarray:
    """A scalar or a 1-D series of real numbers as a flat float array (one value per path or
    per epoch); NaN marks a missing value unless ``finite``; a second axis is refused."""
    arr = real_array(name, value)
    if arr.ndim > 1:
        raise ValueError(f"{name}: expected one value per entry (1-D), got shape {arr.shape}")
    if finite and not np.isfinite(arr).all():
        raise ValueError(f"{name}: contains NaN or infinite values")
    return arr.reshape(-1)


def numeric_array(name: str, value, ndim: tuple[int, ...], last: int | None = None) -> np.ndarray:
    """``value`` as a numeric (real or complex) array with ``ndim`` in ``ndim`` and, when given,
    ``last`` entries in the last axis, finite (NaN or inf is refused: a root, a factor or a
    tensor entry that is not a number has no path behind it). Errors name ``name``."""
    if value is None or isinstance(value, str | bytes):
        raise TypeError(f"{name}: expected a numeric array, got {type(value).__name__}")
    arr = np.asarray(value)
    if arr.dtype.kind not in "iufc":
        raise TypeError(f"{name}: expected numbers, got dtype {arr.dtype}")
    if arr.ndim not in ndim or (last is not None and arr.shape[-1] != last):
        want = " or ".join(f"{d}-D" for d in ndim) + (f" with {last} columns" if last else "")
        raise ValueError(f"{name}: expected {want}, got shape {arr.shape}")
    if arr.dtype.kind in "fc" and not np.isfinite(arr).all():
        raise ValueError(f"{name}: contains NaN or infinite values")
    return arr


def optional_real(name: str, value) -> float | None:
    """A real scalar where ``None`` or NaN means "missing" (returned as ``None``); text,
    booleans, complex numbers and infinities refused."""
    if value is None:
        return None
    if isinstance(value, float | np.floating) and np.isnan(value):
        return None
    return real(name, value)


def bound_array(name: str, value, *, ndim: int | None = None, empty: bool = True) -> np.ndarray:
    """Bounds or errors [m] (a standard deviation, an RMSE, a quantile): real, ``>= 0``, ``+inf``
    allowed (not identifiable, never met), NaN refused; non-empty unless ``empty``."""
    arr = real_array(name, value, ndim=ndim)
    if not empty and arr.size == 0:
        raise ValueError(f"{name}: expected at least one value")
    if np.isnan(arr).any() or (arr < 0).any():
        raise ValueError(f"{name}: expected values >= 0 (inf allowed), got NaN or a negative")
    return arr


def square_matrices(name: str, value, *, ndim: int | None = None) -> np.ndarray:
    """A finite real square matrix or stack (..., n, n) (``ndim`` fixes the stack's rank)."""
    A = finite_array(name, value, ndim=ndim)
    if A.ndim < 2 or A.shape[-1] != A.shape[-2] or A.shape[-1] == 0:
        raise ValueError(f"{name}: expected square matrices (..., n, n), got shape {A.shape}")
    return A


def bound(name: str, value) -> float:
    """A bound, an error or a quantile [m]: a real scalar ``>= 0``, ``+inf`` allowed (never
    met, not identifiable), NaN and ``-inf`` refused."""
    if isinstance(value, float | np.floating) and value == np.inf:
        return float("inf")
    return nonnegative(name, value)


def sign(name: str, value) -> float:
    """A sign convention: the real number ``-1`` or ``+1``."""
    x = real(name, value)
    if x not in (-1.0, 1.0):
        raise ValueError(f"{name}: expected -1 or +1, got {x}")
    return x


def items(name: str, value, cls: type | tuple[type, ...], *, empty: bool = False) -> list:
    """A list or tuple whose every item is an instance of ``cls`` (e.g. reflector planes)."""
    out = sequence(name, value, empty=empty)
    for i, v in enumerate(out):
        instance(f"{name}[{i}]", v, cls)
    return out


def attributes(name: str, value, attrs: Sequence[str], what: str):
    """``value`` if it has every attribute in ``attrs`` (a duck-typed record such as a simulated
    drive), else ``TypeError`` naming ``name`` and ``what`` was expected."""
    missing = [a for a in attrs if not hasattr(value, a)]
    if missing:
        raise TypeError(
            f"{name}: expected {what} (with {', '.join(missing)}), got {type(value).__name__}"
        )
    return value


_UNCHECKED: dict[type, tuple] = {}


def unchecked(cls: type, *args, **kwargs):
    """``cls(*args, **kwargs)`` for a dataclass record, without its ``__post_init__``: the
    unchecked twin for a caller that builds the record from values it has checked or computed
    itself (an inner loop, e.g. one JAVELIN step), the public constructor keeping its checks.
    Fields take the arguments, then their defaults; nothing is converted, so the values must be
    what the checked constructor keeps (tests/test_inner_loops.py rebuilds each such record
    through it)."""
    plan = _UNCHECKED.get(cls)
    if plan is None:
        plan = tuple((f.name, f.init, f.default, f.default_factory) for f in fields(cls))
        _UNCHECKED[cls] = plan
    obj = object.__new__(cls)
    n = len(args)
    i = 0
    for name, init, default, factory in plan:
        if init and i < n:
            value = args[i]
            i += 1
        elif init and name in kwargs:
            value = kwargs[name]
        elif factory is not _MISSING:
            value = factory()
        elif default is not _MISSING:
            value = default
        else:
            raise TypeError(f"{cls.__name__}: missing field {name}")
        object.__setattr__(obj, name, value)
    return obj
