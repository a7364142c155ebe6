"""Seeded drives for the tables and the ablation: one Monte-Carlo trial per drive.

:func:`collect_routes` runs ``runs`` drives per condition through the signal route (the expensive
part), each measured through several extraction routes from the same tensors, on
:func:`tunnelkit.runner.run_trials` (serial, a local Dask cluster or a running one; drive
``i`` draws from the ``i``-th child of the seed, so the result does not depend on where it ran).
:func:`per_drive` is the runner under it, for studies that score each drive where it ran.
"""

from __future__ import annotations

import functools

from .._validate import boolean, callable_, integer, sequence, text
from ..budget import check_bytes
from ..montecarlo import RUN_BYTES
from ..runner import run_trials
from .drives import route_name, simulate_routes

__all__ = ["collect_drives", "collect_routes", "per_drive", "simulate_condition"]


def simulate_condition(
    scenario: str,
    n_epochs: int | None,
    extractions: tuple[str, ...],
    cond: str,
    rng,
    *,
    channel: str = "image",
    nuisance: dict | None = None,
    odometry=None,
):
    """One drive of condition ``cond`` of ``scenario`` through the signal route on ``channel``
    ("image" or "sionna"), measured through every route in ``extractions``
    (:func:`~tunnelkit.simulation.drives.simulate_routes`); the argument order suits
    ``functools.partial`` and :func:`per_drive`'s ``(cond, rng)``; ``nuisance`` the route's
    ``second_order`` / ``diffuse_floor`` (:func:`~tunnelkit.simulation.drives.scenario_route`);
    ``odometry`` the V2X messages' model (:class:`tunnelkit.odometry.Odometry`, None: the
    drive's own, its scenario's ``[odometry]``)."""
    if cond is not None:
        text("cond", cond)
    return simulate_routes(
        scenario,
        rng,
        condition=cond,
        n_epochs=n_epochs,
        extractions=extractions,
        channel=channel,
        nuisance=nuisance,
        odometry=odometry,
    )


def per_drive(scenario, conditions, runs, seed, progress, extractions, make_trial, **parallel):
    """One trial of :func:`~tunnelkit.runner.run_trials` per drive: drive ``i`` (run
    ``i // n``, condition ``i % n``) draws from the ``i``-th child of ``seed``. ``make_trial``
    gets the route names (``extractions``, normalised) and returns the trial ``(cond, rng)``.
    Returns the route names and ``[(condition, result), ...]`` in drive order."""
    text("scenario", scenario)
    sequence("conditions", conditions)
    integer("runs", runs, minimum=1)
    n = max(len(conditions), 1)
    check_bytes("runs", runs * n * RUN_BYTES, f"{runs} runs x {n} conditions, before any is made")
    boolean("progress", progress)
    sequence("extractions", extractions)
    callable_("make_trial", make_trial)
    extractions = tuple(dict.fromkeys(route_name(e) for e in extractions))
    jobs = [c for _ in range(runs) for c in tuple(conditions)]
    results = run_trials(
        make_trial(extractions),
        len(jobs),
        seed,
        inputs=jobs,
        progress=progress,
        desc=f"{scenario} drives",
        **parallel,
    )
    return extractions, list(zip(jobs, results))


def collect_routes(
    scenario: str,
    conditions: tuple[str, ...],
    runs: int,
    seed: int,
    progress: bool = False,
    n_epochs: int | None = None,
    extractions: tuple[str, ...] = ("paper", "ml"),
    channel: str = "image",
    **parallel,
) -> dict[str, dict[str, list]]:
    """``runs`` seeded drives per condition through the signal route (the expensive part), each
    measured through every route in ``extractions`` from the same tensors
    (:func:`~tunnelkit.simulation.drives.simulate_routes`). One trial of
    :func:`~tunnelkit.runner.run_trials` per drive (``parallel``: its ``workers`` /
    ``scheduler`` / ``timeout``): drive ``i`` (run ``i // n``, condition ``i % n``) draws from
    the ``i``-th child of ``seed``. ``n_epochs`` truncates each drive (quick mode); ``channel``
    the channel source (:data:`tunnelkit.signal_route.CHANNELS`). Returns
    ``{extraction: {condition: [DriveData, ...]}}``."""
    text("scenario", scenario)
    sequence("conditions", conditions)
    integer("runs", runs, minimum=1)
    boolean("progress", progress)
    sequence("extractions", extractions)
    extractions, done = per_drive(
        scenario,
        conditions,
        runs,
        seed,
        progress,
        extractions,
        lambda e: functools.partial(simulate_condition, scenario, n_epochs, e, channel=channel),
        **parallel,
    )
    out: dict[str, dict[str, list]] = {e: {c: [] for c in conditions} for e in extractions}
    for cond, routes in done:
        for e, drive in routes.items():
            out[e][cond].append(drive)
    return out


def collect_drives(
    scenario: str,
    conditions: tuple[str, ...],
    runs: int,
    seed: int,
    progress: bool = False,
    n_epochs: int | None = None,
    extraction: str = "paper",
    **parallel,
) -> dict[str, list]:
    """:func:`collect_routes` through one route: ``{condition: [DriveData, ...]}``."""
    text("scenario", scenario)
    sequence("conditions", conditions)
    integer("runs", runs, minimum=1)
    boolean("progress", progress)
    e = route_name(extraction)
    return collect_routes(scenario, conditions, runs, seed, progress, n_epochs, (e,), **parallel)[e]
