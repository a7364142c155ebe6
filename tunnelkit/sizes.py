"""Sizes in bytes as text: a size read from words such as ``8GiB``, ``500MB`` or ``4e9``
(:func:`parse_size`, the memory budget's variable and setting) and a size written in words
(:func:`format_bytes`, ``1536`` -> ``'1.5 KiB'``, the budget's refusals).
"""

from __future__ import annotations

import math
import re

#: parse_size is not exported: the budget's reader, on a name and a string it holds
__all__ = ["format_bytes"]

_UNITS = {
    "": 1,
    "b": 1,
    "kb": 10**3,
    "mb": 10**6,
    "gb": 10**9,
    "tb": 10**12,
    "kib": 2**10,
    "mib": 2**20,
    "gib": 2**30,
    "tib": 2**40,
}


def parse_size(name: str, text: str) -> int:
    """A size in bytes from ``text``: bytes, or a number with a unit (``8GiB``, ``500MB``, ``4e9``);
    a ``ValueError`` naming ``name`` (where the text came from) if it is not one."""
    m = re.fullmatch(r"\s*([0-9.eE+]+)\s*([A-Za-z]*)\s*", text)
    unit = m.group(2).lower() if m else ""
    if not m or unit not in _UNITS:
        raise ValueError(f"{name}: cannot read {text!r} (e.g. 2147483648, 8GiB, 500MB)")
    try:
        value = float(m.group(1)) * _UNITS[unit]
    except ValueError:
        raise ValueError(f"{name}: cannot read {text!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name}: must be a positive size, got {text!r}")
    return int(value)


def format_bytes(n: float) -> str:
    """``1536`` -> ``'1.5 KiB'``; ``n`` a finite size >= 0 [B]."""
    if isinstance(n, bool) or not isinstance(n, int | float):
        raise TypeError(f"n: expected a number of bytes, got {type(n).__name__}")
    if not math.isfinite(n) or n < 0:
        raise ValueError(f"n: expected a finite number of bytes >= 0, got {n}")
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        if n < 1024 or unit == "EiB":
            return f"{n:.3g} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n:.3g} EiB"  # pragma: no cover
