"""Input checks and size checks: the duplicate-element test of make_array and the cost of a checked
helper against its unchecked inner-loop twin."""

from __future__ import annotations

import numpy as np
from run import Case

from tunnelkit import angles, arrays, crlb


def cases() -> list[Case]:
    kw = dict(fc=5.9e9, azimuth=0.0, elevation=-0.5)
    a = np.array([0.1, 4.0, -4.0, 2.0])
    return [
        Case(
            "make_array 100 x 100 (k-d tree duplicate check)",
            lambda: arrays.make_array(100, 100, **kw),
            group="make_array",
            baseline=True,
            repeat=7,
        ),
        Case(
            "make_array 300 x 300",
            lambda: arrays.make_array(300, 300, **kw),
            group="make_array",
            repeat=5,
        ),
        Case(
            "wrap_angle, 4 angles, unchecked",
            lambda: angles.wrap_angle_unchecked(a),
            group="wrap_angle",
            baseline=True,
            number=2000,
        ),
        Case(
            "wrap_angle, 4 angles, checked",
            lambda: crlb.wrap_angle(a),
            group="wrap_angle",
            number=2000,
        ),
    ]
