"""The records of a design sweep: :class:`DesignRow` (one candidate array) and
:class:`DesignReport` (the rows, the recommendation, every input and the warnings); their JSON and
text table are written by :mod:`tunnelkit.design.render`, loaded when asked for. Both records check
their fields at construction (:func:`tunnelkit._validate.record`): a row built by hand with a
negative bound, a share of NaN or a text count is refused, naming the field.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import items
from .._validate import record

__all__ = ["DesignReport", "DesignRow"]


_ROW_INF = (
    "peb_median_m", "peb_p90_m", "predicted_median_m", "predicted_p90_m", "error_median_m",
    "error_p90_m", "error_p90_route_m", "error_p90_ci95_m", "rmse_m", "rmse_ci95_m", "peb_m",
    "predicted_m", "error_median_epoch_m", "unit_p90_m", "pcrlb_rms_m", "hybrid_bound_rms_m",
    "rmse_over_pcrlb", "rmse_over_hybrid_bound", "unit_rmse_over_pcrlb_min",
    "predicted_drive_rms_m", "rmse_over_predicted_drive", "rmse_over_predicted",
    "dead_reckoning_p90_m", "dead_reckoning_rmse_m", "unit_rmse_m", "dead_reckoning_unit_rmse_m",
)  # fmt: skip
_ROW_NONNEGATIVE = ("srnf_valid_share", "met_share", "runs", "units", "drives_per_unit",
                    "unit_yield", "unit_yield_ci95", *_ROW_INF)  # fmt: skip
_ROW_SHAPES = {"error_p90_ci95_m": (2,), "rmse_ci95_m": (2,), "unit_yield_ci95": (2,),
               "unit_p90_m": (3,), "x_m": ("T",), "peb_m": ("T",), "predicted_m": ("T",),
               "srnf_valid": ("T",), "unit_rmse_m": ("U",),
               "dead_reckoning_unit_rmse_m": ("U",)}  # fmt: skip


@dataclass
class DesignRow:
    """One candidate array (the JSON entry of ``tunnelkit design``, :meth:`to_json`).

    Statistics are over the counted (settled) epochs unless named ``*_route_*`` (the whole route);
    ``*_p90_m`` is the ``share``-quantile (the p90 at the default share). ``status`` is a verdict of
    :func:`tunnelkit.design.verdict.judge` (by the unit yield) or ``"error"`` (``reason`` says why).
    The Monte-Carlo ran ``units`` manufactured units (one calibration draw each) of
    ``drives_per_unit`` drives (``runs`` in all): ``unit_yield`` the share of units whose own error
    quantile meets the target, ``unit_yield_ci95`` its Wilson interval, ``unit_p90_m`` the units'
    quantiles' [min, median, max], ``unit_rmse_m`` (``dead_reckoning_unit_rmse_m``) each unit's
    RMSE (a sweep's rows share their drives); ``error_p90_m`` the quantile pooled over units,
    ``error_p90_ci95_m`` Woodruff's interval.

    **Bounds** (lower bounds of what they are set beside, :mod:`tunnelkit.design.drivebound`):
    ``peb_*`` the snapshot PEB (ideal model, one epoch); ``pcrlb_rms_m`` every unit's posterior CRLB
    over the drive (a bound of each unit's expected mean-square error), with
    ``unit_rmse_over_pcrlb_min`` the smallest unit's RMSE over it (a sample, not the bound's check,
    which is ``rmse_over_pcrlb``); ``hybrid_bound_rms_m`` the posterior CRLB pooled over units (the
    calibration draw a fixed unknown of the drive). **Predictions** (first-order, not bounds: the
    tracker may beat them): ``predicted_*`` the snapshot fix's RMS error under the impairments,
    weighted as the tracker weighs; ``predicted_drive_rms_m`` the same over the drive. Per epoch of
    the whole route: ``x_m``, ``peb_m``, ``predicted_m``, ``error_median_epoch_m`` (over runs).
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
    unit_rmse_m: np.ndarray | None = None
    dead_reckoning_unit_rmse_m: np.ndarray | None = None
    gaps: str = ""
    srnf_valid: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:  # a bound or an error may be +inf (never met)
        record(self, shapes=_ROW_SHAPES, positive=("n_elements", "aperture_diagonal_m"),
               nonnegative=_ROW_NONNEGATIVE, allow_inf=_ROW_INF,
               allow_nan=("peb_m", "predicted_m", "error_median_epoch_m"),
               may_be_empty=("reason", "gaps"))  # fmt: skip

    def to_json(self) -> dict:
        """The row as JSON (:func:`tunnelkit.design.render.row_json`)."""
        from .render import row_json  # the writing out loaded when asked for

        return row_json(self)


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
        """The report as JSON (:func:`tunnelkit.design.render.report_json`)."""
        from .render import report_json  # the writing out loaded when asked for

        return report_json(self)

    def to_table(self) -> str:
        """A fixed-width text table; the criterion above it, recommendation and warnings below
        (:func:`tunnelkit.design.render.report_table`)."""
        from .render import report_table  # the writing out loaded when asked for

        return report_table(self)
