"""Where trials run: the two options every parallel command takes (``workers``, a local cluster
of N processes, or ``scheduler``, the address of a running Dask scheduler), checked once.
Kept apart from :mod:`tunnelkit.runner` (the Dask plumbing) so a caller that only checks its
options does not load it."""

from __future__ import annotations

from ._validate import integer

__all__ = ["TRIAL_TIMEOUT_S", "parallel_options"]
TRIAL_TIMEOUT_S = 1800.0  # run_trials' time limit [s] (tunnelkit.runner: a stalled run stops)


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
        from ._scheduler import scheduler_address  # the address parsed when one is given

        scheduler = scheduler_address(scheduler)
    return workers, scheduler
