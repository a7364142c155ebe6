"""The memory budget: sizes asked for by the user are checked before anything is allocated.

Every allocation whose size comes from an argument (array elements, tones x symbols x antennas,
particles x steps, Monte-Carlo runs, facets, ``m_limit``) is compared with the budget first; above
it the call raises ``ValueError`` naming the parameter and the size it would take, instead of a
``MemoryError`` traceback, a swapping machine or a run that never ends.

The budget is 2 GiB by default. Raise or lower it for a session with :func:`set_memory_budget`
or for a process with the environment variable ``TUNNELKIT_MEMORY_BUDGET`` (bytes, or a number
with a unit: ``8GiB``, ``500MB``, ``4e9``). :func:`set_memory_budget` wins over the variable.

    >>> from tunnelkit import budget
    >>> budget.memory_budget() == 2 * 1024**3
    True

``budget.check_elements("n_particles", 10**12, itemsize=32)`` raises ``ValueError: n_particles:
would need 29.1 TiB (10^12 elements of 32 B), above the memory budget of 2 GiB; ...``.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ._validate import integer, text

__all__ = [
    "DEFAULT_BUDGET",
    "check_bytes",
    "check_elements",
    "memory_budget",
    "set_memory_budget",
]

#: the default budget [bytes]
DEFAULT_BUDGET = 2 * 1024**3
ENV = "TUNNELKIT_MEMORY_BUDGET"

_override: int | None = None


def memory_budget() -> int:
    """The budget in bytes: :func:`set_memory_budget`, else ``TUNNELKIT_MEMORY_BUDGET``, else 2 GiB."""
    if _override is not None:
        return _override
    env = os.environ.get(ENV, "").strip()
    if not env:
        return DEFAULT_BUDGET
    from .sizes import parse_size  # a size in words, read when the variable is set

    return parse_size(ENV, env)


def set_memory_budget(nbytes: int | str | None) -> int | None:
    """Set the budget for this process (``None`` goes back to the variable/default).

    Returns the previous setting so a caller can restore it.
    """
    global _override
    prev = _override
    if nbytes is None:
        _override = None
    elif isinstance(nbytes, str):
        from .sizes import parse_size  # a size in words, read when one is given

        _override = parse_size(ENV, nbytes)
    else:
        if isinstance(nbytes, bool) or not isinstance(nbytes, int | float):
            raise TypeError(f"nbytes: expected a number of bytes, got {type(nbytes).__name__}")
        try:
            finite = math.isfinite(nbytes)
        except OverflowError:  # an int beyond float range
            finite = False
        if finite and isinstance(nbytes, float) and not nbytes.is_integer():
            raise ValueError(f"nbytes: must be a whole number of bytes, got {nbytes}")
        if not finite or nbytes <= 0:
            big_int = isinstance(nbytes, int) and not finite
            shown = f"an integer of {len(str(nbytes))} digits" if big_int else f"{nbytes}"
            raise ValueError(f"nbytes: must be a positive, finite number of bytes, got {shown}")
        _override = int(nbytes)
    return prev


def _count(n: int) -> str:
    if n >= 10**6:
        e = math.floor(math.log10(n))
        m = n / 10**e
        return f"10^{e} elements" if abs(m - 1) < 1e-9 else f"{m:.3g}x10^{e} elements"
    return f"{n} elements"


def _whole(name: str, value) -> int:
    """A count ``>= 0``: an integer, or a float holding a whole number (a product of sizes)."""
    if isinstance(value, float | np.floating) and math.isfinite(value) and value.is_integer():
        value = int(value)
    return integer(name, value, minimum=0)


def check_bytes(name: str, nbytes, what: str = "") -> None:
    """Raise ``ValueError`` naming ``name`` if ``nbytes`` exceeds the budget."""
    text("name", name)
    text("what", what, empty=True)
    nbytes = _whole("nbytes", nbytes)
    limit = memory_budget()
    if nbytes > limit:
        from .sizes import format_bytes  # the sizes in words, for the refusal

        detail = f" ({what})" if what else ""
        raise ValueError(
            f"{name}: would need {format_bytes(nbytes)}{detail}, above the memory budget of "
            f"{format_bytes(limit)}; reduce {name} or raise the budget "
            f"(tunnelkit.budget.set_memory_budget or {ENV})"
        )


def check_elements(name: str, count, itemsize: int = 8, what: str = "") -> None:
    """:func:`check_bytes` for ``count`` elements of ``itemsize`` bytes (exact integer product)."""
    text("name", name)
    text("what", what, empty=True)
    count = _whole("count", count)
    itemsize = _whole("itemsize", itemsize)
    if itemsize == 0:
        raise ValueError("itemsize: must be > 0 bytes")
    desc = what or f"{_count(count)} of {itemsize} B"
    check_bytes(name, count * int(itemsize), desc)
