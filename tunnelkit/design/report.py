"""A design sweep and its recommendation: one summary row per candidate array.

:func:`design_sweep` bounds every candidate (and with ``runs >= 2`` adds the JAVELIN Monte-Carlo
of :mod:`tunnelkit.design.montecarlo`) into a :class:`DesignReport` of :class:`DesignRow`
entries, the JSON and text table of ``tunnelkit design``; :func:`recommend` picks the smallest
array that meets the target, :func:`smallest_meeting` searches a list of arrays in order (for
the explorer).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import integer, positive, probability
from ..montecarlo import parallel_options
from .bounds import RouteBounds, path_bounds, route_bounds, route_geometry
from .montecarlo import SETTLE_S, javelin_rmse
from .setup import ArraySpec, DesignSetup, parse_array

__all__ = ["DesignReport", "DesignRow", "design_sweep", "recommend", "smallest_meeting"]


@dataclass
class DesignRow:
    """One candidate array's summary (the JSON entry of ``tunnelkit design``)."""

    array: str
    n_elements: int
    aperture_m: float
    srnf_valid_share: float
    peb_median_m: float
    peb_p90_m: float
    met_share: float
    variants: dict = field(default_factory=dict)
    surfaces: dict = field(default_factory=dict)
    crlb: dict = field(default_factory=dict)
    rmse_m: float | None = None
    rmse_ci95_m: list | None = None
    sigmas: dict | None = None
    rmse_settled_m: float | None = None
    rmse_settled_ci95_m: list | None = None
    peb_rms_settled_m: float | None = None
    median_settled_m: float | None = None

    def to_json(self) -> dict:
        """The CLI's JSON entry: ``array, n_elements, aperture_m, srnf_valid_share,
        peb_median_m, peb_p90_m, rmse_m, rmse_ci95_m``, then the settled RMSE after the
        start-up, its interval, the RMS PEB over the same epochs and the median settled error
        (``rmse_settled_m, rmse_settled_ci95_m, peb_rms_settled_m, median_settled_m``);
        non-finite values and anything not computed are null."""
        fin = lambda v: float(v) if v is not None and np.isfinite(v) else None  # noqa: E731
        ci = lambda v: None if v is None else [fin(x) for x in v]  # noqa: E731
        return {
            "array": self.array,
            "n_elements": int(self.n_elements),
            "aperture_m": fin(self.aperture_m),
            "srnf_valid_share": fin(self.srnf_valid_share),
            "peb_median_m": fin(self.peb_median_m),
            "peb_p90_m": fin(self.peb_p90_m),
            "rmse_m": fin(self.rmse_m),
            "rmse_ci95_m": ci(self.rmse_ci95_m),
            "rmse_settled_m": fin(self.rmse_settled_m),
            "rmse_settled_ci95_m": ci(self.rmse_settled_ci95_m),
            "peb_rms_settled_m": fin(self.peb_rms_settled_m),
            "median_settled_m": fin(self.median_settled_m),
        }


@dataclass
class DesignReport:
    """A sweep: rows per array, the recommendation and the settings it was made with."""

    scenario: str
    rows: list[DesignRow]
    recommendation: dict
    settings: dict

    def to_json(self) -> dict:
        return {
            "scenario": self.scenario,
            "arrays": [r.to_json() for r in self.rows],
            "recommendation": dict(self.recommendation),
        }

    def to_table(self) -> str:
        """A fixed-width text table, the recommendation and the settings below it."""
        s = self.settings
        head = (
            f"{'array':>7s} {'M':>5s} {'aperture':>9s} {'SR-NF ok':>9s} {'PEB med':>9s} "
            f"{'PEB p90':>9s} {'met':>6s} {'no curv.':>9s} {'no RRMs':>9s} {'RMSE [95% CI]':>22s}"
            f" {'settled RMSE':>12s} {'median':>9s} {'/ PEB':>7s}"
        )

        def m(v):
            return f"{100 * v:7.3g}cm" if np.isfinite(v) else "      inf"

        lines = [
            f"Array design for {self.scenario}: fc {s['fc'] / 1e9:g} GHz, bandwidth "
            f"{s['bandwidth'] / 1e6:g} MHz, target PEB <= {s['target']:g} m on "
            f"{100 * s['share']:.0f} % of the route with SR-NF valid (eps {s['eps_phi']:g} rad)",
            head,
        ]
        for r in self.rows:
            rm = (
                f"{r.rmse_m:6.3f} [{r.rmse_ci95_m[0]:.3f}, {r.rmse_ci95_m[1]:.3f}]"
                if r.rmse_m is not None
                else "-"
            )
            settled, median, ratio = "-", "-", "-"
            if r.rmse_settled_m is not None:
                settled = f"{100 * r.rmse_settled_m:9.3g} cm"
                median = f"{100 * r.median_settled_m:6.3g} cm"
                if r.peb_rms_settled_m and np.isfinite(r.peb_rms_settled_m):
                    ratio = f"{r.rmse_settled_m / r.peb_rms_settled_m:6.3g}x"
            lines.append(
                f"{r.array:>7s} {r.n_elements:5d} {100 * r.aperture_m:7.3g}cm "
                f"{100 * r.srnf_valid_share:8.1f}% "
                f"{m(r.peb_median_m)} {m(r.peb_p90_m)} {100 * r.met_share:5.1f}% "
                f"{m(r.variants.get('no_curvature', np.nan))} "
                f"{m(r.variants.get('no_markings', np.nan))} {rm:>22s} {settled:>12s} {median:>9s} {ratio:>7s}"
            )
        rec = self.recommendation
        lines.append(f"recommendation: {rec['array'] or 'none'} — {rec['reason']}")
        lines.append(
            "PEB: horizontal position bound with the antenna height known, clock bias and per-path "
            "gains/Dopplers as nuisances; 'met' = share of epochs with PEB <= target and SR-NF valid."
        )
        if any(r.rmse_m is not None for r in self.rows):
            lines.append(
                f"RMSE: JAVELIN over whole drives [m]; settled: after the first {SETTLE_S:g} s "
                "(RMSE, median error, and RMSE / RMS PEB over the same epochs)."
            )
        return "\n".join(lines)


def recommend(rows: list[DesignRow], target: float, share: float) -> dict:
    """The smallest array (fewest elements) whose ``met_share >= share``, with the reason."""
    ok = [r for r in rows if r.met_share >= share]
    if ok:
        best = min(ok, key=lambda r: (r.n_elements, r.aperture_m))
        return {
            "array": best.array,
            "reason": (
                f"smallest candidate with PEB <= {target:g} m and SR-NF valid on "
                f"{100 * best.met_share:.0f} % of the route (>= {100 * share:.0f} %); median PEB "
                f"{best.peb_median_m:.3g} m"
            ),
        }
    top = max(rows, key=lambda r: (r.met_share, -r.n_elements))
    why = ""
    if top.surfaces:
        worst = min(top.surfaces, key=top.surfaces.get)
        if top.surfaces[worst] < share:
            why = (
                f"; SR-NF binds on the {worst} (valid on {100 * top.surfaces[worst]:.0f} % of "
                f"epochs for {top.array})"
            )
    return {
        "array": None,
        "reason": (
            f"no candidate meets PEB <= {target:g} m with SR-NF valid on {100 * share:.0f} % of "
            f"the route; best is {top.array} with {100 * top.met_share:.0f} %{why}"
        ),
    }


def smallest_meeting(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    eps_phi: float = 0.15,
    epochs=None,
) -> tuple[ArraySpec | None, float]:
    """The first array of ``arrays`` (in the order given) whose PEB <= ``target`` with SR-NF
    valid on ``share`` of the route, and its met share; ``(None, best share)`` if none.

    The SR-NF part is computed first (cheap); the PEB only where SR-NF alone leaves ``share``
    within reach. Arrays that do not fit in the tunnel are skipped; ``epochs`` subsamples the
    route. For the explorer.
    """
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    if share == 0:
        raise ValueError("share: expected a share in (0, 1], got 0")
    best = 0.0
    for spec in (parse_array(a) for a in arrays):
        try:
            g = route_geometry(setup, spec, epochs=epochs)
        except ValueError:
            continue
        b = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g, peb=False)
        if b.srnf_valid.mean() < share:
            continue
        b = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g)
        met = float(np.mean((b.peb <= target) & b.srnf_valid))
        if met >= share:
            return spec, met
        best = max(best, met)
    return None, best


def _summary(b: RouteBounds, target: float) -> tuple[float, float, float]:
    peb = b.peb
    med = float(np.median(peb))
    p90 = float(np.quantile(peb, 0.9, method="higher"))
    met = float(np.mean((peb <= target) & b.srnf_valid))
    return med, p90, met


def design_sweep(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    eps_phi: float = 0.15,
    runs: int = 0,
    seed: int = 0,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    n_epochs: int | None = None,
    timeout: float | None = None,
) -> DesignReport:
    """Bounds (and with ``runs >= 2`` a JAVELIN Monte-Carlo) for each array in ``arrays``.

    ``workers`` / ``scheduler`` / ``timeout`` go to :func:`tunnelkit.montecarlo.run_trials`.
    """
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    specs = [parse_array(a) for a in arrays]
    if not specs:
        raise ValueError("arrays: give at least one candidate array")
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    runs = integer("runs", runs, minimum=0)
    if runs == 1:
        raise ValueError("runs: a 95 % interval needs at least 2 runs (or 0 for bounds only)")
    workers, scheduler = parallel_options(workers, scheduler)
    for s in specs:
        setup.arrays(s)  # fail early, naming the array that does not fit
    rows = []
    for spec in specs:
        b = route_bounds(setup, spec, eps_phi=eps_phi)
        med, p90, met = _summary(b, target)
        variants = {
            "no_curvature": float(np.median(route_bounds(setup, spec, curvature=False).peb)),
            "no_markings": float(np.median(route_bounds(setup, spec, markings=False).peb)),
            "no_curvature_no_markings": float(
                np.median(route_bounds(setup, spec, curvature=False, markings=False).peb)
            ),
        }
        pb = path_bounds(setup, spec)
        crlb = {k: float(np.median(pb[k])) for k in ("d", "direction", "kappa") if pb[k].size}
        row = DesignRow(
            spec.label,
            spec.n_elements,
            spec.aperture(setup.fc),
            float(b.srnf_valid.mean()),
            med,
            p90,
            met,
            variants,
            b.surface_validity(),
            crlb,
        )
        if runs:
            mc = javelin_rmse(
                setup,
                spec,
                runs,
                seed,
                workers=workers,
                scheduler=scheduler,
                progress=progress,
                n_epochs=n_epochs,
                crlb=crlb,
                timeout=timeout,
            )
            row.rmse_m, row.rmse_ci95_m, row.sigmas = mc["rmse_m"], mc["ci95_m"], mc["sigmas"]
            row.rmse_settled_m = mc["rmse_settled_m"]
            row.rmse_settled_ci95_m = mc["settled_ci95_m"]
            row.peb_rms_settled_m = mc["peb_rms_settled_m"]
            row.median_settled_m = mc["median_settled_m"]
        rows.append(row)
    settings = {
        "fc": setup.fc,
        "bandwidth": float(setup.config.bandwidth),
        "target": target,
        "share": share,
        "eps_phi": eps_phi,
        "runs": runs,
        "seed": seed,
    }
    return DesignReport(setup.name, rows, recommend(rows, target, share), settings)
