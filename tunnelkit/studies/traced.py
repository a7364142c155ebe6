"""The traced design: JAVELIN on the ray-traced channel, told the channel's own errors.

On the ray-traced channel (Sionna RT: diffuse scattering, higher-order bounces, cut-off
wavefronts; ``tunnelkit reproduce javelin-table1|2 --channel sionna``) the ML route's first-order
estimates are 25-40 times further off than on the image channel, and every fit fails its own
residual test. The design of the image channel (:func:`~tunnelkit.tracking.javelin.designs.ours_ml`:
sigmas of 0.23 deg, 0.31 deg, 3.6 m, 3.2 cm) then trusts them far too much. The traced design
changes two things, nothing else:

* **measurement noise**: the RMS extraction error of the ML route on the traced channel
  (:func:`~tunnelkit.simulation.analysis.extraction_errors`, all matched paths pooled), each sigma
  times ``sqrt((1 + r) / (1 - r))`` with ``r`` its lag-1 correlation from epoch to epoch
  (:func:`~tunnelkit.simulation.analysis.error_correlations`: the errors of one path repeat, 0.44
  in azimuth and 0.66 in elevation, and a tracker that takes them as white averages them down
  too far), measured by
  :func:`measure_traced_errors` on the straight drive, seed 0, condition L, :data:`SIGMA_RUNS`
  runs (drive ``i`` from the ``i``-th child of seed 0), and stored with its provenance in
  ``data/rt/traced_errors.json`` (:func:`write_traced_errors`; ``benchmarks/bench_rt_sigmas.py
  --write`` re-measures it); :func:`traced_design` reads it, its scene checked against the
  current one (:func:`~tunnelkit.simulation.prefilter.check_provenance`: the ray tracer's settings and the trace cache's key;
  a record of another scene is refused, never reused);
* **a geometry pre-filter** (:mod:`tunnelkit.simulation.prefilter`): an epoch's paths that do not agree with one UE through the tunnel's
  planes are dropped (:func:`~tunnelkit.simulation.prefilter.geometry_keep`: :func:`tunnelkit.path_consistency.epoch_consistency`
  with the model-error floors :data:`~tunnelkit.simulation.prefilter.FLOORS` alone), and an epoch whose fit failed its residual
  test still carries its measurements (on this channel every fit fails it: the test judges eq. 1,
  not the paths the tracker needs).

The noise stays pooled over the kinds of path. One sigma set per kind of path, each path's
taken from the kind of surface the pre-filter assigns it, was measured and is worse (held-out
seed, 4 drives per table: JAVELIN-L 0.556 / 0.563 m against 0.167 / 0.309 m pooled): the
assigned kind is the true one for 58 % of the matched paths (the road bounce for 4 of 38, mostly
taken for a wall or the LoS), and a road bounce taken for the LoS is given the LoS's 2 deg where
it errs by 13. That per-kind noise model was removed with its benchmark.

:func:`simulate_traced` is the drive simulator (:func:`tunnelkit.simulation.drives.simulate_routes`)
with that adapter beside the ordinary one (:func:`tunnelkit.simulation.drives.path_measurements`,
which drops a flagged epoch), both measuring the ML route's epochs (its ``adapters``): one drive,
the same random draws as ``simulate_routes(extractions=("paper", "ml"))``, returned as
``{"paper", "ml", "ml-all", "ml-traced"}`` (``ml-all``: every epoch's ML measurements, flagged or not, unfiltered).
"""

from __future__ import annotations

import json
import warnings
from functools import partial

import numpy as np

from .._validate import boolean, instance, integer, rng_or_error
from ..budget import check_bytes
from ..montecarlo import RUN_BYTES
from ..runner import run_trials
from ..scenarios import data_dir
from ..simulation.analysis import error_correlations, extraction_errors
from ..simulation.drives import CONDITIONS, DriveData, scenario_route, simulate_routes
from ..simulation.prefilter import (
    FLOORS,
    NUISANCE,
    SIGMA_SCENARIO,
    check_floors,
    check_provenance,
    scene_provenance,
    traced_measurements,
)
from ..tracking.javelin import designs
from ..tracking.javelin.measured import design_from_errors

__all__ = [
    "SIGMA_RUNS",
    "TRACED_ROUTES",
    "measure_traced_errors",
    "simulate_traced",
    "traced_design",
    "traced_errors",
    "write_traced_errors",
]

#: the number of condition-L runs (seed 0) the traced sigmas are measured on
SIGMA_RUNS = 3


#: the routes :func:`simulate_traced` returns
TRACED_ROUTES = ("paper", "ml", "ml-all", "ml-traced")


def _errors_path():
    return data_dir() / "rt" / "traced_errors.json"


def _path(path):
    import os
    from pathlib import Path

    if not isinstance(path, str | os.PathLike) or not str(path):
        raise TypeError(f"path: expected a file path, got {path!r}")
    return Path(path)


def simulate_traced(
    route,
    rng: np.random.Generator,
    *,
    condition: str = "L",
    n_epochs: int | None = None,
    channel: str | None = None,
    nuisance: dict | None = None,
    floors=FLOORS,
    odometry=None,
    adapters: dict | None = None,
) -> dict[str, DriveData]:
    """One drive of ``route`` (a :class:`SignalRoute` or a scenario name, :func:`scenario_route`
    with ``channel`` / ``nuisance``) under ``condition`` (a name of :data:`CONDITIONS`), measured
    through the paper's and the ML route as :func:`~tunnelkit.simulation.drives.simulate_routes`
    measures them (same draws, same ``"paper"`` and ``"ml"`` drives), plus ``"ml-all"`` (the ML
    route's measurements of every epoch, its fit test ignored) and ``"ml-traced"`` (those the
    geometry pre-filter keeps, :func:`traced_measurements` with ``floors``); ``odometry`` the V2X
    messages' model (:class:`tunnelkit.odometry.Odometry`, default the drive's own: its
    scenario's ``[odometry]``, the paper's white model where it has none); ``adapters``: more
    drives of the ML route's epochs, name -> adapter as :func:`simulate_routes` takes them."""
    rng = rng_or_error("rng", rng)
    if condition not in CONDITIONS:
        raise ValueError(f"condition: expected one of {list(CONDITIONS)}, got {condition!r}")
    cond = CONDITIONS[condition]
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    floors = check_floors(floors)
    more = {} if adapters is None else instance("adapters", adapters, dict)
    return simulate_routes(
        route,
        rng,
        condition=cond,
        extractions=("paper", "ml"),
        n_epochs=n_epochs,
        channel=channel,
        nuisance=nuisance,
        odometry=odometry,
        adapters={
            "ml-all": ("ml", partial(traced_measurements, floors=floors, prefilter=False)),
            "ml-traced": ("ml", partial(traced_measurements, floors=floors)),
            **{name: ("ml", adapter) for name, adapter in more.items()},
        },
    )


def _sigma_trial(n_epochs, cond, rng):
    return simulate_traced(
        SIGMA_SCENARIO, rng, condition=cond, n_epochs=n_epochs, channel="sionna", nuisance=NUISANCE
    )["ml-all"]


def measure_traced_errors(
    runs: int = SIGMA_RUNS, seed: int = 0, progress: bool = False, n_epochs: int | None = None
) -> dict:
    """The traced design's measurement noise, measured: ``runs`` condition-L drives of
    :data:`SIGMA_SCENARIO` on the ray-traced channel (diffuse power as the ML fit's floor; drive
    ``i`` from the ``i``-th child of ``seed``, :func:`~tunnelkit.runner.run_trials`), every
    epoch's ML measurements (``"ml-all"`` of :func:`simulate_traced`), their RMS errors per kind
    of path (:func:`~tunnelkit.simulation.analysis.extraction_errors`) and their lag-1 correlation
    from epoch to epoch (:func:`~tunnelkit.simulation.analysis.error_correlations`). Returns the
    record :func:`write_traced_errors` stores: ``rows`` (the table, its ``"all"`` row the
    sigmas), ``correlation`` (each sigma's inflation) and the procedure's provenance."""

    runs = integer("runs", runs, minimum=1)
    check_bytes("runs", runs * RUN_BYTES, f"{runs} traced drives")
    seed = integer("seed", seed, minimum=0)
    boolean("progress", progress)
    if n_epochs is not None:
        n_epochs = integer("n_epochs", n_epochs, minimum=1)
    drives = run_trials(
        lambda c, rng: _sigma_trial(n_epochs, c, rng), runs, seed, inputs=["L"] * runs,
        progress=progress, desc="traced drives",
    )  # fmt: skip
    cols, rows = extraction_errors(drives)
    corr = error_correlations(drives)
    route = scenario_route(SIGMA_SCENARIO, "exact", "sionna", NUISANCE)
    return {
        "procedure": "tunnelkit.studies.traced.measure_traced_errors",
        "scenario": SIGMA_SCENARIO,
        "condition": "L",
        "seed": seed,
        "runs": runs,
        "n_epochs": n_epochs,
        "nuisance": dict(NUISANCE),
        **scene_provenance(route),
        "columns": list(cols),
        "rows": [[r[0], *(float(x) if isinstance(x, float) else x for x in r[1:])] for r in rows],
        "correlation": corr,
    }


def write_traced_errors(record: dict, path=None) -> str:
    """Store ``record`` (:func:`measure_traced_errors`) as JSON at ``path`` (default
    ``data/rt/traced_errors.json``, what :func:`traced_errors` reads); returns the path."""
    if not isinstance(record, dict) or "rows" not in record:
        raise TypeError("record: expected the dict of measure_traced_errors")
    p = _errors_path() if path is None else _path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(record, indent=1, default=str) + "\n")
    return str(p)


_CHECKED: dict[tuple, list[str]] = {}


def traced_errors(path=None, *, check: bool = True) -> dict:
    """The stored record of :func:`measure_traced_errors` (``path`` default
    ``data/rt/traced_errors.json``). ``check``: its provenance is compared with the current scene
    and ray tracer (:func:`check_provenance`): a record of another scene, settings, trajectory,
    array, radio or sionna-rt version is refused (``ValueError``), one that does not carry its
    scene key is used with a warning (its scene cannot be checked); ``check=False`` reads it
    as it is."""
    p = _errors_path() if path is None else _path(path)
    check = boolean("check", check)
    if not p.is_file():
        raise FileNotFoundError(
            f"path: no traced errors at {p}; measure them with benchmarks/bench_rt_sigmas.py --write"
        )
    rec = json.loads(p.read_text())
    if not any(r[0] == "all" for r in rec.get("rows", [])):
        raise ValueError(f"path: {p} holds no 'all' row of extraction_errors")
    if check:
        st = p.stat()
        memo = (str(p.resolve()), st.st_mtime_ns, st.st_size)
        if memo not in _CHECKED:
            try:
                _CHECKED[memo] = check_provenance(rec)
            except ValueError as exc:
                raise ValueError(f"path: {p}: {exc}") from None
        if _CHECKED[memo]:
            warnings.warn(
                f"{p} carries no {' / '.join(_CHECKED[memo])}: the scene and ray tracer its "
                "sigmas were measured on cannot be checked against the current ones; re-measure "
                "with benchmarks/bench_rt_sigmas.py --write",
                stacklevel=2,
            )
    return rec


def traced_design(path=None):
    """:func:`~tunnelkit.tracking.javelin.designs.ours_ml` with its measurement noise set to the
    stored traced errors (:func:`traced_errors`, checked against the current scene; the ``"all"``
    row, each sigma inflated by the record's lag-1 error correlation when it has one, the
    long-run standard deviation of an error that repeats from epoch to epoch;
    :func:`~tunnelkit.tracking.javelin.measured.design_from_errors`); to be fed the
    ``"ml-traced"`` drives of :func:`simulate_traced`."""
    rec = traced_errors(path)
    return design_from_errors(
        rec["rows"], base=designs.ours_ml(), correlation=rec.get("correlation")
    )
