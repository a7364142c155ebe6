"""The drive's configuration: every knob of the synthetic drive (:class:`DriveConfig`), read from
a ``halili2022`` scenario file (:func:`load_drive_config`) whose placement it checks on load."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from .._physical import carrier, speeds
from .._validate import finite_array, nonnegative, positive, probability
from ..scenarios import MAX_SAMPLES, Scenario, ScenarioError, load_scenario, register_check

__all__ = ["IDEAL", "DriveConfig", "load_drive_config"]


@dataclass(frozen=True)
class DriveConfig:
    """Every knob of the synthetic drive (SI units). Defaults follow Halili et al. 2022, sec. 3.

    Values the paper does not state (transmitter mount, lane, noise and bias levels, clock
    errors) are our assumptions, chosen to be physically plausible, never fitted to its results.
    """

    # tube and placement
    width: float = 10.0
    height: float = 5.0
    lane_y: float = -2.5
    rx_height: float = 2.0
    tx_y: float = 4.5
    tx_z: float = 4.5
    pass_time: float = 37.0
    # motion: mean speed, gentle speed variation (amplitude, period), duration, sample spacing
    speed: float = 25.0
    speed_amplitude: float = 1.0
    speed_period: float = 27.0
    duration: float = 54.0
    spacing: float = 0.8
    # radio / sounder
    fc: float = 1.35e9
    bandwidth: float = 80e6
    snapshot_period: float = 975.3e-6
    window_snapshots: int = 32
    # multipath
    reflection_coeff: float = 0.6
    max_order: int = 2
    # random errors
    doppler_noise_hz: float = 8.0
    toa_noise_s: float = 1e-9
    noise_ref_range: float = 300.0
    doppler_bias_hz: float = 10.0
    toa_bias_m: float = 1.0
    bias_corr_m: float = 20.0
    outlier_prob: float = 0.02
    drop_prob: float = 0.0
    # clocks
    clock_offset_s: float = 30e-9
    clock_drift: float = 0.2e-9
    cfo_hz: float = 0.0
    cfo_walk_hz: float = 0.2
    # the initial GNSS fix at the tunnel entrance
    gnss_sigma_m: float = 2.0
    gnss_sigma_v: float = 0.2

    def __post_init__(self) -> None:
        for name in (
            "width",
            "height",
            "rx_height",
            "speed",
            "duration",
            "spacing",
            "fc",
            "bandwidth",
            "snapshot_period",
            "noise_ref_range",
            "bias_corr_m",
            "speed_period",
        ):
            positive(name, getattr(self, name))
        for name in (
            "speed_amplitude",
            "doppler_noise_hz",
            "toa_noise_s",
            "doppler_bias_hz",
            "toa_bias_m",
            "clock_offset_s",
            "cfo_walk_hz",
            "gnss_sigma_m",
            "gnss_sigma_v",
            "pass_time",
        ):
            nonnegative(name, getattr(self, name))
        for name in ("clock_drift", "cfo_hz", "lane_y", "tx_y", "tx_z"):
            finite_array(name, getattr(self, name), ndim=0)
        probability("reflection_coeff", self.reflection_coeff, open_interval=False)
        probability("outlier_prob", self.outlier_prob, open_interval=False)
        probability("drop_prob", self.drop_prob, open_interval=False)
        if (
            isinstance(self.window_snapshots, bool)
            or not isinstance(self.window_snapshots, int)
            or self.window_snapshots < 2
        ):
            raise ValueError(
                f"window_snapshots: must be an integer >= 2, got {self.window_snapshots!r}"
            )
        if (
            isinstance(self.max_order, bool)
            or not isinstance(self.max_order, int)
            or not 0 <= self.max_order <= 6
        ):
            raise ValueError(f"max_order: must be an integer in [0, 6], got {self.max_order!r}")
        carrier("fc", self.fc)
        speeds("speed", self.speed + self.speed_amplitude)
        if self.speed_amplitude >= self.speed:
            raise ValueError(
                f"speed_amplitude: must be below speed ({self.speed}) so the vehicle keeps moving, "
                f"got {self.speed_amplitude}"
            )
        half = self.width / 2
        if not -half < self.lane_y < half:
            raise ValueError(f"lane_y: must lie inside the tube (|y| < {half}), got {self.lane_y}")
        if not -half < self.tx_y < half:
            raise ValueError(f"tx_y: must lie inside the tube (|y| < {half}), got {self.tx_y}")
        if not 0 < self.tx_z < self.height:
            raise ValueError(
                f"tx_z: must lie between floor and ceiling (0, {self.height}), got {self.tx_z}"
            )
        if not 0 < self.rx_height < self.height:
            raise ValueError(
                f"rx_height: must lie between floor and ceiling (0, {self.height}), got {self.rx_height}"
            )
        if self.pass_time > self.duration:
            raise ValueError(
                f"pass_time: must be within the drive (<= {self.duration} s), got {self.pass_time}"
            )
        n = self.speed * self.duration / self.spacing
        if n > MAX_SAMPLES:
            raise ValueError(
                f"spacing: {self.spacing:g} m gives {n:.3g} samples over the {self.duration:g} s "
                f"drive (speed x duration / spacing), more than {MAX_SAMPLES:g}"
            )

    def replace(self, **changes) -> DriveConfig:
        """A copy with some fields changed (validated again)."""
        unknown = set(changes) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise ValueError(f"{sorted(unknown)[0]}: not a DriveConfig field")
        return dataclasses.replace(self, **changes)

    @property
    def dt(self) -> float:
        """Epoch period [s]: one parameter set every ``spacing`` metres at the mean speed."""
        return self.spacing / self.speed

    @property
    def doppler_resolution(self) -> float:
        """Doppler resolution of the estimation window, ``1 / (M t_s)`` [Hz] (32 x 975.3 us: 32 Hz)."""
        return 1.0 / (self.window_snapshots * self.snapshot_period)

    @property
    def delay_resolution(self) -> float:
        """Delay resolution ``1 / B`` [s] (80 MHz: 12.5 ns, 3.75 m)."""
        return 1.0 / self.bandwidth


#: Field changes that switch every random error and clock effect off (ideal measurements):
#: ``make_drive(**IDEAL)``; multipath and the speed variation stay as configured.
IDEAL = {
    "doppler_noise_hz": 0.0,
    "toa_noise_s": 0.0,
    "doppler_bias_hz": 0.0,
    "toa_bias_m": 0.0,
    "outlier_prob": 0.0,
    "clock_offset_s": 0.0,
    "clock_drift": 0.0,
    "cfo_hz": 0.0,
    "cfo_walk_hz": 0.0,
}


_SECTIONS = ("tube", "transmitter", "vehicle", "radio", "multipath", "errors", "clock", "gnss")


def load_drive_config(name: str = "halili2022-drive") -> DriveConfig:
    """A :class:`DriveConfig` from a scenario preset's plain sections (``data/scenarios/<name>.toml``).

    Every key of ``[tube]``, ``[transmitter]``, ``[vehicle]``, ``[radio]``, ``[multipath]``,
    ``[errors]``, ``[clock]`` and ``[gnss]`` must be a :class:`DriveConfig` field; unknown keys are
    errors naming the key.
    """
    sc = load_scenario(name)
    if sc.family != "halili2022":
        raise ScenarioError(
            f"name: {sc.name!r} is a {sc.family!r} scenario, not a Halili drive; "
            'load_drive_config reads paper = "halili2022" files ([tube], [transmitter], ...)'
        )
    fields = {f.name: f for f in dataclasses.fields(DriveConfig)}
    kw = {}
    for sec in _SECTIONS:
        table = sc.sections.get(sec, {})
        if not isinstance(table, dict):
            raise ScenarioError(f"{sc.path.name}: [{sec}] must be a table")
        for key in table:
            if key not in fields:
                raise ScenarioError(
                    f"{sc.path.name}: unknown key '{sec}.{key}'; known: {sorted(fields)}"
                )
            kind = int if fields[key].type in ("int", int) else float
            kw[key] = sc.get(f"{sec}.{key}", kind)
    try:
        return DriveConfig(**kw)
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"{sc.path.name}: {exc}") from None


@register_check("halili2022")
def _check_tube(sc: Scenario) -> None:
    """Transmitter and vehicle inside the tube, every value a valid :class:`DriveConfig` field
    and a drive of at most ``MAX_SAMPLES`` epochs (run on load of a ``halili2022`` file)."""
    where, sec = sc.path.name, sc.sections
    w, h = sec["tube"]["width"], sec["tube"]["height"]
    for key, val, lim in (
        ("transmitter.tx_y", sec["transmitter"]["tx_y"], w / 2),
        ("vehicle.lane_y", sec["vehicle"]["lane_y"], w / 2),
    ):
        if not abs(val) < lim:
            raise ScenarioError(
                f"{where}: '{key}' = {val:g} m lies outside the {w:g} m wide tube (|y| < {lim:g})"
            )
    for key, val in (
        ("transmitter.tx_z", sec["transmitter"]["tx_z"]),
        ("vehicle.rx_height", sec["vehicle"]["rx_height"]),
    ):
        if not 0 < val < h:
            raise ScenarioError(
                f"{where}: '{key}' = {val:g} m lies outside the {h:g} m high tube (0 < z < {h:g})"
            )
    owner = {k: name for name, tab in sec.items() if isinstance(tab, dict) for k in tab}
    try:
        DriveConfig(**{k: sec[s][k] for k, s in owner.items()})
    except ValueError as exc:
        field_name, _, msg = str(exc).partition(":")
        key = f"{owner.get(field_name, '?')}.{field_name}"
        raise ScenarioError(f"{where}: '{key}': {msg.strip()}") from None
    veh = sec["vehicle"]
    n = veh["speed"] * veh["duration"] / veh["spacing"]
    if n > MAX_SAMPLES:
        raise ScenarioError(
            f"{where}: 'vehicle.spacing' {veh['spacing']:g} m gives {n:.3g} samples over the "
            f"drive (speed x duration / spacing), more than {MAX_SAMPLES:g}"
        )
