"""Input checks shared by every public function.

Each helper raises ``ValueError`` or ``TypeError`` whose message starts with the offending
parameter's name, so a student sees *which* argument is wrong instead of a numpy traceback.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence

import numpy as np

__all__ = [
    "boolean",
    "callable_",
    "choice",
    "cosine",
    "finite_array",
    "instance",
    "integer",
    "messages",
    "nonnegative",
    "positive",
    "probability",
    "real",
    "record",
    "rng_or_error",
    "sequence",
    "text",
    "vector",
]

_F64 = np.dtype(float)
_BAD_KINDS = {"U": "text", "S": "bytes", "b": "booleans", "c": "complex numbers", "O": "objects"}


def _real_array(name: str, value, dtype=float) -> np.ndarray:
    """``value`` as a real array; strings, bools, complex and non-numbers raise ``TypeError``."""
    if value is None:
        raise TypeError(f"{name}: expected an array of numbers, got None")
    if isinstance(value, str | bytes):
        raise TypeError(f"{name}: expected numbers, got text {value!r}")
    if isinstance(value, np.ndarray):
        raw = value
    else:
        try:
            raw = np.asarray(value)
        except (TypeError, ValueError) as exc:  # ragged nested lists
            raise TypeError(
                f"{name}: expected an array of numbers, got {type(value).__name__} ({exc})"
            ) from None
    kind = raw.dtype.kind
    want_complex = np.dtype(dtype).kind == "c"
    if kind in "iuf" or (kind == "c" and want_complex):
        return raw.astype(dtype, copy=False)
    if kind == "O":
        try:
            arr = np.asarray(raw.tolist(), dtype=dtype)
        except (TypeError, ValueError):
            raise TypeError(
                f"{name}: expected an array of numbers, got {type(value).__name__} holding "
                "non-numeric items"
            ) from None
        if not want_complex and any(
            isinstance(v, bool | complex | np.bool_ | np.complexfloating)
            for v in np.asarray(raw, dtype=object).ravel()
        ):
            raise TypeError(f"{name}: expected real numbers, got booleans or complex numbers")
        return arr
    what = _BAD_KINDS.get(kind, f"dtype {raw.dtype}")
    raise TypeError(f"{name}: expected real numbers, got {what}")


def messages(name: str, x, *, batched: bool = False) -> np.ndarray:
    """V2X messages ``x`` checked, as floats: one per epoch (T,), or (..., T) of several drives
    with ``batched``; NaN where a message is missing, none infinite."""
    if isinstance(x, str | bytes) or np.asarray(x).dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected real numbers (NaN: a message lost), got {x!r:.40}")
    x = np.asarray(x, dtype=float)
    if x.ndim < 1 or (x.ndim > 1 and not batched):
        raise ValueError(f"{name}: expected shape {('(T,)', '(..., T)')[batched]}, got {x.shape}")
    if np.isinf(x).any():
        raise ValueError(f"{name}: contains infinite values (NaN marks a missing message)")
    return x


def finite_array(
    name: str,
    value,
    *,
    ndim: int | None = None,
    shape: Sequence[int | None] | None = None,
    dtype=float,
) -> np.ndarray:
    """Return ``value`` as a float array, refusing NaN/inf, a wrong ``ndim`` or ``shape``.

    Strings, booleans, ``None`` and complex numbers (unless ``dtype`` is complex) raise
    ``TypeError`` naming ``name``: an imaginary part is never dropped silently. ``shape`` may hold
    ``None`` for an axis of any length; a leading ``...`` is not supported, use ``ndim=None`` and a
    trailing-axis check instead.
    """
    if type(value) is np.ndarray and value.dtype == _F64 and dtype is float:
        arr = value  # the common case in inner loops: no conversion at all
    else:
        arr = _real_array(name, value, dtype)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: expected {ndim}-D input, got shape {arr.shape}")
    if shape is not None:
        if arr.ndim != len(shape) or any(
            s is not None and s != a for s, a in zip(shape, arr.shape)
        ):
            want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
            raise ValueError(f"{name}: expected shape {want}, got {arr.shape}")
    if not np.isfinite(arr).all():
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
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real | np.ndarray):
        raise TypeError(f"{name}: expected a real number, got {type(value).__name__}")
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "iuf":
            raise TypeError(f"{name}: expected a real number, got an array of {value.dtype}")
        if value.ndim != 0:
            raise TypeError(f"{name}: expected a scalar, got an array of shape {value.shape}")
    x = float(value)
    if not np.isfinite(x):
        raise ValueError(f"{name}: must be finite, got {x}")
    return x


def real(name: str, value) -> float:
    """A finite real scalar (bools, strings and complex numbers refused)."""
    return _scalar(name, value)


def positive(name: str, value, *, none: bool = False) -> float | None:
    """A finite scalar strictly greater than zero (or None, where ``none``: not given)."""
    x = None if none and value is None else _scalar(name, value)
    if x is not None and x <= 0:
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


def integer(name: str, value, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """An integer (numpy integers accepted; floats, even ``10.0`` or ``10.5``, and bools refused)
    within ``[minimum, maximum]``."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected an integer, got {value!r}")
    n = int(value)
    if minimum is not None and n < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {n}")
    if maximum is not None and n > maximum:
        raise ValueError(f"{name}: must be <= {maximum}, got {n}")
    return n


def text(name: str, value, *, empty: bool = False) -> str:
    """A string (a title, an axis or a label), non-empty unless ``empty``."""
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected text, got {type(value).__name__}")
    if not value and not empty:
        raise ValueError(f"{name}: must not be empty")
    return value


def sequence(name: str, value, *, empty: bool = False) -> list:
    """A list or tuple (or another non-text sequence) as a list, non-empty unless ``empty``."""
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise TypeError(f"{name}: expected a list, got {type(value).__name__}")
    out = list(value)
    if not out and not empty:
        raise ValueError(f"{name}: must not be empty")
    return out


def boolean(name: str, value) -> bool:
    """A real ``True``/``False`` (numpy bools accepted; ``"no"``, 0 and 1 refused)."""
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"{name}: expected True or False, got {value!r}")
    return bool(value)


def choice(name: str, value, options: Sequence[str]) -> str:
    """One of the strings ``options``."""
    if not isinstance(value, str) or value not in options:
        raise ValueError(f"{name}: expected one of {', '.join(map(repr, options))}, got {value!r}")
    return value


def callable_(name: str, value):
    """Anything callable."""
    if not callable(value):
        raise TypeError(f"{name}: expected a callable, got {type(value).__name__}")
    return value


def cosine(name: str, value) -> np.ndarray:
    """The cosine of an incidence angle: finite and in ``[0, 1]`` everywhere."""
    c = finite_array(name, value)
    if c.size and (c.min() < 0 or c.max() > 1):
        bad = float(c.min()) if c.min() < 0 else float(c.max())
        raise ValueError(f"{name}: must lie in [0, 1], got {bad}")
    return c


def instance(name: str, value, cls: type | tuple[type, ...], what: str | None = None):
    """``value`` if it is an instance of ``cls`` (a class or a tuple of classes), else
    ``TypeError`` naming ``name`` and what was expected (``what``, default the class names), so a
    wrong object is refused at the boundary instead of failing later with an ``AttributeError``."""
    if not isinstance(value, cls):
        if what is None:
            classes = cls if isinstance(cls, tuple) else (cls,)
            what = " or ".join(
                f"a {c.__module__.removeprefix('tunnelkit.')}.{c.__qualname__}" for c in classes
            )
        raise TypeError(f"{name}: expected {what}, got {type(value).__name__}")
    return value


def rng_or_error(name: str, rng) -> np.random.Generator:
    """Insist on an explicit ``numpy.random.Generator`` (no hidden global seeding)."""
    if not isinstance(rng, np.random.Generator):
        raise TypeError(
            f"{name}: expected a numpy.random.Generator (e.g. np.random.default_rng(0)), "
            f"got {type(rng).__name__}"
        )
    return rng


# --- records: every field of a dataclass checked by its annotation ------------------------------

_FIELD_HINTS: dict[type, dict[str, object]] = {}


def _field_hints(cls: type) -> dict[str, object]:
    """``{field: annotation}`` of a dataclass, resolved once per class (a name that cannot be
    resolved, e.g. one imported for type checking only, is left unchecked)."""
    hints = _FIELD_HINTS.get(cls)
    if hints is None:
        import dataclasses
        import sys
        import typing

        try:
            hints = typing.get_type_hints(cls)
        except Exception:
            ns = vars(sys.modules[cls.__module__]) if cls.__module__ in sys.modules else {}
            hints = {}
            for f in dataclasses.fields(cls):
                tp = f.type
                if isinstance(tp, str):
                    try:
                        tp = eval(tp, ns)  # an annotation of the package's own code
                    except Exception:
                        continue
                hints[f.name] = tp
        _FIELD_HINTS[cls] = hints
    return hints


def _members(tp) -> tuple[tuple, bool]:
    """(annotation's members without None, whether None is allowed)."""
    import types
    import typing

    if typing.get_origin(tp) in (typing.Union, types.UnionType):
        args = typing.get_args(tp)
        return tuple(a for a in args if a is not type(None)), type(None) in args
    return (tp,), tp is None or tp is type(None)


def _bind(name: str, got: tuple[int, ...], spec: tuple, dims: dict) -> None:
    """Check ``got`` (a shape) against ``spec`` (ints, symbol names shared across fields, None)."""
    if len(got) != len(spec):
        raise ValueError(f"{name}: expected {len(spec)}-D input, got shape {got}")
    for g, s in zip(got, spec):
        if s is None:
            continue
        if isinstance(s, str):
            s = dims.setdefault(s, g)
        if g != s:
            want = "(" + ", ".join("n" if x is None else str(dims.get(x, x)) for x in spec) + ")"
            raise ValueError(f"{name}: expected shape {want}, got {got}")


def _classify(tp) -> tuple[str, tuple, bool]:
    """(kind, classes, None allowed) of a field annotation, the dispatch of :func:`_field`:
    kind one of array, bool, int, float, str, seq, map, callable, class, any."""
    import typing
    from collections.abc import Callable as _Callable
    from collections.abc import Mapping as _Mapping
    from collections.abc import Sequence as _Sequence

    members, allows_none = _members(tp)
    plain = tuple(typing.get_origin(m) or m for m in members)
    if np.ndarray in plain:
        others = tuple(m for m in plain if m is not np.ndarray and isinstance(m, type))
        return "array", others, allows_none
    if bool in plain:
        return "bool", (), allows_none
    if int in plain and float not in plain:
        return "int", (), allows_none
    if float in plain:
        return "float", (), allows_none
    if str in plain:
        return "str", (), allows_none
    if any(m in (list, tuple, _Sequence, typing.Sequence) for m in plain):
        return "seq", (), allows_none
    if any(m in (dict, _Mapping, typing.Mapping) for m in plain):
        return "map", (), allows_none
    if any(m in (_Callable, typing.Callable) for m in plain):
        return "callable", (), allows_none
    classes = tuple(m for m in plain if isinstance(m, type) and m is not object)
    if classes and len(classes) == len(plain):
        return "class", classes, allows_none
    return "any", (), allows_none


_SIGNED = {"positive": positive, "nonnegative": nonnegative}


def _field(name, value, kind, classes, allows_none, *, spec, sign, allow_nan, may_be_empty,
           dims, allow_inf=False) -> None:  # fmt: skip
    if value is None:
        if allows_none:
            return
        raise TypeError(f"{name}: expected a value, got None")
    if kind == "array":
        if classes and not isinstance(value, np.ndarray) and isinstance(value, classes):
            return
        if isinstance(value, str | bytes):
            raise TypeError(f"{name}: expected an array of numbers, got text {value!r}")
        arr = value if isinstance(value, np.ndarray) else np.asarray(value)
        dk = arr.dtype.kind
        if dk not in "biufc":
            raise TypeError(f"{name}: expected an array of numbers, got dtype {arr.dtype}")
        if dk in "fc" and not allow_nan and not np.isfinite(arr).all():
            bad = np.isnan(arr) | (np.isinf(arr) & ~(allow_inf & (arr.real == np.inf)))
            if bad.any():
                raise ValueError(f"{name}: contains NaN or infinite values")
        if spec is not None:
            _bind(name, arr.shape, spec, dims)
        if sign and arr.size and dk in "iuf":
            low = float(arr.min())
            if low < 0 or (sign == "positive" and low == 0):
                raise ValueError(
                    f"{name}: must be {'>' if sign == 'positive' else '>='} 0, got {low}"
                )
    elif kind == "bool":
        boolean(name, value)
    elif kind == "int":
        integer(name, value, minimum={"positive": 1, "nonnegative": 0}.get(sign))
    elif kind == "float":
        if allow_nan and isinstance(value, float) and np.isnan(value):
            return
        if allow_inf and isinstance(value, float) and value == np.inf:
            return
        _SIGNED.get(sign, real)(name, value)
    elif kind == "str":
        if not isinstance(value, str):
            raise TypeError(f"{name}: expected text, got {type(value).__name__}")
        if not value and not may_be_empty:
            raise ValueError(f"{name}: must not be empty")
    elif kind == "seq":
        if isinstance(value, str | bytes) or not isinstance(value, list | tuple):
            raise TypeError(f"{name}: expected a list, got {type(value).__name__}")
        if not value:
            if not may_be_empty:
                raise ValueError(f"{name}: must not be empty")
        elif spec is not None:
            _bind(name, (len(value),), spec, dims)
    elif kind == "map":
        from collections.abc import Mapping as _Mapping

        if not isinstance(value, _Mapping):
            raise TypeError(f"{name}: expected a mapping, got {type(value).__name__}")
    elif kind == "callable":
        callable_(name, value)
    elif kind == "class":
        instance(name, value, classes)


_PLANS: dict[type, list] = {}


def _plan(cls: type) -> list:
    """[(field, kind, classes, None allowed)] of a dataclass's init fields, once per class."""
    plan = _PLANS.get(cls)
    if plan is None:
        import dataclasses

        hints = _field_hints(cls)
        plan = [
            (f.name, *_classify(hints[f.name]))
            for f in dataclasses.fields(cls)
            if f.init and f.name in hints
        ]
        _PLANS[cls] = plan
    return plan


def record(
    obj,
    *,
    shapes: dict[str, tuple] | None = None,
    positive: Sequence[str] = (),
    nonnegative: Sequence[str] = (),
    allow_nan: Sequence[str] = (),
    may_be_empty: Sequence[str] = (),
    skip: Sequence[str] = (),
    allow_inf: Sequence[str] = (),
) -> None:
    """Check every field of the dataclass ``obj`` by its annotation (for ``__post_init__``).

    ``float`` finite real, ``int`` integer, ``bool`` True/False, ``str`` non-empty text,
    ``np.ndarray`` numbers (finite unless in ``allow_nan``), lists, mappings, callables and classes
    by type, ``X | None`` also ``None``. ``shapes`` gives a field's shape (arrays) or ``(length,)``
    (lists): ints, ``None`` for any length, or a symbol such as ``"T"`` that must take the same
    value in every field it appears in. ``positive``/``nonnegative`` name fields with that sign;
    ``may_be_empty`` text or lists that may be empty; ``skip`` fields left unchecked;
    ``allow_inf`` floats or float arrays whose entries may be ``+inf`` (no bound, never). Errors name the field.
    """
    key = (type(obj), positive, nonnegative, allow_nan, may_be_empty, skip, allow_inf,
           tuple(shapes.items()) if shapes else ())  # fmt: skip
    try:
        steps = _COMPILED[key]
    except (KeyError, TypeError):  # first call (or options given as lists: not cached)
        shapes = shapes or {}
        steps = tuple(
            (
                name,
                kind,
                classes,
                allows_none,
                shapes.get(name),
                "positive" if name in positive else "nonnegative" if name in nonnegative else "",
                name in allow_nan,
                name in may_be_empty,
                name in allow_inf,
            )
            for name, kind, classes, allows_none in _plan(type(obj))
            if name not in skip
        )
        try:
            _COMPILED[key] = steps
        except TypeError:
            pass
    dims: dict[str, int] = {}
    for name, kind, classes, allows_none, spec, sign, nan_ok, empty_ok, inf_ok in steps:
        value = getattr(obj, name)
        if kind == "array" and type(value) is np.ndarray and value.dtype.kind == "f" and value.size:
            # the common case, float arrays: min (and max) catch NaN, infinities and the sign
            lo = value.min()
            if not nan_ok and not (lo > -np.inf and (inf_ok or value.max() < np.inf)):
                raise ValueError(f"{name}: contains NaN or infinite values")
            if spec is not None:
                _bind(name, value.shape, spec, dims)
            if sign and (lo < 0 or (sign == "positive" and lo == 0)):
                raise ValueError(
                    f"{name}: must be {'>' if sign == 'positive' else '>='} 0, got {float(lo)}"
                )
            continue
        # the other common cases inline (what _field would accept), the rest through _field
        tv = type(value)
        if (
            (kind == "int" and tv is int and (not sign or value >= (sign == "positive")))
            or (kind == "bool" and tv is bool)
            or (kind == "class" and isinstance(value, classes))
            or (kind == "str" and tv is str and (value or empty_ok))
            or (kind == "map" and tv is dict)
            or (
                kind == "seq"
                and (tv is list or tv is tuple)
                and spec is None
                and (value or empty_ok)
            )
            or (value is None and allows_none)
        ):
            continue
        _field(name, value, kind, classes, allows_none, spec=spec, sign=sign, allow_nan=nan_ok,
               may_be_empty=empty_ok, dims=dims, allow_inf=inf_ok)  # fmt: skip


#: record()'s checks per (class, options), built on the first call
_COMPILED: dict[tuple, tuple] = {}
