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
    "peb_median_m", "peb_p90_m", "achievable_median_m", "achievable_p90_m", "error_median_m",
    "error_p90_m", "error_p90_ci95_m", "rmse_m", "rmse_ci95_m", "peb_m", "achievable_m",
    "error_median_epoch_m", "drive_bound_known_rms_m", "drive_bound_learned_rms_m",
    "rmse_over_tracker_bound", "rmse_over_achievable", "screen_m", "dead_reckoning_p90_m",
    "dead_reckoning_rmse_m",
)  # fmt: skip
_ROW_NONNEGATIVE = ("srnf_valid_share", "met_share", "runs", *_ROW_INF)
_ROW_SHAPES = {"error_p90_ci95_m": (2,), "rmse_ci95_m": (2,), "x_m": ("T",), "peb_m": ("T",),
               "achievable_m": ("T",), "srnf_valid": ("T",)}  # fmt: skip


@dataclass
class DesignRow:
    """One candidate array (the JSON entry of ``tunnelkit design``, :meth:`to_json`).

    Bound and error statistics are over the counted (settled) epochs; ``*_p90_m`` is the
    ``share``-quantile (the 90th percentile at the default share). ``status`` is a verdict of
    :func:`tunnelkit.design.verdict.judge` or ``"error"`` (``reason`` says why). Per-epoch
    arrays cover the whole route: ``x_m``, ``peb_m``, ``achievable_m`` and, with runs,
    ``error_median_epoch_m`` (median over runs). With runs on the bound route (and on the
    ray-traced channel's route, there of the sigmas its tracker is told), the bounds over
    the drive (RMS, counted epochs) of a tracker that knows the surfaces and of one that learns
    its VUEs (``drive_bound_known_rms_m``, ``drive_bound_learned_rms_m``, :func:`_drive_bounds`).
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
    achievable_median_m: float | None = None
    achievable_p90_m: float | None = None
    met_share: float | None = None
    error_median_m: float | None = None
    error_p90_m: float | None = None
    error_p90_ci95_m: list | None = None
    rmse_m: float | None = None
    rmse_ci95_m: list | None = None
    runs: int = 0
    x_m: np.ndarray | None = None
    peb_m: np.ndarray | None = None
    achievable_m: np.ndarray | None = None
    error_median_epoch_m: np.ndarray | None = None
    tracker_vues: str | None = None
    drive_bound_known_rms_m: float | None = None
    drive_bound_learned_rms_m: float | None = None
    rmse_over_tracker_bound: float | None = None
    rmse_over_achievable: float | None = None
    error_model: dict | None = None
    dead_reckoning_p90_m: float | None = None
    dead_reckoning_rmse_m: float | None = None
    screen_m: float | None = field(default=None, repr=False)
    srnf_valid: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:  # a bound or an error may be +inf (never met)
        record(self, shapes=_ROW_SHAPES, positive=("n_elements", "aperture_diagonal_m"),
               nonnegative=_ROW_NONNEGATIVE, allow_inf=_ROW_INF,
               allow_nan=("peb_m", "achievable_m", "error_median_epoch_m"),
               may_be_empty=("reason",))  # fmt: skip

    @property
    def aperture_m(self) -> float:
        """The aperture's diagonal [m] (largest distance between two elements)."""
        return self.aperture_diagonal_m

    def to_json(self) -> dict:
        """``array, n_elements, aperture_diagonal_m, status, reason, srnf_valid_share,
        srnf_valid_share_by_surface, peb_median_m, peb_p90_m, achievable_median_m,
        achievable_p90_m, met_share, error_median_m, error_p90_m, error_p90_ci95_m, rmse_m,
        rmse_ci95_m, runs, tracker_vues, drive_bound_known_rms_m, drive_bound_learned_rms_m,
        rmse_over_tracker_bound, rmse_over_achievable`` (the RMSE over the RMS of
        ``achievable_m`` on the same epochs) and ``per_epoch {x_m, peb_m, achievable_m,
        error_median_m}`` (non-finite values and anything not computed are null); on the
        ray-traced channel's route also ``error_model`` (the tracker's measurement-noise model,
        :func:`tunnelkit.design.traced.error_model_summary`, with ``told_sigmas`` the long-run
        sigmas its tracker is told); with dead reckoning measured, ``dead_reckoning_p90_m`` and
        ``dead_reckoning_rmse_m`` (the same drives, every measurement dropped)."""
        out = {
            "array": self.array,
            "n_elements": int(self.n_elements),
            "aperture_diagonal_m": _fin(self.aperture_diagonal_m),
            "status": self.status,
            "reason": self.reason,
            "srnf_valid_share": _fin(self.srnf_valid_share),
            "srnf_valid_share_by_surface": {
                k: _fin(v) for k, v in self.srnf_valid_share_by_surface.items()
            },
            "peb_median_m": _fin(self.peb_median_m),
            "peb_p90_m": _fin(self.peb_p90_m),
            "achievable_median_m": _fin(self.achievable_median_m),
            "achievable_p90_m": _fin(self.achievable_p90_m),
            "met_share": _fin(self.met_share),
            "error_median_m": _fin(self.error_median_m),
            "error_p90_m": _fin(self.error_p90_m),
            "error_p90_ci95_m": _fins(self.error_p90_ci95_m),
            "rmse_m": _fin(self.rmse_m),
            "rmse_ci95_m": _fins(self.rmse_ci95_m),
            "runs": int(self.runs),
            "tracker_vues": self.tracker_vues,
            "drive_bound_known_rms_m": _fin(self.drive_bound_known_rms_m),
            "drive_bound_learned_rms_m": _fin(self.drive_bound_learned_rms_m),
            "rmse_over_tracker_bound": _fin(self.rmse_over_tracker_bound),
            "rmse_over_achievable": _fin(self.rmse_over_achievable),
            "per_epoch": {
                "x_m": _fins(self.x_m),
                "peb_m": _fins(self.peb_m),
                "achievable_m": _fins(self.achievable_m),
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
        lines = [
            f"Array design for {self.scenario}: fc {s['fc'] / 1e9:g} GHz, bandwidth "
            f"{s['bandwidth'] / 1e6:g} MHz; target {s['target']:g} m on {100 * s['share']:g} % "
            "of the settled route",
            f"impairments: phase {imp['phase_error_deg']:g} deg, gain {imp['gain_error_db']:g} "
            f"dB, spatial wideband {'on' if imp['spatial_wideband'] else 'off'}, diffuse share "
            f"{imp['dmc_share']:g}; Monte-Carlo: {s['runs']} runs ({s['mode']} route), seed "
            f"{s['seed']}"
            + (f", entry fix {s['start_sigma_m']:g} m per axis" if "start_sigma_m" in s else ""),
            f"criterion: {_CRITERION_TEXT[s['criterion']]}",
            f"{'array':>7s} {'M':>5s} {'diagonal':>9s} {'SR-NF ok':>9s} {'PEB med':>9s} "
            f"{'PEB ' + q:>9s} {'ach. med':>9s} {'ach. ' + q:>9s} {'err med':>9s} "
            f"{'err ' + q:>9s} {'95% CI':>21s} {'RMSE':>9s}  status",
        ]
        for r in self.rows:
            if r.peb_median_m is None:  # nothing computed: the reason only
                lines.append(
                    f"{r.array:>7s} {r.n_elements:5d} {_cm(r.aperture_diagonal_m)}  {r.reason}"
                )
                continue
            ci = r.error_p90_ci95_m
            cis = f"[{_cm(ci[0]).strip()}, {_cm(ci[1]).strip()}]" if ci else "-"
            lines.append(
                f"{r.array:>7s} {r.n_elements:5d} {_cm(r.aperture_diagonal_m)} "
                f"{100 * r.srnf_valid_share:8.1f}% {_cm(r.peb_median_m)} {_cm(r.peb_p90_m)} "
                f"{_cm(r.achievable_median_m)} {_cm(r.achievable_p90_m)} "
                f"{_cm(r.error_median_m)} {_cm(r.error_p90_m)} {cis:>21s} {_cm(r.rmse_m)}  "
                f"{r.status}"
            )
        rec = self.recommendation
        lines.append(f"recommendation ({rec['basis']}): {rec['array'] or 'none'} — {rec['reason']}")
        lines.append(
            f"diagonal: the aperture's diagonal; PEB: ideal position error bound; ach.: the "
            f"achievable bound under the impairments; err: Monte-Carlo 2-D error; {q}: the "
            f"{s['share']:g}-quantile over the settled epochs (pooled over runs), CI: bootstrap "
            "over runs; SR-NF ok: share of the route where SR-NF holds on every surface."
        )
        for r in self.rows:
            if r.srnf_valid_share_by_surface:
                per = ", ".join(
                    f"{k} {100 * v:.0f} %" for k, v in r.srnf_valid_share_by_surface.items()
                )
                lines.append(f"  SR-NF valid, {r.array}: {per}")
            for what, y in (
                ("achievable bound", r.achievable_m),
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
                if r.drive_bound_known_rms_m is not None:
                    ratio = r.rmse_over_tracker_bound
                    lines.append(
                        f"  {r.array}: bound of the sigmas the tracker is told (settled RMS) "
                        f"{r.drive_bound_known_rms_m:.3g} m"
                        + ("" if ratio is None else f", tracker RMSE / bound {ratio:.3g}")
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
