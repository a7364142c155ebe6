"""Notebook 06 explorer: the three Halili filters on one synthetic drive, sliders for sigma and q."""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from .._validate import integer, nonnegative, positive
from .base import Explorer, float_slider, int_slider

__all__ = ["doppler_explorer", "doppler_figure"]


def doppler_figure(
    sigma_hz: float = 32.79, q: float = 0.5, doppler_bias_hz: float = 10.0, seed: int = 0
) -> go.Figure:
    """Pure callback: error over time of the three approaches on one seeded drive.

    ``sigma_hz`` is the filters' assumed Doppler noise (R = sigma^2), ``q`` the process-noise
    density of eq. 3, ``doppler_bias_hz`` the drive's traffic bias on the Doppler (the truth).
    """
    from ..doppler_drive import gnss_fix, make_drive, measure
    from ..plots.doppler import error_time_figure
    from ..tracking.doppler import run_approaches

    sigma_hz = positive("sigma_hz", sigma_hz)
    q = nonnegative("q", q)
    doppler_bias_hz = nonnegative("doppler_bias_hz", doppler_bias_hz)
    seed = integer("seed", seed, minimum=0)
    drive = make_drive(doppler_bias_hz=doppler_bias_hz)
    rng = np.random.default_rng(seed)
    meas = measure(drive, rng)
    fix = gnss_fix(drive, rng)
    tracks = run_approaches(drive, meas, fix, sigma_hz=sigma_hz, q=q)
    means = {
        k: float(np.mean(np.linalg.norm(v.position - drive.position, axis=1)))
        for k, v in tracks.items()
    }
    title = "mean error: " + ", ".join(f"{k} {v:.1f} m" for k, v in means.items())
    return error_time_figure(drive, {k: v.position for k, v in tracks.items()}, title=title)


def doppler_explorer(
    sigma_hz: float = 32.79, q: float = 0.5, doppler_bias_hz: float = 10.0, seed: int = 0
) -> Explorer:
    """Sliders: filter sigma [Hz], process noise q, the drive's Doppler bias [Hz], noise seed."""
    return Explorer(
        doppler_figure,
        {
            "sigma_hz": float_slider(
                "filter sigma [Hz]", sigma_hz, 2.0, 150.0, 0.5, name="sigma_hz"
            ),
            "q": float_slider("q [m^2/s^3]", q, 0.01, 10.0, 0.01, name="q"),
            "doppler_bias_hz": float_slider(
                "drive's Doppler bias [Hz]", doppler_bias_hz, 0.0, 30.0, 1.0, name="doppler_bias_hz"
            ),
            "seed": int_slider("noise seed", seed, 0, 20, name="seed"),
        },
        columns=2,
    )
