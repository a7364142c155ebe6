"""Quick mode and seeded Monte-Carlo runs.

Quick mode (``TUNNELKIT_QUICK=1``) shrinks Monte-Carlo and particle counts so every notebook runs
in CI in seconds; full mode reproduces the papers. Every run takes an explicit seed or
``numpy.random.Generator``; independent trials get independent child streams via
``SeedSequence.spawn`` so results do not depend on how the work is split.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np

from ._validate import callable_, integer
from .budget import check_bytes

__all__ = ["QUICK", "RUN_BYTES", "mc_count", "quick_mode", "run_trials", "spawn_rngs"]

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


def run_trials(
    trial: Callable[[np.random.Generator], Any],
    runs: int,
    seed: int | np.random.Generator,
    *,
    progress: bool = False,
    desc: str = "trials",
) -> list[Any]:
    """Call ``trial(rng)`` ``runs`` times with independent seeded generators, optionally with tqdm."""
    callable_("trial", trial)
    runs = integer("runs", runs, minimum=1)
    check_bytes("runs", runs * RUN_BYTES, f"{runs} runs of at least {RUN_BYTES} B each")
    rngs = spawn_rngs(seed, runs)
    it = rngs
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(rngs, desc=desc, leave=False)
    return [trial(r) for r in it]
