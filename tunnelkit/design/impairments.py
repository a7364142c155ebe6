"""The impairments a design carries: :class:`DesignImpairments` (per-element calibration error,
the spatial-wideband term, dense diffuse multipath), as the design's error model
(:func:`tunnelkit.design.achievable.path_error_model`) and the channel route take them, and the
two named sets a design starts from (:func:`preset_impairments`):

* ``"calibrated"`` (the default of :func:`tunnelkit.design.design_sweep` and of
  ``tunnelkit design``): a manufactured array after calibration and a tunnel's measured diffuse
  power. Per-element phase and gain errors of 1.5 deg and 0.25 dB RMS, what a 28 GHz, 64-element
  phased-array receiver kept after calibration by code-modulated embedded test, checked against a
  network analyser over its 64 elements and 64 phase settings
  (:data:`CALIBRATED_PHASE_ERROR_DEG`, :data:`CALIBRATED_GAIN_ERROR_DB`); 5.6 % of the received
  power diffuse, the mean a 5.9 GHz V2V campaign measured in a road tunnel with LoS
  (:data:`MEASURED_DIFFUSE_SHARE`; the project's ray tracer gives about 1.1 % on concrete); the
  spatial-wideband term in the channel, and modelled by the estimator, where the band's delay
  across the largest candidate spans more than :data:`WIDEBAND_CYCLES` of a cycle (sources in
  REFERENCES.md).
* ``"ideal"``: eq. 1's channel and a perfect array, the optimistic case.
"""

from __future__ import annotations

from dataclasses import dataclass

from .._validate import boolean, instance, nonnegative, positive, sequence
from ..channel import DiffuseSpec, Impairments
from ..constants import C
from .setup import ArraySpec, DesignSetup, parse_array

__all__ = [
    "CALIBRATED_GAIN_ERROR_DB",
    "CALIBRATED_PHASE_ERROR_DEG",
    "MAX_GAIN_ERROR_DB",
    "MAX_PHASE_ERROR_DEG",
    "MEASURED_DIFFUSE_SD",
    "MEASURED_DIFFUSE_SHARE",
    "PRESETS",
    "WIDEBAND_CYCLES",
    "DesignImpairments",
    "implausible_impairments",
    "preset_impairments",
    "wideband_cycles",
]

_DMC_SPATIAL = ("white", "per-surface")
#: the largest per-element phase error [deg, standard deviation] a calibrated array has
MAX_PHASE_ERROR_DEG = 45.0
#: the largest per-element gain error [dB, standard deviation] a calibrated array has
MAX_GAIN_ERROR_DB = 6.0
#: per-element phase error [deg RMS] left after calibration: a 28 GHz, 64-element phased-array
#: receiver calibrated by hierarchical code-modulated embedded test, against a network analyser
#: over 64 elements and 64 phase settings (REFERENCES.md)
CALIBRATED_PHASE_ERROR_DEG = 1.5
#: per-element gain error [dB RMS] left after calibration, the same array
CALIBRATED_GAIN_ERROR_DB = 0.25
#: the diffuse share of the received power measured in a road tunnel at 5.9 GHz (mean, with LoS;
#: "Measurement and diffuse multipath analysis of V2V propagation channel at 5.9 GHz in tunnel
#: area", REFERENCES.md) against about 1.1 % from the project's ray tracer on concrete
MEASURED_DIFFUSE_SHARE = 0.056
#: its standard deviation over the campaign's snapshots (the same source)
MEASURED_DIFFUSE_SD = 0.063
#: the band's delay across the largest aperture [cycles of the bandwidth] above which the
#: spatial-wideband term matters (bandwidth x aperture / c; the term's phase error across the
#: band reaches about this share of a cycle): the calibrated set turns it on, the report warns
#: when it is off
WIDEBAND_CYCLES = 0.1
#: the named impairment sets (module docstring)
PRESETS = ("calibrated", "ideal")


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


def wideband_cycles(setup: DesignSetup, specs) -> float:
    """The band's delay across the largest of ``specs`` (candidate arrays, as
    :func:`~tunnelkit.design.setup.parse_array` reads them) on ``setup``, in cycles of the
    bandwidth: ``bandwidth x aperture / c``."""
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    if isinstance(specs, str | ArraySpec):
        specs = [specs]
    specs = [parse_array(s) for s in sequence("specs", specs)]
    return max(s.aperture(setup.fc) for s in specs) * setup.config.bandwidth / C


def preset_impairments(name: str, setup, specs) -> DesignImpairments:
    """The named impairment set ``name`` (:data:`PRESETS`, module docstring) for the candidates
    ``specs`` on ``setup``: the spatial-wideband term of ``"calibrated"`` depends on the band and
    the largest aperture (:func:`wideband_cycles`)."""
    if not isinstance(name, str) or name not in PRESETS:
        raise ValueError(f"name: expected one of {', '.join(PRESETS)}, got {name!r}")
    wide = wideband_cycles(setup, specs) > WIDEBAND_CYCLES
    if name == "ideal":
        return DesignImpairments()
    return DesignImpairments(
        phase_error_deg=CALIBRATED_PHASE_ERROR_DEG,
        gain_error_db=CALIBRATED_GAIN_ERROR_DB,
        spatial_wideband=wide,
        dmc_share=MEASURED_DIFFUSE_SHARE,
        wideband_model=wide,
    )


def design_impairments(impairments, setup, specs) -> DesignImpairments:
    """``impairments`` (a preset's name, :data:`PRESETS`, a dict of fields or a
    ``DesignImpairments``) as the object the prediction and the error model take: the argument
    of :func:`~tunnelkit.design.design_sweep` and :func:`~tunnelkit.design.smallest_meeting`,
    checked by them."""
    if isinstance(impairments, str):
        if impairments not in PRESETS:
            raise ValueError(
                f"impairments: expected one of {', '.join(PRESETS)}, a "
                f"design.DesignImpairments or a dict of its fields, got {impairments!r}"
            )
        return preset_impairments(impairments, setup, specs)
    if isinstance(impairments, dict):
        return DesignImpairments(**impairments)
    if not isinstance(impairments, DesignImpairments):
        raise TypeError(
            f"impairments: expected 'calibrated', 'ideal', a design.DesignImpairments or a dict "
            f"of its fields, got "
            f"{type(impairments).__name__}"
        )
    return impairments


def implausible_impairments(imp: DesignImpairments) -> list[str]:
    """Warnings for valid but unusual impairments (``imp`` a checked
    :class:`DesignImpairments`): a diffuse share more than three standard deviations above the
    tunnel campaign's mean, phase or gain errors above a quarter of the hard limits
    (:data:`MAX_PHASE_ERROR_DEG`, :data:`MAX_GAIN_ERROR_DB`): an uncalibrated array, or a value
    in the wrong unit."""
    imp = instance("imp", imp, DesignImpairments)
    out = []
    top = MEASURED_DIFFUSE_SHARE + 3 * MEASURED_DIFFUSE_SD
    if imp.dmc_share > top:
        out.append(
            f"impairments: a diffuse share of {100 * imp.dmc_share:.4g} % is more than three "
            f"standard deviations above the {100 * MEASURED_DIFFUSE_SHARE:g} % "
            f"(sd {100 * MEASURED_DIFFUSE_SD:g} %) a road-tunnel campaign measured at 5.9 GHz "
            f"(above {100 * top:.3g} %): the specular paths the design locates on carry "
            f"{100 * (1 - imp.dmc_share):.3g} % of the power"
        )
    if imp.phase_error_deg > MAX_PHASE_ERROR_DEG / 4:
        out.append(
            f"impairments: {imp.phase_error_deg:g} deg per element is more than a calibrated "
            f"array keeps ({CALIBRATED_PHASE_ERROR_DEG:g} deg after calibration): an "
            "uncalibrated array?"
        )
    if imp.gain_error_db > MAX_GAIN_ERROR_DB / 4:
        out.append(
            f"impairments: {imp.gain_error_db:g} dB per element is more than a calibrated "
            f"array keeps ({CALIBRATED_GAIN_ERROR_DB:g} dB after calibration): an uncalibrated "
            "array?"
        )
    return out
