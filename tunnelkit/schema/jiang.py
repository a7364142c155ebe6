"""The scenario schema of Jiang, Wang & Peng (2023): the 2-D tunnel (``paper = "jiang2023"``)."""

from __future__ import annotations

from .spec import Table, header, key_float, key_floats, key_int, key_str, key_table

ANGLE_ROWS = "rows of (sigma_theta [deg], sigma_d [m]), each >= 0 (angle <= 180 deg)"

JIANG = Table(
    (
        *header("jiang2023"),
        key_table(
            "tunnel",
            Table(
                (
                    key_str("kind", "tunnel model", choices=("walls2d",)),
                    key_floats(
                        "walls",
                        "[A, B, C] of the two parallel wall lines A x + B y + C = 0",
                        shape=(2, 3),
                    ),
                ),
                "Jiang's straight 2-D tunnel between two parallel wall lines (top view)",
            ),
        ),
        key_table(
            "base_station",
            Table(
                (
                    key_floats(
                        "position",
                        "base station (x, y), strictly between the walls",
                        "m",
                        shape=(2,),
                    ),
                ),
                "the single base station",
            ),
        ),
        key_table(
            "noise",
            Table(
                (key_floats("levels", ANGLE_ROWS, shape=(None, 2), ge=0.0),),
                "measurement noise levels of Tables 2-3",
            ),
            optional=True,
        ),
        key_table(
            "trajectory",
            Table(
                (
                    key_str("kind", "trajectory model", choices=("piecewise_acceleration",)),
                    key_floats(
                        "start", "start position (x, y), inside the tunnel", "m", shape=(2,)
                    ),
                    key_floats("velocity", "initial velocity (vx, vy)", "m/s", shape=(2,)),
                    key_float("period", "sampling period T1 (eq. 41)", "s", gt=0.0),
                    key_int("steps", "number of samples", ge=2, le=1_000_000),
                    key_floats(
                        "segments",
                        "[duration s, a_along m/s^2, a_across m/s^2] per constant-acceleration segment",
                        shape=(None, 3),
                        optional=True,
                    ),
                ),
                "ground truth: constant acceleration per segment in the tunnel frame",
            ),
        ),
        key_table(
            "tracking",
            Table(
                (
                    key_float(
                        "q", "white-noise-acceleration spectral density per axis", "m^2/s^3", ge=0.0
                    ),
                    key_floats(
                        "p0_sigma",
                        "prior standard deviations (position, velocity)",
                        "m, m/s",
                        shape=(2,),
                        gt=0.0,
                    ),
                ),
                "filter settings of notebook 05",
            ),
            optional=True,
        ),
    ),
    "Jiang, Wang & Peng (2023): the 2-D rectangular tunnel",
)
