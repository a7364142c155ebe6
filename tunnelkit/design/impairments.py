"""The impairments a design carries: :class:`DesignImpairments` (per-element calibration error,
the spatial-wideband term, dense diffuse multipath), as the design's error model
(:func:`tunnelkit.design.achievable.path_error_model`) and the channel route take them."""

from __future__ import annotations

from dataclasses import dataclass

from .._validate import boolean, nonnegative, positive
from ..channel import DiffuseSpec, Impairments

__all__ = ["MAX_GAIN_ERROR_DB", "MAX_PHASE_ERROR_DEG", "DesignImpairments"]

_DMC_SPATIAL = ("white", "per-surface")
#: the largest per-element phase error [deg, standard deviation] a calibrated array has
MAX_PHASE_ERROR_DEG = 45.0
#: the largest per-element gain error [dB, standard deviation] a calibrated array has
MAX_GAIN_ERROR_DB = 6.0


@dataclass(frozen=True)
class DesignImpairments:
    """The impairments a design carries (module docstring).

    ``phase_error_deg`` / ``gain_error_db``: standard deviations of the per-element calibration
    error; ``spatial_wideband``: the per-element delay across the aperture, in the channel;
    ``wideband_model``: the estimator models that term too (the ML extraction with
    ``wideband=True``, :mod:`tunnelkit.extraction.ml.wideband`), so it leaves no bias (needs
    ``spatial_wideband``: a model term the channel lacks is refused); ``dmc_share`` in
    [0, 1): the diffuse share of the received power, with time constant ``dmc_decay_s`` (20 ns
    by default, a short concrete tunnel); ``dmc_spatial``: ``"white"`` (independent over the
    elements). ``"per-surface"`` (diffuse power spread in angle around each specular path) is
    not implemented and refused.
    """

    phase_error_deg: float = 0.0
    gain_error_db: float = 0.0
    spatial_wideband: bool = False
    dmc_share: float = 0.0
    dmc_decay_s: float = 20e-9
    dmc_spatial: str = "white"
    wideband_model: bool = False

    def __post_init__(self) -> None:
        # beyond these the array is not calibrated at all (a uniform phase has a 104 deg
        # standard deviation) and the linearised error model means nothing
        if nonnegative("phase_error_deg", self.phase_error_deg) > MAX_PHASE_ERROR_DEG:
            raise ValueError(
                f"phase_error_deg: expected at most {MAX_PHASE_ERROR_DEG:g} deg (a calibrated "
                f"array), got {self.phase_error_deg:g}"
            )
        if nonnegative("gain_error_db", self.gain_error_db) > MAX_GAIN_ERROR_DB:
            raise ValueError(
                f"gain_error_db: expected at most {MAX_GAIN_ERROR_DB:g} dB (a calibrated "
                f"array), got {self.gain_error_db:g}"
            )
        boolean("spatial_wideband", self.spatial_wideband)
        if boolean("wideband_model", self.wideband_model) and not self.spatial_wideband:
            raise ValueError(
                "wideband_model: the estimator models the spatial-wideband term of the channel; "
                "set spatial_wideband=True too (a model term the channel lacks is not an option)"
            )
        share = nonnegative("dmc_share", self.dmc_share)
        if share >= 1.0:
            raise ValueError(f"dmc_share: the diffuse share must lie in [0, 1), got {share}")
        positive("dmc_decay_s", self.dmc_decay_s)
        if self.dmc_spatial not in _DMC_SPATIAL:
            raise ValueError(f"dmc_spatial: expected 'white', got {self.dmc_spatial!r}")
        if self.dmc_spatial == "per-surface":
            raise ValueError(
                "dmc_spatial: 'per-surface' (diffuse power spread around each specular path) is "
                "not implemented; use 'white'"
            )

    @property
    def ideal(self) -> bool:
        """True when the channel is eq. 1 exactly (no impairment)."""
        return (
            self.phase_error_deg == 0
            and self.gain_error_db == 0
            and not self.spatial_wideband
            and self.dmc_share == 0
        )

    @property
    def dmc(self) -> DiffuseSpec | None:
        """The :class:`~tunnelkit.channel.DiffuseSpec` of the diffuse multipath (None if off)."""
        return DiffuseSpec(self.dmc_share, self.dmc_decay_s) if self.dmc_share > 0 else None

    def channel_impairments(self) -> Impairments:
        """The :class:`~tunnelkit.channel.Impairments` that synthesise this channel."""
        return Impairments(
            phase_sigma_deg=float(self.phase_error_deg),
            gain_sigma_db=float(self.gain_error_db),
            spatial_wideband=bool(self.spatial_wideband),
            dmc=self.dmc,
        )
