"""The Monte-Carlo runner: seeded trials run serially or on a Dask cluster.

Runs are serial by default; ``workers=N`` starts a
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
Trial functions must be picklable: module-level functions, bound with ``functools.partial``; the
trial object is sent to the cluster once per run (the result of one task that every trial
depends on, fetched once by each worker and recomputed if its holder dies), not with every task.
Trials go in tasks of a few trials each (:data:`CHUNKS_PER_THREAD`), and an input may be a handle of
:meth:`TrialPool.prepare` (per-item state built on the cluster, e.g. one model per array, that
its trials fetch worker to worker).

Bad input and stalls: ``workers`` beyond the cores this process may use is capped to them (with a
:class:`RuntimeWarning`: more single-threaded processes than cores only add overhead); a
scheduler address that accepts the connection but never answers fails with
:class:`SchedulerUnreachable` after ``timeout`` seconds (the address is probed with Dask's
``identity`` call under a hard deadline before a client is built); ``trial_timeout`` (default
:data:`TRIAL_TIMEOUT_S`, half an hour) stops a run with :class:`TrialTimeout` when a trial runs
longer than that serially, or on Dask when no task has finished for that long times the trials
per task (one task holds a few trials, :data:`CHUNKS_PER_THREAD`). ``streams`` lets several trials share one child generator
(common random numbers: e.g. the same drive noise for every candidate array).


The seeds and quick mode are :mod:`tunnelkit.montecarlo`'s.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import uuid
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np

from ._checks import attributes
from ._parallel import TRIAL_TIMEOUT_S, parallel_options
from ._validate import boolean, callable_, integer, positive, sequence, text
from .budget import check_bytes
from .montecarlo import RUN_BYTES, spawn_rngs

__all__ = [
    "CONNECT_TIMEOUT_S",
    "TRIAL_TIMEOUT_S",
    "SchedulerUnreachable",
    "TrialLost",
    "TrialPool",
    "TrialTimeout",
    "available_cores",
    "parallel_options",
    "run_trials",
    "trial_pool",
]


#: seconds to wait for a scheduler given by address before :class:`SchedulerUnreachable`
CONNECT_TIMEOUT_S = 10.0


class SchedulerUnreachable(ConnectionError, ValueError):
    """No Dask scheduler answered at the address given as ``scheduler`` within the timeout."""


class TrialLost(RuntimeError):
    """A trial's worker died more often than Dask allows; the run stops rather than drop it."""


class TrialTimeout(TimeoutError):
    """A trial ran past ``trial_timeout`` (serially), or no trial finished for that long (Dask)."""


def available_cores() -> int:
    """The number of CPU cores this process may run on (its affinity mask where the platform
    has one, else ``os.cpu_count()``)."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # pragma: no cover - platforms without sched_getaffinity
        return max(os.cpu_count() or 1, 1)


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
    trial_timeout: float | None = TRIAL_TIMEOUT_S,
    streams: Sequence[int] | None = None,
    shared_streams: bool = False,
    pool: TrialPool | None = None,
) -> list[Any]:
    """Call ``trial(rng)`` ``runs`` times with independent seeded generators, optionally with tqdm.

    ``streams`` (one non-negative integer per trial): trial ``i`` gets a fresh copy of child
    generator ``streams[i]`` of ``seed`` (trials with the same stream see the same random
    numbers: a stream given twice is refused unless ``shared_streams``, common random numbers
    meant); default: trial ``i`` gets child ``i``. ``trial_timeout`` [s] (default
    :data:`TRIAL_TIMEOUT_S`, ``None`` no limit): see the module docstring. ``pool``: a :func:`trial_pool` already open (instead of ``workers`` /
    ``scheduler``), so several steps share one cluster. Other options: module docstring."""
    callable_("trial", trial)
    runs = integer("runs", runs, minimum=1)
    check_bytes("runs", runs * RUN_BYTES, f"{runs} runs of at least {RUN_BYTES} B each")
    rngs = _stream_rngs(seed, runs, streams, boolean("shared_streams", shared_streams))
    # ``trial(inputs[i], rng_i)`` when ``inputs`` is given; parallel options: module docstring
    calls = _calls(rngs, inputs)
    workers, scheduler = parallel_options(workers, scheduler)
    retries = integer("retries", retries, minimum=0)
    progress, desc = boolean("progress", progress), text("desc", desc)
    timeout = positive("timeout", timeout)
    trial_timeout = positive("trial_timeout", trial_timeout, none=True)
    if pool is not None:
        if not isinstance(pool, TrialPool):
            raise TypeError(f"pool: expected a runner.TrialPool, got {type(pool).__name__}")
        if workers is not None or scheduler is not None:
            raise ValueError(
                "pool, workers, scheduler: give a pool or where to start one, not both"
            )
        if pool.client is None:
            return _run_serial(trial, calls, progress, desc, trial_timeout)
        return _run_dask(pool.client, trial, calls, progress, desc, retries, trial_timeout)
    workers = _capped(workers)
    if workers is None and scheduler is None:
        return _run_serial(trial, calls, progress, desc, trial_timeout)
    with _client(workers, scheduler, timeout) as client:
        return _run_dask(client, trial, calls, progress, desc, retries, trial_timeout)


def _capped(workers: int | None) -> int | None:
    if workers is not None and workers > available_cores():
        import warnings

        warnings.warn(
            f"workers: {workers} processes on {available_cores()} core(s): capped to "
            f"{available_cores()} (give a scheduler address to use a larger cluster)",
            RuntimeWarning,
            stacklevel=3,
        )
        return available_cores()
    return workers


class TrialPool:
    """Where a Monte-Carlo runs (:func:`trial_pool`): serially in this process (``client``
    None) or on one Dask client that several steps share, e.g. a sweep that builds a model per
    array (:meth:`prepare`) and runs its trials on them (``run_trials(..., pool=pool)``) on the
    same cluster, started once."""

    def __init__(self, client=None) -> None:
        if client is not None:
            attributes("client", client, ("submit",), "a dask.distributed Client")
        self.client = client

    @property
    def parallel(self) -> bool:
        return self.client is not None

    def map(self, fn: Callable[[Any], Any], items: Sequence[Any], desc: str = "tasks") -> list:
        """``[fn(x) for x in items]`` in order, one task per item on the cluster (single-threaded
        BLAS, as the trials), serially without one. ``fn`` and the items must be picklable."""
        return self.gather(self.prepare(fn, items, desc))

    def prepare(self, fn: Callable[[Any], Any], items: Sequence[Any], desc: str = "tasks") -> list:
        """:meth:`map` leaving each result on its worker (a future; serially the value). As
        :func:`run_trials` ``inputs``, a trial's task depends on its item's only (no barrier)
        and fetches it worker to worker. Submitted in order: put the longest item first."""
        fn, desc = callable_("fn", fn), text("desc", desc)
        items = sequence("items", items, empty=True)
        if self.client is None:
            with _one_blas_thread():
                return [fn(x) for x in items]
        tag = uuid.uuid4().hex[:8]
        return [
            self.client.submit(_one_call, fn, x, key=f"{PREPARE_KEY}-{i}-{tag}", pure=False)
            for i, x in enumerate(items)
        ]

    def gather(self, handles: Sequence[Any]) -> list:
        """The values of :meth:`prepare`'s handles, in order."""
        handles = sequence("handles", handles, empty=True)
        return handles if self.client is None else self.client.gather(handles)


def trial_pool(
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float = CONNECT_TIMEOUT_S,
) -> contextlib.AbstractContextManager[TrialPool]:
    """A :class:`TrialPool` (a context manager, its arguments checked at the call): serial without
    ``workers`` / ``scheduler``, else one local cluster of ``workers`` processes (capped to the
    cores, as :func:`run_trials`) or the cluster at ``scheduler``, closed on exit."""
    workers, scheduler = parallel_options(workers, scheduler)
    timeout = positive("timeout", timeout)
    return _trial_pool(_capped(workers), scheduler, timeout)


@contextlib.contextmanager
def _trial_pool(workers, scheduler, timeout) -> Iterator[TrialPool]:
    if workers is None and scheduler is None:
        yield TrialPool(None)
        return
    with _client(workers, scheduler, timeout) as client:
        yield TrialPool(client)


def _one_call(fn, x):
    """Worker side of :meth:`TrialPool.map`."""
    with _one_blas_thread():
        return fn(x)


def _stream_rngs(seed, runs: int, streams, shared: bool = False) -> list[np.random.Generator]:
    """One generator per trial: child ``i`` of ``seed``, or child ``streams[i]`` (copied, so
    trials sharing a stream start from the same state: refused unless ``shared``)."""
    if streams is None:
        return spawn_rngs(seed, runs)
    if isinstance(streams, str | bytes) or not isinstance(streams, Sequence | np.ndarray):
        raise TypeError(
            f"streams: expected a sequence of integers (one per trial), got {streams!r}"
        )
    idx = [integer("streams", s, minimum=0) for s in streams]
    if len(idx) != runs:
        raise ValueError(f"streams: expected {runs} values (runs), got {len(idx)}")
    if not shared and len(set(idx)) < len(idx):
        twice = next(i for i in idx if idx.count(i) > 1)
        raise ValueError(
            f"streams: stream {twice} is given {idx.count(twice)} times, and trials of one stream "
            "see the same random numbers; pass shared_streams=True where that is meant (common "
            "random numbers)"
        )
    children = spawn_rngs(seed, max(idx) + 1)
    return [pickle.loads(pickle.dumps(children[i])) for i in idx]


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


@contextlib.contextmanager
def _alarm(seconds: float | None, what: str) -> Iterator[None]:
    """Raise :class:`TrialTimeout` in this thread after ``seconds`` (``SIGALRM``; only where
    signals reach this thread: the main thread of a POSIX process, else no limit)."""
    import signal
    import threading

    if (
        seconds is None
        or not hasattr(signal, "setitimer")
        or threading.current_thread() is not threading.main_thread()
    ):
        yield
        return

    import time

    # a run inside a trial (nested limits): the outer limit's time keeps running and is restored
    outer, _ = signal.getitimer(signal.ITIMER_REAL)
    t0 = time.monotonic()

    def _fire(signum, frame):
        if 0 < outer <= seconds and callable(old):  # the outer deadline came first: its handler
            return old(signum, frame)
        raise TrialTimeout(f"{what} ran longer than trial_timeout = {seconds:g} s")

    old = signal.signal(signal.SIGALRM, _fire)
    signal.setitimer(signal.ITIMER_REAL, min(seconds, outer) if outer > 0 else seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
        if outer > 0:
            signal.setitimer(signal.ITIMER_REAL, max(outer - (time.monotonic() - t0), 1e-3))


def _run_serial(
    trial, calls, progress: bool, desc: str, trial_timeout: float | None = None
) -> list[Any]:
    out = []
    with _bar(len(calls), progress, desc) as bar, _one_blas_thread():
        for i, (args, rng) in enumerate(calls):
            with _alarm(trial_timeout, f"trial {i} of {len(calls)} ({desc})"):
                out.append(trial(*args, rng))
            bar.update()
    return out


@contextlib.contextmanager
def _client(workers: int | None, scheduler: str | None, timeout: float) -> Iterator[Any]:
    """A ``distributed.Client`` on a fresh local cluster or on ``scheduler``, closed on exit."""
    import logging

    import dask
    from distributed import Client, LocalCluster

    if scheduler is not None:
        _probe_scheduler(scheduler, timeout)
        try:
            client = Client(scheduler, timeout=timeout, set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise _unreachable(scheduler, timeout) from exc
        with client:
            yield client
        return
    # Dask sets MALLOC_TRIM_THRESHOLD_ in its workers, which turns glibc's adaptive mmap threshold
    # off: every large numpy temporary is then a fresh mmap with its page faults (about 25 % more
    # CPU on a JAVELIN drive). A cluster that lives for one run does not need the trimming.
    with (
        dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}),
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


def _unreachable(scheduler: str, timeout: float) -> SchedulerUnreachable:
    return SchedulerUnreachable(
        f"scheduler: no Dask scheduler answered at {scheduler} within {timeout:g} s "
        "(is `dask scheduler` running there, and the port reachable?)"
    )


def _probe_scheduler(scheduler: str, timeout: float) -> None:
    """Ask ``scheduler`` for its identity under a hard deadline of ``timeout`` seconds: a server
    that accepts the TCP connection and never answers would otherwise hold ``Client()`` past
    its own connect timeout. Runs on a private event loop in a helper thread (the caller may
    already run one, e.g. a notebook kernel)."""
    import asyncio
    import concurrent.futures

    from distributed.comm import connect

    async def identity():
        comm = await connect(scheduler, timeout=timeout)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    async def bounded():
        return await asyncio.wait_for(identity(), timeout)

    pool = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="tunnelkit-probe")
    try:
        reply = pool.submit(asyncio.run, bounded()).result(timeout + 5.0)
    except (OSError, TimeoutError, concurrent.futures.TimeoutError) as exc:
        raise _unreachable(scheduler, timeout) from exc
    finally:
        pool.shutdown(wait=False)
    if not isinstance(reply, dict) or reply.get("type") != "Scheduler":
        raise SchedulerUnreachable(
            f"scheduler: the server at {scheduler} answered, but not as a Dask scheduler "
            f"(identity reply {str(reply)[:80]!r})"
        )


def _hold(trial):
    """Worker side: the trial object itself (see :func:`_run_dask`)."""
    return trial


def _trial_chunk(trial, chunk: list, n: int, desc: str) -> list:
    """Worker side: the trials ``chunk`` = ``[(i, args, rng_bytes)]`` in order, each on a fresh
    copy of its generator (a rerun replays the same streams), single-threaded BLAS."""
    out = []
    with _one_blas_thread():
        for i, args, rng_bytes in chunk:
            try:
                out.append(trial(*args, pickle.loads(rng_bytes)))
            except Exception as exc:
                exc.add_note(f"raised by trial {i} of {n} ({desc}) on a Dask worker")
                raise
    return out


#: the prefixes of the tasks' keys: the trial every task depends on, the tasks of trials, a
#: pool's prepared items. Fixed words, never the run's ``desc``: Dask groups tasks by the key's
#: leading words (``dask.utils.key_split``), and a ``desc`` such as ``"italiano2026-slalom
#: drives"`` put the shared trial in its tasks' group; the scheduler then placed every task on
#: the one worker holding it and estimated their length from its (microseconds), so none was
#: ever stolen: a 20-run traced table ran on one of two workers
TRIAL_KEY, CHUNK_KEY, PREPARE_KEY = "trial-object", "trial-chunk", "prepared-item"

#: trials go in about this many tasks per worker thread (a task costs the scheduler and the
#: worker a few ms; several per thread keep the end of the run balanced); the time limit counts
#: from the last finished task, ``trial_timeout`` per trial it holds
CHUNKS_PER_THREAD = 8


def _chunk_size(n: int, threads: int) -> int:
    return -(-n // (CHUNKS_PER_THREAD * max(threads, 1)))


def _run_dask(
    client, trial, calls, progress: bool, desc: str, retries: int, trial_timeout=None
) -> list[Any]:
    from distributed import as_completed
    from distributed.scheduler import KilledWorker

    tag = uuid.uuid4().hex[:8]
    n = len(calls)
    # the trial (it may carry a large model) is one task's result, fetched once per worker, not
    # sent with every task; unlike scattered data it is recomputed if a worker holding it dies
    shared = client.submit(_hold, trial, key=f"{TRIAL_KEY}-{tag}", pure=False)
    size = _chunk_size(n, sum(client.nthreads().values()))
    # no task finished for this long: a task of ``size`` trials may take ``size`` trial times
    stall = None if trial_timeout is None else trial_timeout * size
    chunks = [list(range(i, min(i + size, n))) for i in range(0, n, size)]
    futures = [
        client.submit(
            _trial_chunk,
            shared,
            [(i, calls[i][0], pickle.dumps(calls[i][1])) for i in idx],
            n,
            desc,
            key=f"{CHUNK_KEY}-{idx[0]}-{tag}",
            pure=False,
            retries=retries,
        )
        for idx in chunks
    ]
    index = {f.key: c for c, f in enumerate(futures)}
    out: list[Any] = [None] * n
    with _bar(n, progress, desc) as bar:
        for fut in _as_completed(as_completed, futures, client, stall, chunks, index, desc):
            idx = chunks[index[fut.key]]
            try:
                out[idx[0] : idx[-1] + 1] = fut.result()
            except KilledWorker as exc:
                who = f"trial {idx[0]}" if len(idx) == 1 else f"trials {idx[0]}-{idx[-1]}"
                raise TrialLost(
                    f"{who} of {n} ({desc}) was lost: the workers holding it died more "
                    "often than Dask allows (distributed.scheduler.allowed-failures); the run is "
                    "stopped rather than reported without it"
                ) from exc
            bar.update(len(idx))
    return out


def _cancel_late(futures, chunks, index) -> str:
    """Cancel every future and name the trials that had not finished ("trials [..] of N")."""
    late = sorted(i for f in futures if not f.done() for i in chunks[index[f.key]])
    for f in futures:
        f.cancel()
    n = sum(len(c) for c in chunks)
    return f"trials {late[:10]}{' ...' if len(late) > 10 else ''} of {n}"


NO_WORKER_WAIT_S = 120.0
"""Seconds a Dask run waits for a worker when its cluster has none (a nanny restarting a killed
worker on a loaded machine takes seconds; a cluster whose workers are all gone never finishes)."""

#: seconds between the checks for a cluster left without workers while a Dask run waits
WORKER_CHECK_S = 1.0


def _as_completed(as_completed, futures, client, trial_timeout, chunks, index, desc):
    """Futures as they finish; :class:`TrialTimeout` when none finished for ``trial_timeout``,
    :class:`TrialLost` when the cluster has had no worker for ``NO_WORKER_WAIT_S``. Blocks
    until a finish, the timeout or :data:`WORKER_CHECK_S` (then asks for the workers)."""
    import time

    ac = as_completed(futures, loop=client.loop)
    cond = ac.thread_condition  # notified by Dask when a future joins the finished queue
    left, last = len(futures), time.monotonic()
    workerless = None
    while left:
        now = time.monotonic()
        tick = WORKER_CHECK_S
        if trial_timeout is not None:
            tick = min(tick, max(trial_timeout - (now - last), 0.0) + 1e-3)
        with cond:  # checked under the lock: a finish between the check and the wait wakes it
            if not ac.has_ready():
                cond.wait(timeout=tick)
        batch = ac.next_batch(block=False) if ac.has_ready() else []
        now = time.monotonic()
        if not batch:
            # a cluster left without workers never finishes anything
            workerless = None if client.nthreads() else (workerless or now)
            if workerless is not None and now - workerless > NO_WORKER_WAIT_S:
                raise TrialLost(
                    f"{_cancel_late(futures, chunks, index)} ({desc}) were lost: the cluster "
                    f"has had no worker for {NO_WORKER_WAIT_S:g} s (workers died and were not "
                    "restarted)"
                )
            if trial_timeout is not None and now - last > trial_timeout:
                raise TrialTimeout(
                    f"{_cancel_late(futures, chunks, index)} ({desc}): none finished within "
                    f"{trial_timeout:g} s (trial_timeout times the trials per task)"
                )
            continue
        last = now
        left -= len(batch)
        yield from sorted(batch, key=lambda f: index[f.key])
