"""Dead reckoning's drift against distance driven, beside its bound, under two odometry models.

A straight drive at a highway speed, its V2X messages drawn ``n_drives`` times by
:meth:`tunnelkit.odometry.Odometry.draw` (the paper's white model and the automotive one, each
from its own generator seeded ``seed``) and integrated by
:func:`tunnelkit.reckoning.dead_reckoning` from the true start; per epoch the 2-D error's RMSE and
90th percentile over the drives, beside :func:`tunnelkit.reckoning.dead_reckoning_bound` (with
lost messages, the bound of each drive's arrival pattern, its mean square over the drives: the
bound of the error averaged over the losses). ``docs/results/odometry.md`` reports it
(``benchmarks/bench_odometry.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._domains import positive_array
from .._validate import finite_array, instance, integer, positive, record, sequence
from ..odometry import MODELS, Odometry
from ..reckoning import dead_reckoning, dead_reckoning_bound

__all__ = ["DISTANCES_M", "MODELS", "Drift", "drift", "drift_rows", "drift_table"]

#: the distances [m] the table reports (40 m: the shortest drive of the paper's scenarios)
DISTANCES_M = (40.0, 100.0, 250.0, 500.0, 1000.0, 2000.0, 3000.0)


@dataclass(frozen=True)
class Drift:
    """Dead reckoning's error along one drive: ``distance`` [m] driven at each epoch (T,), the
    2-D error's ``rmse`` and ``p90`` [m] over ``n_drives`` drives, the ``bound`` [m] beside them,
    the Monte-Carlo standard error of the mean square error ``mse_se`` [m^2] and the mean error
    along the track ``along`` [m] (a bias the linearised bound does not hold)."""

    distance: np.ndarray
    rmse: np.ndarray
    p90: np.ndarray
    bound: np.ndarray
    mse_se: np.ndarray
    along: np.ndarray
    n_drives: int

    def __post_init__(self) -> None:
        shape = ("T",)
        keys = ("distance", "rmse", "p90", "bound", "mse_se", "along")
        record(self, shapes=dict.fromkeys(keys, shape), positive=("n_drives",))

    def at(self, distances) -> dict[str, np.ndarray]:
        """``rmse``, ``p90``, ``bound`` [m] at ``distances`` [m] (interpolated between epochs)."""
        d = finite_array("distances", distances, ndim=1)
        if d.size and (d.min() < 0 or d.max() > self.distance[-1]):
            raise ValueError(f"distances: expected values in [0, {self.distance[-1]:g}] m")
        keys = ("rmse", "p90", "bound", "along")
        return {k: np.interp(d, self.distance, getattr(self, k)) for k in keys}


def drift(
    odometry: Odometry,
    *,
    n_drives: int = 2000,
    seed: int = 0,
    length: float = 3000.0,
    speed: float = 22.0,
    epoch_rate: float = 10.0,
) -> Drift:
    """Dead reckoning's error over ``n_drives`` drives of ``length`` [m] straight at ``speed``
    [m/s], epochs at ``epoch_rate`` [Hz], messages drawn by ``odometry`` (``seed``)."""
    instance("odometry", odometry, Odometry)
    n = integer("n_drives", n_drives, minimum=2)
    seed = integer("seed", seed, minimum=0)
    length, speed = positive("length", length), positive("speed", speed)
    dt = 1.0 / positive("epoch_rate", epoch_rate)
    T = int(np.ceil(length / speed / dt - 1e-9)) + 1
    t = np.arange(T) * dt
    v, th = np.full(T, speed), np.zeros(T)
    rng = np.random.default_rng(seed)
    S, H = np.empty((n, T)), np.empty((n, T))
    for i in range(n):
        S[i], H[i] = odometry.draw(t, v, th, rng)
    truth = dead_reckoning(t, v, th, np.zeros(2))
    err = dead_reckoning(t, S, H, np.zeros(2)) - truth
    e2 = (err**2).sum(-1)
    arrived = None if odometry.dropout == 0 else np.isfinite(S)
    b = dead_reckoning_bound(t, v, th, odometry, 0.0, arrived=arrived)
    bound = np.sqrt((b**2).mean(0)) if b.ndim == 2 else b
    return Drift(
        distance=speed * t,
        rmse=np.sqrt(e2.mean(0)),
        p90=np.quantile(np.sqrt(e2), 0.9, axis=0),
        bound=bound,
        mse_se=e2.std(0, ddof=1) / np.sqrt(n),
        along=err[..., 0].mean(0),
        n_drives=n,
    )


def drift_rows(n_drives: int = 2000, seed: int = 0, distances=DISTANCES_M, **kw) -> list[dict]:
    """One row per distance: ``distance`` [m] and, per model of :data:`MODELS`,
    ``{name}_rmse``, ``{name}_p90``, ``{name}_bound``, ``{name}_along`` (the mean error along the
    track) [m]; ``kw`` as :func:`drift`'s."""
    d = positive_array("distances", distances, ndim=1)
    if not d.size:
        raise ValueError("distances: expected one or more distances [m], got none")
    kw.setdefault("length", float(d.max()))
    at = {name: drift(m, n_drives=n_drives, seed=seed, **kw).at(d) for name, m in MODELS.items()}
    return [
        {"distance": float(x)}
        | {
            f"{m}_{k}": float(at[m][k][i])
            for m in MODELS
            for k in ("rmse", "p90", "bound", "along")
        }
        for i, x in enumerate(d)
    ]


def _fmt(x: float) -> str:
    return f"{x:.3g}" if x < 100 else f"{x:.0f}"


def drift_table(rows: list[dict]) -> str:
    """``rows`` of :func:`drift_rows` as a Markdown table: per model RMSE / bound and p90."""
    rows = sequence("rows", rows)
    want = {"distance"} | {f"{m}_{k}" for m in MODELS for k in ("rmse", "p90", "bound")}
    for r in rows:
        if not isinstance(r, dict) or not want <= set(r):
            raise ValueError(f"rows: expected drift_rows' dicts with {sorted(want)}, got {r!r:.60}")
    head = "| distance [m] | " + " | ".join(f"{m}: RMSE / bound [m] | {m}: p90 [m]" for m in MODELS)
    lines = [head + " |", "| --- " * (1 + 2 * len(MODELS)) + "|"]
    for r in rows:
        cells = [f"{r['distance']:g}"]
        for m in MODELS:
            cells += [f"{_fmt(r[f'{m}_rmse'])} / {_fmt(r[f'{m}_bound'])}", _fmt(r[f"{m}_p90"])]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)
