"""Notebook 05 explorer: one run of TSWLS, EKF, UKF and UPF with noise and particle-count sliders."""

from __future__ import annotations

import ipywidgets as widgets
import numpy as np
import plotly.graph_objects as go

from .base import Explorer, float_slider, int_slider

__all__ = ["upf_explorer", "upf_figure"]


def upf_figure(
    sigma_theta_deg: float = 2.0,
    sigma_d: float = 2.0,
    n_particles: int = 200,
    los: bool = False,
    curved: bool = False,
    seed: int = 0,
) -> go.Figure:
    """Position error per epoch of the four ``jiang2023`` estimators on one simulated run, with
    sqrt(posterior CRLB); the legend gives each one's RMSE over the run."""
    from ..plots.tracking import rmse_bound_figure
    from ..tracking.pcrlb import vs_pcrlb
    from ..tracking.virtual_station import experiment, monte_carlo

    scenario = "jiang2023-curved" if curved else "jiang2023-straight"
    exp = experiment(scenario, level=(float(np.radians(sigma_theta_deg)), float(sigma_d)), los=los)
    res = monte_carlo(exp, 1, int(seed), options={"UPF": {"n_particles": int(n_particles)}})
    err = {n: np.linalg.norm(e[0, :, :2] - exp.truth[:, :2], axis=-1) for n, e in res.items()}
    bound = vs_pcrlb(exp.model, exp.truth, exp.P0)
    labels = {f"{n} (RMSE {np.sqrt(np.mean(e**2)):.2f} m)": e for n, e in err.items()}
    title = (
        f"{'curved' if curved else 'straight'}, {'LOS' if los else 'NLOS'}: "
        f"sigma_theta = {sigma_theta_deg:g} deg, sigma_d = {sigma_d:g} m, {n_particles} particles"
    )
    return rmse_bound_figure(exp.times, labels, bound, title=title)


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
        "sigma_theta_deg": float_slider("sigma_theta [deg]", v["sigma_theta_deg"], 0.1, 5.0, 0.1),
        "sigma_d": float_slider("sigma_d [m]", v["sigma_d"], 0.05, 5.0, 0.05),
        "n_particles": int_slider("UPF particles", v["n_particles"], 1, 1000, 1),
        "los": widgets.Checkbox(value=v["los"], description="LOS (direct path)"),
        "curved": widgets.Checkbox(value=v["curved"], description="curved trajectory"),
        "seed": int_slider("seed", v["seed"], 0, 50),
    }
    return Explorer(upf_figure, controls)
