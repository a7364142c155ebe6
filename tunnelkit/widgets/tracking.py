"""Notebook 05 explorer: one run of TSWLS, EKF, UKF and UPF with noise and particle-count sliders."""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from .._validate import boolean, integer, positive
from .base import Explorer, checkbox, float_slider, int_slider

__all__ = ["upf_explorer", "upf_figure"]

#: the dashed curve's name: what it bounds (the RMSE over runs of this drive), not one run
NOISE_FREE_BOUND_NAME = "sqrt(PCRLB), this path without process noise (bounds the RMSE over runs)"


def upf_figure(
    sigma_theta_deg: float = 2.0,
    sigma_d: float = 2.0,
    n_particles: int = 200,
    los: bool = False,
    curved: bool = False,
    seed: int = 0,
) -> go.Figure:
    """Position error per epoch of the four ``jiang2023`` estimators on one simulated run, with
    sqrt(posterior CRLB) of the drive as simulated (its path without process noise, the start
    known through the prior mean: a bound on the RMSE of unbiased estimators over many such runs,
    not on one run's error); the legend
    gives each one's RMSE over the run."""
    from ..plots.tracking import rmse_bound_figure
    from ..tracking.pcrlb import vs_pcrlb
    from ..tracking.virtual_station import experiment, monte_carlo

    sigma_theta_deg = positive("sigma_theta_deg", sigma_theta_deg)
    sigma_d = positive("sigma_d", sigma_d)
    n_particles = integer("n_particles", n_particles, minimum=1, maximum=100_000)
    los, curved = boolean("los", los), boolean("curved", curved)
    seed = integer("seed", seed, minimum=0)
    scenario = "jiang2023-curved" if curved else "jiang2023-straight"
    exp = experiment(scenario, level=(float(np.radians(sigma_theta_deg)), float(sigma_d)), los=los)
    res = monte_carlo(exp, 1, int(seed), options={"UPF": {"n_particles": int(n_particles)}})
    err = {n: np.linalg.norm(e[0, :, :2] - exp.truth[:, :2], axis=-1) for n, e in res.items()}
    bound = vs_pcrlb(exp.model, exp.truth, exp.P0, process_noise=False)
    labels = {f"{n} (RMSE {np.sqrt(np.mean(e**2)):.2f} m)": e for n, e in err.items()}
    title = (
        f"{'curved' if curved else 'straight'}, {'LOS' if los else 'NLOS'}: "
        f"sigma_theta = {sigma_theta_deg:g} deg, sigma_d = {sigma_d:g} m, {n_particles} particles"
    )
    return rmse_bound_figure(
        exp.times, labels, bound, title=title, bound_name=NOISE_FREE_BOUND_NAME
    )


def upf_explorer(**initial) -> Explorer:
    """Sliders for the noise levels, the particle count and the seed; toggles for LOS and the curve."""
    v = {
        "sigma_theta_deg": 2.0,
        "sigma_d": 2.0,
        "n_particles": 200,
        "los": False,
        "curved": False,
        "seed": 0,
        **initial,
    }
    controls = {
        "sigma_theta_deg": float_slider(
            "sigma_theta [deg]", v["sigma_theta_deg"], 0.1, 5.0, 0.1, name="sigma_theta_deg"
        ),
        "sigma_d": float_slider("sigma_d [m]", v["sigma_d"], 0.05, 5.0, 0.05, name="sigma_d"),
        "n_particles": int_slider(
            "UPF particles", v["n_particles"], 1, 1000, 1, name="n_particles"
        ),
        "los": checkbox("LOS (direct path)", v["los"], name="los"),
        "curved": checkbox("curved trajectory", v["curved"], name="curved"),
        "seed": int_slider("seed", v["seed"], 0, 50, name="seed"),
    }
    return Explorer(upf_figure, controls)
