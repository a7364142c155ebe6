"""Quick mode and seeded Monte-Carlo runs.

Quick mode (``TUNNELKIT_QUICK=1``) shrinks Monte-Carlo and particle counts so every notebook runs
in CI in seconds; full mode reproduces the papers. Every run takes an explicit seed or
``numpy.random.Generator``; independent trials get independent child streams via
``SeedSequence.spawn`` so results do not depend on how the work is split.

Parallel runs (:func:`run_trials`): serial by default; ``workers=N`` starts a
``dask.distributed.LocalCluster`` of ``N`` single-threaded processes on 127.0.0.1 (dashboard off)
for the run and stops it afterwards; ``scheduler="tcp://HOST:8786"`` sends the trials to a running
Dask cluster (``dask scheduler`` / ``dask worker``), failing with :class:`SchedulerUnreachable`
after ``timeout`` seconds if nothing answers. Each trial gets the child generator it would get in a
serial run, shipped as bytes so a rescheduled trial restarts its stream, results come back in
trial order, and every trial runs with single-threaded BLAS (threadpoolctl): the same seed gives
identical results serially, on 1 or on N workers. A trial whose worker dies is
rescheduled by Dask (up to ``distributed.scheduler.allowed-failures`` deaths, default 3); past
that the run stops with :class:`TrialLost` naming the trial, never a statistic without it.
``retries`` re-runs a trial that raised (off by default: a seeded trial fails the same way twice).
Trial functions must be picklable: module-level functions, bound with ``functools.partial``.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import uuid
from collections.abc import Callable, Iterator, Sequence
from typing import Any
from urllib.parse import urlsplit

import numpy as np

from ._validate import integer, positive

__all__ = [
    "CONNECT_TIMEOUT_S",
    "QUICK",
    "SchedulerUnreachable",
    "TrialLost",
    "mc_count",
    "parallel_options",
    "quick_mode",
    "run_trials",
    "spawn_rngs",
]

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
    if isinstance(seed, np.random.Generator):
        return list(seed.spawn(n))
    seed = integer("seed", seed, minimum=0)
    return [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(n)]


#: seconds to wait for a scheduler given by address before :class:`SchedulerUnreachable`
CONNECT_TIMEOUT_S = 10.0


class SchedulerUnreachable(ConnectionError, ValueError):
    """No Dask scheduler answered at the address given as ``scheduler`` within the timeout."""


class TrialLost(RuntimeError):
    """A trial's worker died more often than Dask allows; the run stops rather than drop it."""


def run_trials(
    trial: Callable[..., Any],
    runs: int,
    seed: int | np.random.Generator,
    *,
    progress: bool = False,
    desc: str = "trials",
    inputs: Sequence[Any] | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    retries: int = 0,
    timeout: float = CONNECT_TIMEOUT_S,
) -> list[Any]:
    """Call ``trial(rng)`` ``runs`` times with independent seeded generators, optionally with tqdm."""
    rngs = spawn_rngs(seed, runs)
    # ``trial(inputs[i], rng_i)`` when ``inputs`` is given; parallel options: module docstring
    calls = _calls(rngs, inputs)
    workers, scheduler = parallel_options(workers, scheduler)
    retries = integer("retries", retries, minimum=0)
    timeout = positive("timeout", timeout)
    if workers is None and scheduler is None:
        return _run_serial(trial, calls, progress, desc)
    with _client(workers, scheduler, timeout) as client:
        return _run_dask(client, trial, calls, progress, desc, retries)


def _calls(rngs: list[np.random.Generator], inputs) -> list[tuple[tuple, np.random.Generator]]:
    """``(leading arguments, rng)`` per trial."""
    if inputs is None:
        return [((), r) for r in rngs]
    if isinstance(inputs, np.ndarray):
        inputs = list(inputs)
    if isinstance(inputs, str | bytes) or not isinstance(inputs, Sequence):
        raise TypeError(f"inputs: expected a sequence (one item per trial), got {inputs!r}")
    if len(inputs) != len(rngs):
        raise ValueError(f"inputs: expected {len(rngs)} items (runs), got {len(inputs)}")
    return [((x,), r) for x, r in zip(inputs, rngs)]


def _bar(total: int, progress: bool, desc: str):
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, leave=False, disable=not progress)


def _one_blas_thread():
    """Single-threaded BLAS for the trials, serial or on a worker: a multi-threaded BLAS splits
    its sums by the machine's core count, and the last bits of the results with them."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")


def _run_serial(trial, calls, progress: bool, desc: str) -> list[Any]:
    out = []
    with _bar(len(calls), progress, desc) as bar, _one_blas_thread():
        for args, rng in calls:
            out.append(trial(*args, rng))
            bar.update()
    return out


def parallel_options(
    workers: int | None = None, scheduler: str | None = None
) -> tuple[int | None, str | None]:
    """Check ``workers`` (an integer >= 1) and ``scheduler`` (``[tcp://]HOST:PORT``), at most one
    given; returns them with the address normalised (``tcp://`` added when no scheme is given)."""
    if workers is not None and scheduler is not None:
        raise ValueError(
            "workers, scheduler: give one or the other (a local cluster of N processes, or the "
            f"address of a running one), got workers={workers!r} and scheduler={scheduler!r}"
        )
    if workers is not None:
        workers = integer("workers", workers, minimum=1)
    if scheduler is not None:
        scheduler = _scheduler_address(scheduler)
    return workers, scheduler


_SCHEMES = ("tcp", "tls", "ws", "wss")


def _scheduler_address(address) -> str:
    if not isinstance(address, str):
        raise TypeError(
            f"scheduler: expected an address such as 'tcp://HOST:8786', got {address!r}"
        )
    text = address.strip()
    full = text if "://" in text else f"tcp://{text}"
    bad = ValueError(
        f"scheduler: expected an address such as 'tcp://HOST:8786' "
        f"(scheme one of {', '.join(_SCHEMES)}), got {address!r}"
    )
    try:
        parts = urlsplit(full)
        port = parts.port
    except ValueError as exc:
        raise bad from exc
    if (
        parts.scheme not in _SCHEMES
        or not parts.hostname
        or port is None
        or port == 0
        or parts.path not in ("", "/")
        or parts.query
        or parts.fragment
        or parts.username
    ):
        raise bad
    return full.rstrip("/")


@contextlib.contextmanager
def _client(workers: int | None, scheduler: str | None, timeout: float) -> Iterator[Any]:
    """A ``distributed.Client`` on a fresh local cluster or on ``scheduler``, closed on exit."""
    import logging

    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=timeout, set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise SchedulerUnreachable(
                f"scheduler: no Dask scheduler answered at {scheduler} within {timeout:g} s "
                "(is `dask scheduler` running there, and the port reachable?)"
            ) from exc
        with client:
            yield client
        return
    with (
        LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            scheduler_port=0,
            # no dashboard; the scheduler's health/metrics HTTP server on a free loopback port
            dashboard_address="127.0.0.1:0",
            scheduler_kwargs={"dashboard": False},
            silence_logs=logging.CRITICAL,  # shutdown races log heartbeat errors
        ) as cluster,
        Client(cluster, set_as_default=False) as client,
    ):
        yield client


def _one_trial(trial, args: tuple, rng_bytes: bytes):
    """Worker side: a fresh copy of the trial's generator, so a rerun replays the same stream."""
    with _one_blas_thread():
        return trial(*args, pickle.loads(rng_bytes))


def _run_dask(client, trial, calls, progress: bool, desc: str, retries: int) -> list[Any]:
    from distributed import as_completed
    from distributed.scheduler import KilledWorker

    tag = uuid.uuid4().hex[:8]
    futures = [
        client.submit(
            _one_trial,
            trial,
            args,
            pickle.dumps(rng),
            key=f"{desc}-{i}-{tag}",
            pure=False,
            retries=retries,
        )
        for i, (args, rng) in enumerate(calls)
    ]
    index = {f.key: i for i, f in enumerate(futures)}
    out: list[Any] = [None] * len(futures)
    with _bar(len(futures), progress, desc) as bar:
        for fut in as_completed(futures, loop=client.loop):
            i = index[fut.key]
            try:
                out[i] = fut.result()
            except KilledWorker as exc:
                raise TrialLost(
                    f"trial {i} of {len(futures)} ({desc}): its worker died each time it ran "
                    "(Dask's distributed.scheduler.allowed-failures); the run is stopped rather "
                    "than reported without it"
                ) from exc
            except Exception as exc:
                exc.add_note(f"raised by trial {i} of {len(futures)} ({desc}) on a Dask worker")
                raise
            bar.update()
    return out
