"""Quick mode and the seeds of Monte-Carlo runs.

Quick mode (``TUNNELKIT_QUICK=1``) shrinks Monte-Carlo and particle counts so every notebook runs
in CI in seconds; full mode reproduces the papers. Every run takes an explicit seed or
``numpy.random.Generator``; independent trials get independent child streams via
``SeedSequence.spawn`` so results do not depend on how the work is split.

The runs themselves, serial or on a Dask cluster, go through :func:`tunnelkit.runner.run_trials`.
"""

from __future__ import annotations

import os

import numpy as np

from ._validate import integer
from .budget import check_bytes

__all__ = ["QUICK", "RUN_BYTES", "mc_count", "quick_mode", "spawn_rngs"]

#: memory one run holds at least: its generator (about 1 KiB measured) and its result slot
RUN_BYTES = 1024

_TRUE = {"1", "true", "yes", "on"}


def quick_mode() -> bool:
    """True when the environment variable ``TUNNELKIT_QUICK`` is set to 1/true/yes/on."""
    return os.environ.get("TUNNELKIT_QUICK", "").strip().lower() in _TRUE


#: quick mode as read at import time (notebooks read it once in their setup cell)
QUICK = quick_mode()


def mc_count(full: int, quick: int) -> int:
    """``quick`` in quick mode, else ``full`` (both positive integers)."""
    integer("full", full, minimum=1)
    integer("quick", quick, minimum=1)
    return quick if quick_mode() else full


def spawn_rngs(seed: int | np.random.Generator, n: int) -> list[np.random.Generator]:
    """``n`` independent generators derived from ``seed`` (an int or a Generator)."""
    n = integer("n", n, minimum=1)
    check_bytes("n", n * RUN_BYTES, f"{n} generators of about {RUN_BYTES} B")
    if isinstance(seed, np.random.Generator):
        return list(seed.spawn(n))
    seed = integer("seed", seed, minimum=0)
    return [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(n)]
