"""Which array and how far apart the sites: JAVELIN along a row of sites over kilometres.

:func:`long_tunnel_study` answers the operator's question for a long tunnel: for every
candidate array and site spacing it builds the row (:meth:`SiteRow.along
<tunnelkit.design.sites.SiteRow.along>`, one drive of ``length`` metres at 80 km/h), the array's
bound route along it once (:func:`~tunnelkit.design.sites.site_route`), and runs ``runs``
drives (:func:`~tunnelkit.design.sites.site_drive`) with JAVELIN from a drawn open-sky fix and,
on the same drive, start and V2X messages, dead reckoning (every measurement dropped,
:func:`tunnelkit.simulation.without_radio`). All configurations go through ONE
:func:`tunnelkit.runner.run_trials` call; run ``r`` of every configuration uses child generator
``r`` of ``seed`` (common random numbers, as the design's sweep).

Per (array, spacing) over the settled epochs (:func:`tunnelkit.settling.settled`) of all runs:
the 2-D error's p90 and RMSE, the p90 at the worst point between sites (the UE's position
relative to its serving site, within half a spacing of it, binned every ``bin_m`` metres; the
bin of the largest p90, NaN when no epoch lies that close; ``worst_offset`` its
centre, negative towards -x), dead
reckoning's p90 and RMSE, the radio's gain (dead reckoning's p90 over JAVELIN's) and whether
the p90 meets ``target``, and the yield: the share of runs (each site a unit of its own, drawn
per run) whose own p90 meets it. Monte-Carlo figures of the tracker, not bounds; beside them
``bound``, the root mean square over the settled epochs of the posterior CRLB of the drive
(:func:`~tunnelkit.design.sites.row_pcrlb`: the messages' model with its biases as states, the
serving sites' information), below which no tracker's RMSE lies beyond Monte-Carlo noise. Under impairments
each site's array is a unit of its own, drawn per drive (:func:`~tunnelkit.design.sites.site_drive`). The V2X messages follow
``odometry`` (a name of :data:`tunnelkit.odometry.MODELS`, a model, or by default the scenario's
``[odometry]``): the paper's white model where the scenario has none,
the optimistic case for dead reckoning, or ``"automotive"`` (a scale error and a drifting heading
bias: dead reckoning drifts with the distance). JAVELIN is told the messages' white noise, or with
``told_odometry`` the messages' model (its bias states,
:meth:`~tunnelkit.tracking.javelin.JavelinConfig.told`), or a model of its own (an
:class:`~tunnelkit.odometry.Odometry`: a tracker told other figures than the messages carry,
e.g. one repeating term set to zero).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import numpy as np

from .._physical import start_spread
from .._validate import boolean, choice, instance, integer, nonnegative, positive, sequence
from ..odometry import MODELS, Odometry
from ..settling import settled
from .arrayjob import START_HEIGHT_SIGMA_M, design_planes, javelin_config, median_sigmas
from .errordraws import draw_calibration
from .setup import DesignSetup, parse_array
from .sites import LONG_DRIVE_SPEED, SiteRoute, SiteRow, row_pcrlb, site_drive, site_route
from .trackerfix import START_SIGMA_M
from .units import unit_yield

__all__ = ["LongTunnelResult", "LongTunnelTrial", "long_tunnel_study"]


@dataclass(frozen=True)
class LongTunnelTrial:
    """One drive of one (array, spacing) configuration (picklable; sent to each worker once
    with every configuration's row, route and tracker): the 2-D error per epoch of JAVELIN and
    of dead reckoning, (2, T)."""

    rows: tuple
    routes: tuple
    designs: tuple
    start_sigma: float = START_SIGMA_M
    odometry: Odometry = MODELS["white"]

    def __post_init__(self) -> None:
        from ..tracking.javelin import JavelinDesign

        instance("odometry", self.odometry, Odometry)
        n = len(sequence("rows", self.rows))
        for name, cls in (("rows", SiteRow), ("routes", SiteRoute), ("designs", JavelinDesign)):
            items = sequence(name, getattr(self, name))
            if len(items) != n:
                raise ValueError(f"{name}: expected {n} entries (one per row), got {len(items)}")
            for i, x in enumerate(items):
                if not (x is None and name == "designs"):  # None: the paper's tracker
                    instance(f"{name}[{i}]", x, cls)
        start_spread("start_sigma", self.start_sigma)

    def __call__(self, c: int, rng: np.random.Generator) -> np.ndarray:
        from ..simulation import evaluate, without_radio
        from ..tracking.javelin import draw_start

        c = integer("c", c, minimum=0, maximum=len(self.rows) - 1)
        row, route, design = self.rows[c], self.routes[c], self.designs[c]
        # the sites' units from a stream of their own (spawned: the run's stream does not move),
        # so every array and spacing sees the same noise, clock biases and V2X messages
        units = rng.spawn(1)[0]
        cal = [draw_calibration(route.route.model, units) for _ in range(row.count)]
        drive = site_drive(row, route, rng, calibration=cal, odometry=self.odometry)
        sh, s = START_HEIGHT_SIGMA_M, self.start_sigma
        p0 = draw_start(drive.truth[0], s, rng, sh)  # after the drive, as the design's sweep
        out = []
        for d in (drive, without_radio(drive)):
            ev = evaluate(d, design, sigma_p0_ue=s, start=p0, sigma_p0_height=sh)
            out.append(np.linalg.norm(ev.estimates[:, :2] - drive.truth[:, :2], axis=1))
        return np.stack(out)


#: the keys of a row of :class:`LongTunnelResult`
_KEYS = frozenset(
    ("array", "spacing", "sites", "p90", "rmse", "bound", "worst_offset", "worst_p90", "dr_p90",
     "dr_rmse", "gain", "meets", "yield", "yield_ci")
)  # fmt: skip


@dataclass(frozen=True)
class LongTunnelResult:
    """:func:`long_tunnel_study`'s answer: one dict per (array, spacing) in ``rows`` (keys
    ``array``, ``spacing``, ``sites``, ``p90``, ``rmse``, ``bound`` (the posterior CRLB's RMS over
    the settled epochs), ``worst_offset``, ``worst_p90``,
    ``dr_p90``, ``dr_rmse``, ``gain``, ``meets``, ``yield`` and its 95 % Wilson interval
    ``yield_ci``: the share of runs, each its own drive and its own draw of every site's unit,
    whose own p90 meets the target), the inputs, and the wall time [s]."""

    rows: tuple
    target: float
    length: float
    runs: int
    seed: int
    wall_s: float
    odometry: Odometry = MODELS["white"]
    told_odometry: bool = False

    def __post_init__(self) -> None:
        for i, r in enumerate(sequence("rows", self.rows)):
            if not isinstance(r, dict) or not _KEYS <= set(r):
                raise TypeError(f"rows[{i}]: expected a dict with keys {sorted(_KEYS)}")
        positive("target", self.target), positive("length", self.length)
        integer("runs", self.runs, minimum=1), integer("seed", self.seed, minimum=0)
        nonnegative("wall_s", self.wall_s)
        instance("odometry", self.odometry, Odometry)
        boolean("told_odometry", self.told_odometry)

    def meeting(self) -> list[tuple[str, float]]:
        """The (array, spacing) pairs whose p90 meets the target."""
        return [(r["array"], r["spacing"]) for r in self.rows if r["meets"]]

    def to_json(self) -> dict:
        """The result as plain JSON types."""
        return {
            "rows": [
                {k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in r.items()}
                for r in self.rows
            ],
            "target_m": self.target,
            "length_m": self.length,
            "runs": self.runs,
            "seed": self.seed,
            "wall_s": self.wall_s,
            "odometry": self.odometry.label,
            "odometry_figures": asdict(self.odometry),
            "told_odometry": self.told_odometry,
        }

    def table(self) -> str:
        """The rows as a Markdown table."""
        head = (
            "| array | spacing [m] | sites | p90 [m] | RMSE [m] | bound [m] | worst point: offset "
            "[m] | worst p90 [m] | DR p90 [m] | DR RMSE [m] | gain (DR p90 / p90) | "
            f"p90 <= {self.target:g} m | yield [95 % CI] |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        )
        lines = [head]
        for r in self.rows:
            lines.append(
                f"| {r['array']} | {r['spacing']:g} | {r['sites']} | {r['p90']:.3f} | "
                f"{r['rmse']:.3f} | {r['bound']:.3f} | {r['worst_offset']:+.0f} | {r['worst_p90']:.3f} | "
                f"{r['dr_p90']:.3f} | {r['dr_rmse']:.3f} | {r['gain']:.1f} | "
                f"{'yes' if r['meets'] else 'no'} | {r['yield']:.2f} "
                f"[{r['yield_ci'][0]:.2f}, {r['yield_ci'][1]:.2f}] |"
            )
        return "\n".join(lines)


def _summary(
    err: np.ndarray, row: SiteRow, route: SiteRoute, bin_m: float, target: float, bound
) -> dict:
    """``err`` (runs, 2, T) of one configuration and its ``bound`` (T,) -> the row of
    :class:`LongTunnelResult`."""
    idx = settled(row.setup.trajectory.t)
    e, dr = err[:, 0, idx], err[:, 1, idx]
    # the yield: the share of runs (each its own drive and its own draw of every site's unit)
    # whose own p90 over the drive meets the target, with its Wilson interval
    share, ci = unit_yield(np.quantile(e, 0.9, axis=1), target)
    # between two sites: the UE no farther from its serving site than half a spacing (the
    # stretches beyond the first and the last site are not "between sites")
    off = route.offset[idx]
    inner = np.abs(off) <= 0.5 * row.spacing
    bins = np.floor(off / bin_m).astype(int)
    worst = max(
        ((float(np.quantile(e[:, inner & (bins == b)], 0.9)), b) for b in np.unique(bins[inner])),
        key=lambda x: x[0],
        default=(float("nan"), 0),
    )
    p90 = float(np.quantile(e, 0.9))
    dr_p90 = float(np.quantile(dr, 0.9))
    return {
        "spacing": row.spacing,
        "sites": row.count,
        "p90": p90,
        "rmse": float(np.sqrt(np.mean(e**2))),
        "bound": float(np.sqrt(np.mean(bound[idx] ** 2))),
        "worst_offset": (worst[1] + 0.5) * bin_m,
        "worst_p90": worst[0],
        "dr_p90": dr_p90,
        "dr_rmse": float(np.sqrt(np.mean(dr**2))),
        "gain": dr_p90 / p90,
        "meets": bool(p90 <= target),
        "yield": share,
        "yield_ci": [float(c) for c in ci],
    }


def long_tunnel_study(
    setup: DesignSetup,
    arrays=("4x4", "8x8", "16x16"),
    spacings=(100.0, 200.0, 400.0, 800.0),
    *,
    length: float = 2000.0,
    runs: int = 20,
    seed: int = 0,
    target: float = 1.0,
    speed: float = LONG_DRIVE_SPEED,
    impairments=None,
    bin_m: float = 10.0,
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float | None = None,
    odometry: str | Odometry | None = None,
    told_odometry: bool | Odometry = False,
) -> LongTunnelResult:
    """JAVELIN and dead reckoning along a row of ``setup``'s sites for every array x spacing
    (module docstring): ``runs`` drives of ``length`` [m] at ``speed`` [m/s] each, the error
    model under ``impairments`` (default none), ``target`` [m] the p90 to meet, ``bin_m`` [m]
    the bins of the worst point between sites; ``workers`` / ``scheduler`` / ``timeout`` as
    :func:`tunnelkit.runner.run_trials`; ``odometry`` the V2X messages' model, a name of
    :data:`tunnelkit.odometry.MODELS` or an :class:`~tunnelkit.odometry.Odometry` (``None``: the
    setup's scenario's ``[odometry]``, the paper's white model where it has none), which JAVELIN
    is told with ``told_odometry`` (``True``; an :class:`~tunnelkit.odometry.Odometry`: that
    model told instead). Returns a :class:`LongTunnelResult`."""
    from ..runner import run_trials

    instance("setup", setup, DesignSetup)
    specs = [parse_array(a) for a in sequence("arrays", arrays)]
    gaps = [positive("spacings", s) for s in sequence("spacings", spacings)]
    if not specs or not gaps:
        raise ValueError("arrays, spacings: give at least one of each")
    from ..budget import check_bytes
    from ..montecarlo import RUN_BYTES

    runs, seed = integer("runs", runs, minimum=1), integer("seed", seed, minimum=0)
    check_bytes("runs", runs * len(specs) * len(gaps) * RUN_BYTES, f"{runs} runs per row")
    target, bin_m = positive("target", target), positive("bin_m", bin_m)
    if odometry is None:
        odometry = setup.trajectory.odometry
    elif not isinstance(odometry, Odometry):
        odometry = MODELS[choice("odometry", odometry, tuple(MODELS))]
    if isinstance(told_odometry, Odometry):
        told = told_odometry
    else:
        told = odometry if boolean("told_odometry", told_odometry) else None
    t0 = time.perf_counter()
    rows, routes, designs, keys = [], [], [], []
    for s in gaps:
        row = SiteRow.along(setup, s, length, speed=speed)
        planes = design_planes(row.setup)
        for spec in specs:
            route = site_route(row, spec, impairments)
            crlb = median_sigmas(route.route.model)
            rows.append(row)
            routes.append(route)
            d = javelin_config(crlb, route.route.min_d, planes, odometry)
            designs.append(d if told is None else d.with_(config=d.config.told(told)))
            keys.append(spec.label)
    C = len(rows)
    trial = LongTunnelTrial(tuple(rows), tuple(routes), tuple(designs), odometry=odometry)
    res = run_trials(
        trial,
        C * runs,
        seed,
        inputs=[c for c in range(C) for _ in range(runs)],
        streams=[r for _ in range(C) for r in range(runs)],
        shared_streams=True,
        workers=workers,
        scheduler=scheduler,
        desc="long tunnel",
        **({} if timeout is None else {"timeout": timeout}),
    )
    out = []
    for c in range(C):
        err = np.stack(res[c * runs : (c + 1) * runs])
        bound = row_pcrlb(rows[c], routes[c], odometry, trial.start_sigma)
        summary = _summary(err, rows[c], routes[c], bin_m, target, bound)
        out.append({"array": keys[c], **summary})
    out.sort(key=lambda r: (parse_array(r["array"]).n_elements, r["spacing"]))
    wall = time.perf_counter() - t0
    return LongTunnelResult(
        tuple(out), target, float(length), runs, seed, wall, odometry, told is not None
    )
