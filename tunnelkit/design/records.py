"""The records of a design sweep: :class:`DesignRow` (one candidate array) and
:class:`DesignReport` (the rows, the recommendation, every input and the warnings), as JSON or a
text table; :func:`over_target` the stretches of the route above the target. Both records check
their fields at construction (:func:`tunnelkit._validate.record`): a row built by hand with a
negative bound, a share of NaN or a text count is refused, naming the field.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import items
from .._validate import finite_array, positive, record

__all__ = ["DesignReport", "DesignRow", "over_target"]


def _fin(v):
    return float(v) if v is not None and np.isfinite(v) else None


def _fins(v):
    return None if v is None else [_fin(x) for x in np.asarray(v, float).ravel()]


_ROW_INF = (
    "peb_median_m", "peb_p90_m", "predicted_median_m", "predicted_p90_m", "error_median_m",
    "error_p90_m", "error_p90_route_m", "error_p90_ci95_m", "rmse_m", "rmse_ci95_m", "peb_m",
    "predicted_m", "error_median_epoch_m", "unit_p90_m", "pcrlb_rms_m", "hybrid_bound_rms_m",
    "rmse_over_pcrlb", "rmse_over_hybrid_bound", "unit_rmse_over_pcrlb_min",
    "predicted_drive_rms_m", "rmse_over_predicted_drive",
    "rmse_over_predicted", "dead_reckoning_p90_m", "dead_reckoning_rmse_m",
)  # fmt: skip
_ROW_NONNEGATIVE = ("srnf_valid_share", "met_share", "runs", "units", "drives_per_unit",
                    "unit_yield", "unit_yield_ci95", *_ROW_INF)  # fmt: skip
_ROW_SHAPES = {"error_p90_ci95_m": (2,), "rmse_ci95_m": (2,), "unit_yield_ci95": (2,),
               "unit_p90_m": (3,), "x_m": ("T",), "peb_m": ("T",), "predicted_m": ("T",),
               "srnf_valid": ("T",)}  # fmt: skip


@dataclass
class DesignRow:
    """One candidate array (the JSON entry of ``tunnelkit design``, :meth:`to_json`).

    Statistics are over the counted (settled) epochs unless named ``*_route_*`` (the whole
    route); ``*_p90_m`` is the ``share``-quantile (the 90th percentile at the default share).
    ``status`` is a verdict of :func:`tunnelkit.design.verdict.judge` (by the unit yield) or
    ``"error"`` (``reason`` says why). The Monte-Carlo ran ``units`` manufactured units (one
    calibration draw each) of ``drives_per_unit`` drives (``runs`` in all): ``unit_yield`` the
    share of units whose own error quantile meets the target, ``unit_yield_ci95`` its Wilson
    interval, ``unit_p90_m`` the units' quantiles' [min, median, max]; ``error_p90_m`` the
    quantile pooled over units with ``error_p90_ci95_m`` Woodruff's interval over units.

    **Bounds** (lower bounds of what they are set beside, :mod:`tunnelkit.design.drivebound`):
    ``peb_*`` the snapshot PEB (ideal model, one epoch); ``pcrlb_rms_m`` every unit's posterior
    CRLB over the drive (a bound of each unit's expected mean-square error), with
    ``unit_rmse_over_pcrlb_min`` the smallest unit's sample RMSE over it (from that unit's few
    drives: 1.8-9.7 under phase and gain errors alone, 0.70-1.27 under the calibrated default,
    ``benchmarks/bench_design_units.py``; a unit's two drives scatter about its expected error,
    so it is a sample, not the bound's check, which is ``rmse_over_pcrlb``);
    ``hybrid_bound_rms_m`` the posterior CRLB pooled over units (the calibration draw a fixed
    unknown of the drive). **Predictions** (first-order, not bounds: the tracker may beat
    them): ``predicted_*`` the snapshot fix's RMS error under the impairments, weighted as the
    tracker weighs; ``predicted_drive_rms_m`` the same over the drive. Per-epoch arrays cover the whole route: ``x_m``,
    ``peb_m``, ``predicted_m`` and, with units, ``error_median_epoch_m`` (median over runs).
    """

    array: str
    n_elements: int
    aperture_diagonal_m: float
    status: str = "error"
    reason: str = ""
    srnf_valid_share: float | None = None
    srnf_valid_share_by_surface: dict = field(default_factory=dict)
    peb_median_m: float | None = None
    peb_p90_m: float | None = None
    predicted_median_m: float | None = None
    predicted_p90_m: float | None = None
    met_share: float | None = None
    error_median_m: float | None = None
    error_p90_m: float | None = None
    error_p90_ci95_m: list | None = None
    error_p90_route_m: float | None = None
    rmse_m: float | None = None
    rmse_ci95_m: list | None = None
    runs: int = 0
    units: int = 0
    drives_per_unit: int = 0
    unit_yield: float | None = None
    unit_yield_ci95: list | None = None
    unit_p90_m: list | None = None
    x_m: np.ndarray | None = None
    peb_m: np.ndarray | None = None
    predicted_m: np.ndarray | None = None
    error_median_epoch_m: np.ndarray | None = None
    pcrlb_rms_m: float | None = None
    hybrid_bound_rms_m: float | None = None
    rmse_over_pcrlb: float | None = None
    rmse_over_hybrid_bound: float | None = None
    unit_rmse_over_pcrlb_min: float | None = None
    predicted_drive_rms_m: float | None = None
    rmse_over_predicted_drive: float | None = None
    rmse_over_predicted: float | None = None
    error_model: dict | None = None
    dead_reckoning_p90_m: float | None = None
    dead_reckoning_rmse_m: float | None = None
    gaps: str = ""
    srnf_valid: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:  # a bound or an error may be +inf (never met)
        record(self, shapes=_ROW_SHAPES, positive=("n_elements", "aperture_diagonal_m"),
               nonnegative=_ROW_NONNEGATIVE, allow_inf=_ROW_INF,
               allow_nan=("peb_m", "predicted_m", "error_median_epoch_m"),
               may_be_empty=("reason", "gaps"))  # fmt: skip

    @property
    def aperture_m(self) -> float:
        """The aperture's diagonal [m] (largest distance between two elements)."""
        return self.aperture_diagonal_m

    #: the JSON's scalar keys, in order (besides the fields handled apart in :meth:`to_json`)
    _SCALARS = (
        "srnf_valid_share", "peb_median_m", "peb_p90_m", "predicted_median_m", "predicted_p90_m",
        "met_share", "error_median_m", "error_p90_m", "error_p90_route_m", "rmse_m",
        "unit_yield", "pcrlb_rms_m", "hybrid_bound_rms_m", "rmse_over_pcrlb",
        "rmse_over_hybrid_bound", "unit_rmse_over_pcrlb_min", "predicted_drive_rms_m",
        "rmse_over_predicted_drive", "rmse_over_predicted",
    )  # fmt: skip

    def to_json(self) -> dict:
        """The row as JSON: ``array, n_elements, aperture_diagonal_m, status, reason, gaps`` (the
        epochs where the array cannot fix the position, named; empty when none), the
        scalars of the class docstring (``null`` when not computed or not finite),
        ``error_p90_ci95_m, rmse_ci95_m, unit_yield_ci95, unit_p90_m``, the counts ``runs,
        units, drives_per_unit`` and ``per_epoch {x_m, peb_m, predicted_m,
        error_median_m}``; on the ray-traced channel's route also ``error_model`` (the
        tracker's measurement-noise model, :func:`tunnelkit.design.traced.error_model_summary`,
        with ``told_sigmas`` the long-run sigmas its tracker is told); with dead reckoning
        measured, ``dead_reckoning_p90_m`` and ``dead_reckoning_rmse_m`` (the same drives,
        every measurement dropped)."""
        out = {
            "array": self.array,
            "n_elements": int(self.n_elements),
            "aperture_diagonal_m": _fin(self.aperture_diagonal_m),
            "status": self.status,
            "reason": self.reason,
            "gaps": self.gaps,
            "srnf_valid_share_by_surface": {
                k: _fin(v) for k, v in self.srnf_valid_share_by_surface.items()
            },
            **{k: _fin(getattr(self, k)) for k in self._SCALARS},
            "error_p90_ci95_m": _fins(self.error_p90_ci95_m),
            "rmse_ci95_m": _fins(self.rmse_ci95_m),
            "unit_yield_ci95": _fins(self.unit_yield_ci95),
            "unit_p90_m": _fins(self.unit_p90_m),
            "runs": int(self.runs),
            "units": int(self.units),
            "drives_per_unit": int(self.drives_per_unit),
            "per_epoch": {
                "x_m": _fins(self.x_m),
                "peb_m": _fins(self.peb_m),
                "predicted_m": _fins(self.predicted_m),
                "error_median_m": _fins(self.error_median_epoch_m),
            },
        }
        if self.error_model is not None:
            out["error_model"] = dict(self.error_model)
        if self.dead_reckoning_p90_m is not None:
            out["dead_reckoning_p90_m"] = _fin(self.dead_reckoning_p90_m)
            out["dead_reckoning_rmse_m"] = _fin(self.dead_reckoning_rmse_m)
        return out


@dataclass
class DesignReport:
    """A sweep: rows per array, the recommendation, every input and the warnings."""

    scenario: str
    rows: list[DesignRow]
    recommendation: dict
    settings: dict
    warnings: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        record(self, may_be_empty=("warnings",))
        items("rows", self.rows, DesignRow)

    @property
    def criterion(self) -> str:
        return self.settings["criterion"]

    def to_json(self) -> dict:
        return {
            "scenario": self.scenario,
            "inputs": dict(self.settings),
            "criterion": self.criterion,
            "arrays": [r.to_json() for r in self.rows],
            "recommendation": dict(self.recommendation),
            "warnings": list(self.warnings),
        }

    def to_table(self) -> str:
        """A fixed-width text table; the criterion above it, recommendation and warnings below."""
        s = self.settings
        imp = s["impairments"]
        q = f"p{100 * s['share']:g}"
        st = s["settle_s"]
        lines = [
            f"Array design for {self.scenario}: fc {s['fc'] / 1e9:g} GHz, bandwidth "
            f"{s['bandwidth'] / 1e6:g} MHz ({s['n_rb']} RB at {s['scs'] / 1e3:g} kHz); target {s['target']:g} m on {100 * s['share']:g} % "
            f"of the settled route (the epochs {st:g} s after the start, --settle), required "
            f"unit yield {100 * s['required_yield']:g} %",
            f"impairments ({s.get('impairments_preset', 'custom')}): phase "
            f"{imp['phase_error_deg']:g} deg, gain {imp['gain_error_db']:g} "
            f"dB, spatial wideband {'on' if imp['spatial_wideband'] else 'off'}, diffuse share "
            f"{imp['dmc_share']:.10g}; Monte-Carlo: units of {s['drives_per_unit']} drives "
            f"({s['mode']} route, {s['units']} units first, up to {s['max_units']}), seed "
            f"{s['seed']}"
            + (f", entry fix {s['start_sigma_m']:g} m per axis" if "start_sigma_m" in s else ""),
            f"criterion: {_CRITERION_TEXT[s['criterion']]}",
            f"{'array':>7s} {'M':>5s} {'SR-NF ok':>9s} {'PEB ' + q:>9s} {'pred ' + q:>9s} "
            f"{'units':>5s} {'unit yield [95% CI]':>20s} {'err ' + q:>9s} {'95% CI':>21s} "
            f"{'route ' + q:>9s} {'RMSE':>9s} {'PCRLB':>9s} {'hybrid':>9s}  status",
        ]
        for r in self.rows:
            if r.peb_median_m is None:  # nothing computed: the reason only
                lines.append(f"{r.array:>7s} {r.n_elements:5d}  {r.reason}")
                continue
            ci = r.error_p90_ci95_m
            cis = f"[{_cm(ci[0]).strip()}, {_cm(ci[1]).strip()}]" if ci else "-"
            yc = r.unit_yield_ci95
            ys = f"{100 * r.unit_yield:.0f}% [{100 * yc[0]:.0f}, {100 * yc[1]:.0f}]" if yc else "-"
            lines.append(
                f"{r.array:>7s} {r.n_elements:5d} {100 * r.srnf_valid_share:8.1f}% "
                f"{_cm(r.peb_p90_m)} {_cm(r.predicted_p90_m)} {r.units:5d} {ys:>20s} "
                f"{_cm(r.error_p90_m)} {cis:>21s} {_cm(r.error_p90_route_m)} {_cm(r.rmse_m)} "
                f"{_cm(r.pcrlb_rms_m)} {_cm(r.hybrid_bound_rms_m)}  {r.status}"
            )
        rec = self.recommendation
        lines.append(f"recommendation ({rec['basis']}): {rec['array'] or 'none'} — {rec['reason']}")
        lines.append(
            f"Bounds: PEB the ideal snapshot position error bound (of one epoch's fix; the "
            f"tracker fuses epochs and may go below it, and a bound's p90 bounds no error's p90); "
            f"the tracker's lower bounds (of trackers nearly unbiased for the fixed route), checked "
            f"by Monte-Carlo: PCRLB every unit's posterior CRLB over the drive (settled RMS), hybrid the same pooled over units, the "
            f"calibration a fixed unknown per unit (both beside RMSE). Prediction (not a bound, decides nothing): pred, "
            f"the first-order RMS error of the tracker's fix under the impairments. err: "
            f"Monte-Carlo 2-D error, {q} its {s['share']:g}-quantile pooled over units on the "
            f"settled route (CI: Woodruff's interval over units, a unit's drives one cluster; "
            f"information only: at 20 units it covered 83-98 %, docs/results/design-units.md), route {q} on the whole route; unit "
            f"yield: the share of units whose own {q} meets the target (Wilson interval)."
        )
        lines.append(_CHANNEL_TEXT[s.get("channel", "image")])
        for r in self.rows:
            if r.srnf_valid_share_by_surface:
                per = ", ".join(
                    f"{k} {100 * v:.0f} %" for k, v in r.srnf_valid_share_by_surface.items()
                )
                lines.append(f"  SR-NF valid, {r.array}: {per}")
            for what, y in (
                ("predicted error", r.predicted_m),
                ("median error", r.error_median_epoch_m),
            ):
                if y is not None and r.x_m is not None:
                    spans = over_target(r.x_m[: len(y)], y, s["target"])
                    if spans:
                        lines.append(f"  {r.array}: {what} above the target at x = {spans}")
            em = r.error_model
            if em and em.get("kind") == "traced-measured":
                sg = em["sigmas"]
                lines.append(
                    f"  {r.array}: traced route, noise measured on seed {em['seed']} "
                    f"({em['runs']} drives): {sg['phi_deg']:.3g} / {sg['psi_deg']:.3g} deg, "
                    f"{sg['kappa_m']:.3g} m, {sg['delta_d_m']:.3g} m; geometry pre-filter"
                )
                tg = em.get("told_sigmas")
                if tg:
                    lines.append(
                        f"  {r.array}: the tracker is told their long-run value "
                        f"{tg['phi_deg']:.3g} / {tg['psi_deg']:.3g} deg, {tg['kappa_m']:.3g} m, "
                        f"{tg['delta_d_m']:.3g} m"
                    )
                if r.predicted_drive_rms_m is not None:
                    ratio = r.rmse_over_predicted_drive
                    lines.append(
                        f"  {r.array}: posterior CRLB of the sigmas the tracker is told (settled "
                        f"RMS; a prediction, the traced errors are not Gaussian) "
                        f"{r.predicted_drive_rms_m:.3g} m"
                        + ("" if ratio is None else f", tracker RMSE / it {ratio:.3g}")
                    )
            if r.dead_reckoning_p90_m is not None:
                gain = None
                if r.rmse_m is not None and r.dead_reckoning_rmse_m:
                    gain = 1 - r.rmse_m / r.dead_reckoning_rmse_m
                lines.append(
                    f"  {r.array}: dead reckoning on the same drives (every measurement dropped): "
                    f"{q} {r.dead_reckoning_p90_m:.3g} m, RMSE {r.dead_reckoning_rmse_m:.3g} m"
                    + ("" if gain is None else f"; the radio's gain in RMSE {100 * gain:.2g} %")
                )
        lines.extend(f"warning: {w}" for w in self.warnings)
        return "\n".join(lines)


def over_target(x, y, target: float) -> str:
    """The stretches of the route where ``y > target`` (non-finite counts), as text:
    ``"45.0..38.1 m, 12.5 m"`` in route order; ``""`` when none."""
    x = finite_array("x", x, ndim=1)
    try:
        y = np.asarray(y, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"y: expected real numbers (NaN allowed), got {type(y).__name__}") from None
    if y.shape != x.shape:
        raise ValueError(f"y: expected one value per x, shape {x.shape}, got {y.shape}")
    target = positive("target", target)
    bad = ~(y <= target)
    out, i = [], 0
    while i < bad.size:
        if not bad[i]:
            i += 1
            continue
        j = i
        while j + 1 < bad.size and bad[j + 1]:
            j += 1
        out.append(f"{x[i]:.1f} m" if i == j else f"{x[i]:.1f}..{x[j]:.1f} m")
        i = j + 1
    return ", ".join(out)


_CHANNEL_TEXT = {
    "image": (
        "channel: the image method's eq. 1 decided (specular paths only). On the paper tunnel "
        "the ray-traced channel (diffuse and second-order paths) gave errors of metres where "
        "this one gives millimetres (notebook 08, section 9): read the table as optimistic."
    ),
    "sionna": "channel: the ray-traced channel decided (Sionna RT, the array's measured errors).",
}

_CRITERION_TEXT = {
    "achievable": (
        "achievable (the design's tracker models each reflection's wavefront on its virtual UE; "
        "SR-NF validity is information, not a gate)"
    ),
    "srnf": ("srnf (an eq. 51 estimator: an epoch counts only where SR-NF holds on every surface)"),
}


def _cm(v) -> str:
    if v is None:
        return "        -"
    return f"{100 * v:7.3g}cm" if np.isfinite(v) else "      inf"
