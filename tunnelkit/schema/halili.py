"""The scenario schema of Halili et al. (2022): one roadside unit (``paper = "halili2022"``)."""

from __future__ import annotations

from .._physical import CARRIER_HZ
from .spec import Table, header, key_float, key_int, key_table

HALILI = Table(
    (
        *header("halili2022"),
        key_table(
            "tube",
            Table(
                (
                    key_float("width", "tube width", "m", gt=0.0, default=10.0),
                    key_float("height", "tube height", "m", gt=0.0, default=5.0),
                ),
                "rectangular tube",
            ),
            default={},
        ),
        key_table(
            "transmitter",
            Table(
                (
                    key_float("tx_y", "transmitter across (|tx_y| < width/2)", "m", default=4.5),
                    key_float("tx_z", "transmitter height (0 < tx_z < height)", "m", default=4.5),
                    key_float(
                        "pass_time",
                        "time the van passes the transmitter",
                        "s",
                        ge=0.0,
                        default=37.0,
                    ),
                ),
                "the roadside unit",
            ),
            default={},
        ),
        key_table(
            "vehicle",
            Table(
                (
                    key_float("lane_y", "lane centre (|lane_y| < width/2)", "m", default=-2.5),
                    key_float(
                        "rx_height", "antenna height (< tube height)", "m", gt=0.0, default=2.0
                    ),
                    key_float("speed", "mean speed", "m/s", gt=0.0, le=100.0, default=25.0),
                    key_float(
                        "speed_amplitude", "speed variation amplitude", "m/s", ge=0.0, default=1.0
                    ),
                    key_float("speed_period", "speed variation period", "s", gt=0.0, default=27.0),
                    key_float("duration", "recording time", "s", gt=0.0, le=1e5, default=54.0),
                    key_float(
                        "spacing",
                        "distance between stored parameter sets",
                        "m",
                        gt=0.0,
                        default=0.8,
                    ),
                ),
                "the van",
            ),
            default={},
        ),
        key_table(
            "radio",
            Table(
                (
                    key_float(
                        "fc",
                        "carrier frequency",
                        "Hz",
                        ge=CARRIER_HZ[0],
                        le=CARRIER_HZ[1],
                        default=1.35e9,
                    ),
                    key_float("bandwidth", "sounder bandwidth", "Hz", gt=0.0, default=80e6),
                    key_float(
                        "snapshot_period", "snapshot period t_s", "s", gt=0.0, default=975.3e-6
                    ),
                    key_int(
                        "window_snapshots",
                        "local stationarity window M",
                        ge=2,
                        le=100_000,
                        default=32,
                    ),
                ),
                "channel sounder",
            ),
            default={},
        ),
        key_table(
            "multipath",
            Table(
                (
                    key_float(
                        "reflection_coeff", "amplitude per bounce", ge=0.0, le=1.0, default=0.6
                    ),
                    key_int("max_order", "highest reflection order", ge=0, le=6, default=2),
                ),
                "image-method multipath",
            ),
            default={},
        ),
        key_table(
            "errors",
            Table(
                (
                    key_float(
                        "doppler_noise_hz",
                        "white Doppler noise at short range",
                        "Hz",
                        ge=0.0,
                        default=8.0,
                    ),
                    key_float(
                        "toa_noise_s", "white ToA noise at short range", "s", ge=0.0, default=1e-9
                    ),
                    key_float(
                        "noise_ref_range",
                        "noise grows as sqrt(1 + (r/ref)^2)",
                        "m",
                        gt=0.0,
                        default=300.0,
                    ),
                    key_float(
                        "doppler_bias_hz", "Gauss-Markov Doppler bias", "Hz", ge=0.0, default=10.0
                    ),
                    key_float("toa_bias_m", "NLOS excess delay scale", "m", ge=0.0, default=1.0),
                    key_float("bias_corr_m", "bias correlation length", "m", gt=0.0, default=20.0),
                    key_float(
                        "outlier_prob",
                        "probability of a Doppler outlier",
                        ge=0.0,
                        le=1.0,
                        default=0.02,
                    ),
                    key_float(
                        "drop_prob",
                        "probability of a missed measurement",
                        ge=0.0,
                        lt=1.0,
                        default=0.0,
                    ),
                ),
                "measurement errors",
            ),
            default={},
        ),
        key_table(
            "clock",
            Table(
                (
                    key_float("clock_offset_s", "ToA clock offset", "s", ge=0.0, default=30e-9),
                    key_float("clock_drift", "clock drift", "s/s", default=0.2e-9),
                    key_float("cfo_hz", "residual carrier-frequency offset", "Hz", default=0.0),
                    key_float("cfo_walk_hz", "CFO random walk", "Hz/sqrt(s)", ge=0.0, default=0.2),
                ),
                "clocks",
            ),
            default={},
        ),
        key_table(
            "gnss",
            Table(
                (
                    key_float(
                        "gnss_sigma_m", "position error of the last fix", "m", ge=0.0, default=2.0
                    ),
                    key_float(
                        "gnss_sigma_v", "velocity error of the last fix", "m/s", ge=0.0, default=0.2
                    ),
                ),
                "the GNSS fix at the entrance",
            ),
            default={},
        ),
    ),
    "Halili et al. (2022): one roadside unit, Doppler and ToA",
)
