"""Registry of ``tunnelkit reproduce`` targets: one paper result each, "paper" beside "ours".

Adding a target is one module in this package with one decorated function::

    @register("jiang-crlb", help="...", default_runs=2000)
    def jiang_crlb(runs: int, seed: int, progress: bool, **parallel) -> Report: ...

``parallel`` holds ``workers``, ``scheduler`` and ``timeout``; the target passes them on to
:func:`tunnelkit.runner.run_trials`, through which all its random trials go (module-level
trial functions bound with ``functools.partial``, so Dask can ship them to other processes). The
report must not depend on them: the same seed gives the same numbers serially or on N workers.

Modules here are imported on first use of :data:`REGISTRY` via :func:`targets`.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass

from .._checks import items
from .._validate import boolean, choice, integer, positive, record, text
from ..budget import check_bytes
from ..montecarlo import RUN_BYTES
from ..odometry import MODELS
from ..report import Report
from ..runner import CONNECT_TIMEOUT_S, parallel_options

__all__ = ["Report", "Target", "register", "run", "targets"]


@dataclass(frozen=True)
class Target:
    """A registered reproduction: ``fn(runs, seed, progress, **parallel) -> Report``."""

    name: str
    help: str
    default_runs: int
    fn: Callable[..., Report]
    bytes_per_run: int = RUN_BYTES  #: memory one run keeps until the report is built
    channels: tuple[str, ...] = ("image",)  #: channel sources it runs on (``fn(channel=...)``)
    lengths: bool = False  #: its drive can be lengthened (``fn(length=...)``)
    #: its V2X messages take a named model and its JAVELIN a motion step (``fn(odometry=...,
    #: motion_step=...)``)
    odometries: bool = False

    def __post_init__(self) -> None:
        record(self, positive=("default_runs", "bytes_per_run"))


_REGISTRY: dict[str, Target] = {}
_DISCOVERED = False
#: the module of each target: :func:`run` imports only that one (notebook 01's ``jiang-crlb``
#: loads no tracker or drive simulator); :func:`targets` imports them all
TARGET_MODULES = {
    "halili": "halili",
    "javelin-table1": "javelin_tables",
    "javelin-table2": "javelin_tables",
    "jiang-crlb": "jiang_crlb",
    "jiang-table2": "jiang_tables",
    "jiang-table3": "jiang_tables",
}


def register(
    name: str,
    *,
    help: str,
    default_runs: int,
    bytes_per_run: int = RUN_BYTES,
    channels: tuple[str, ...] = ("image",),
    lengths: bool = False,
    odometries: bool = False,
):
    """Decorator registering a reproduction target under ``name``.

    ``bytes_per_run`` is what one Monte-Carlo run keeps in memory until the report is built;
    ``runs * bytes_per_run`` is checked against :mod:`tunnelkit.budget` before anything runs.
    ``channels``: the channel sources the target runs on; with more than "image" its function
    takes ``channel=``. ``lengths``: its drive can be lengthened (its function takes
    ``length=``, metres). ``odometries``: its drives' V2X messages take a named model of
    :data:`tunnelkit.odometry.MODELS` (its function takes ``odometry=``).
    """
    text("name", name), text("help", help), boolean("lengths", lengths)
    boolean("odometries", odometries)
    integer("default_runs", default_runs, minimum=1)
    integer("bytes_per_run", bytes_per_run, minimum=1)
    [text(f"channels[{i}]", c) for i, c in enumerate(items("channels", channels, str))]

    def deco(fn):
        if name in _REGISTRY:
            raise ValueError(f"name: reproduce target {name!r} registered twice")
        _REGISTRY[name] = Target(
            name,
            help,
            default_runs,
            fn,
            bytes_per_run,
            tuple(channels),
            bool(lengths),
            bool(odometries),
        )
        return fn

    return deco


def targets() -> dict[str, Target]:
    """All targets, importing every module of this package once."""
    global _DISCOVERED
    if not _DISCOVERED:
        for mod in pkgutil.iter_modules(__path__):
            importlib.import_module(f"{__name__}.{mod.name}")
        _DISCOVERED = True
    return dict(sorted(_REGISTRY.items()))


def run(
    name: str,
    *,
    runs: int | None = None,
    seed: int = 0,
    progress: bool = False,
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float = CONNECT_TIMEOUT_S,
    channel: str = "image",
    nuisance: dict | None = None,
    length: float | None = None,
    odometry: str = "white",
    told_odometry: bool = False,
    motion_step: str | None = None,
) -> Report:
    """Run target ``name`` with ``runs`` Monte-Carlo runs (its default if None) and ``seed``,
    serially or on Dask (``workers`` local processes, or a running ``scheduler``; see
    :func:`tunnelkit.runner.run_trials`). The report is the same either way. ``channel``:
    "image" (default) or, for the targets that support it, "sionna" (the ray-traced channel).
    ``nuisance`` (those targets only): the route's ``second_order`` / ``diffuse_floor``
    (:class:`tunnelkit.signal_route.SignalRoute`). ``length`` (the targets whose drive can be
    lengthened: javelin-table1): the drive over ``length`` metres ending where the preset's ends
    (:func:`tunnelkit.simulation.variants.drive_variant`, e.g. 120). ``odometry`` (the targets with
    a drive: javelin-table1|2): the V2X messages' model, a name of
    :data:`tunnelkit.odometry.MODELS` ("white", the paper's, by default; "automotive");
    ``told_odometry``: JAVELIN is told that model (its bias states; a model other than white);
    ``motion_step`` (the same targets): how JAVELIN steps on the messages, ``None`` (default)
    as each design does (the paper's eq. 62, ours the midpoint of two messages), or every design
    the same, eq. 62's ``"held"`` or ``"midpoint"``
    (:data:`tunnelkit.tracking.javelin.config.MOTION_STEPS`)."""
    if isinstance(name, str) and name in TARGET_MODULES:
        importlib.import_module(f"{__name__}.{TARGET_MODULES[name]}")
    reg = _REGISTRY if isinstance(name, str) and name in _REGISTRY else targets()
    if name not in reg:
        raise ValueError(f"name: unknown reproduce target {name!r}; available: {', '.join(reg)}")
    tgt = reg[name]
    if channel not in tgt.channels:
        raise ValueError(
            f"channel: target {name!r} runs on {', '.join(map(repr, tgt.channels))}, "
            f"not {channel!r}"
        )
    on = {} if channel == "image" else {"channel": channel}
    if nuisance is not None:
        if tgt.channels == ("image",):
            raise ValueError(
                f"nuisance: target {name!r} has no route model to extend (only the targets with "
                "a channel switch do)"
            )
        if not isinstance(nuisance, dict):
            raise TypeError(f"nuisance: expected a dict, got {type(nuisance).__name__}")
        on["nuisance"] = nuisance
    if length is not None:
        if not tgt.lengths:
            raise ValueError(
                f"length: target {name!r} drives its preset only (javelin-table1 takes a length)"
            )
        on["length"] = positive("length", length)
    if odometry != "white":
        choice("odometry", odometry, tuple(MODELS))
        if not tgt.odometries:
            raise ValueError(
                f"odometry: target {name!r} has no V2X messages to model (javelin-table1|2 do)"
            )
        on["odometry"] = odometry
    if told_odometry:
        if odometry == "white":
            raise ValueError("told_odometry: needs an odometry model other than the white one")
        on["told_odometry"] = True
    if motion_step is not None:
        choice("motion_step", motion_step, ("held", "midpoint"))
        if not tgt.odometries:
            raise ValueError(
                f"motion_step: target {name!r} runs no tracker on V2X messages (javelin-table1|2 "
                "do)"
            )
        on["motion_step"] = motion_step
    runs = tgt.default_runs if runs is None else integer("runs", runs, minimum=1)
    seed = integer("seed", seed, minimum=0)
    check_bytes("runs", runs * tgt.bytes_per_run, f"{runs} runs of about {tgt.bytes_per_run} B")
    workers, scheduler = parallel_options(workers, scheduler)
    timeout = positive("timeout", timeout)
    rep = tgt.fn(runs, seed, progress, workers=workers, scheduler=scheduler, timeout=timeout, **on)
    rep.meta = {"target": name, "runs": runs, "seed": seed, **rep.meta}
    return rep
