"""Notebook 06: the whole 54 s drive (1688 epochs) with the three Halili filters, and its parts."""

from __future__ import annotations

import numpy as np
from run import Case

from tunnelkit import doppler_drive as dv
from tunnelkit.doppler_drive import drive as drive_model
from tunnelkit.tracking import doppler as dp


def cases() -> list[Case]:
    d = dv.make_drive()
    rng = np.random.default_rng(0)
    meas = dv.measure(d, rng)
    fix = dv.gnss_fix(d, rng)
    key = drive_model._config_key(d.config)

    def three():
        return dp.run_approaches(d, meas, fix, sigma_hz=32.79)

    def one(name):
        return lambda: dp.run_approaches(d, meas, fix, sigma_hz=32.79, approaches=(name,))

    return [
        Case("drive 54 s: all three filters", three, group="doppler_drive", repeat=7, goal_s=2.0),
        Case("drive 54 s: EKF DS", one("EKF DS"), group="doppler_drive", baseline=True, repeat=7),
        Case("drive 54 s: KF DS and ToA", one("KF DS and ToA"), group="doppler_drive", repeat=7),
        Case(
            "drive 54 s: EKF DS and KF ToA",
            one("EKF DS and KF ToA"),
            group="doppler_drive",
            repeat=7,
        ),
        Case(
            "channel: image method + CIR/Doppler peaks",
            lambda: drive_model._make_drive_cached.__wrapped__(key),
            group="doppler_parts",
            baseline=True,
            repeat=5,
        ),
        Case(
            "measure: one noisy realisation",
            lambda: dv.measure(d, np.random.default_rng(1)),
            group="doppler_parts",
        ),
        Case(
            "posterior CRLB along the drive",
            lambda: dp.posterior_crlb(d, sigma_hz=32.79, sigma_range=1.0),
            group="doppler_parts",
            repeat=5,
        ),
    ]
