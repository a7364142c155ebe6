"""Notebook 01 explorer: sqrt(CRLB) over the tunnel for chosen TOA/DOA noise levels."""

from __future__ import annotations

import ipywidgets as widgets
import numpy as np
import plotly.graph_objects as go

from .. import crlb
from .._validate import boolean, finite_array, integer, positive
from ..budget import check_elements
from ..scenarios import load_scenario
from ..tunnel2d import Tunnel2D
from .base import Explorer, float_slider

__all__ = ["crlb_explorer", "crlb_figure", "crlb_map"]


def crlb_map(
    tunnel,
    stations,
    sigma_theta: float,
    sigma_d: float,
    *,
    along=(0.0, 150.0),
    n_along: int = 151,
    n_across: int = 61,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """sqrt(CRLB) [m] on a grid in tunnel coordinates (along, across), walls excluded by a 0.1 m margin.

    Returns ``(along, across, rmse)`` with ``rmse`` of shape (n_across, n_along).
    """
    if not isinstance(tunnel, Tunnel2D):
        raise TypeError(f"tunnel: expected a tunnel2d.Tunnel2D, got {type(tunnel).__name__}")
    along = finite_array("along", along, shape=(2,))
    n_along = integer("n_along", n_along, minimum=2)
    n_across = integer("n_across", n_across, minimum=2)
    check_elements("n_along, n_across", 64 * n_along * n_across, what="the CRLB map")
    a = np.linspace(along[0], along[1], n_along)
    c = np.linspace(0.1, tunnel.width - 0.1, n_across)
    grid = tunnel.from_tunnel_frame(np.stack(np.meshgrid(a, c), -1))
    return a, c, crlb.crlb_rmse(grid, stations, sigma_theta, sigma_d)


def crlb_figure(
    sigma_theta_deg: float = 0.5,
    sigma_d: float = 0.1,
    los: bool = False,
    scenario: str = "jiang2023-straight",
    log_scale: bool = True,
) -> go.Figure:
    """Heat map of sqrt(CRLB) (Jiang eq. 28 with the corrected F_xy) over the tunnel.

    NLOS uses the two virtual stations; ``los=True`` adds the base station itself (the direct path).
    """
    sigma_theta_deg, sigma_d = (
        positive("sigma_theta_deg", sigma_theta_deg),
        positive("sigma_d", sigma_d),
    )
    los, log_scale = boolean("los", los), boolean("log_scale", log_scale)
    sc = load_scenario(scenario)
    tunnel, bs = sc.tunnel(), sc.base_station()
    stations = tunnel.virtual_stations(bs)
    if los:
        stations = np.vstack([bs, stations])
    a, c, r = crlb_map(tunnel, stations, np.radians(sigma_theta_deg), sigma_d)
    z = np.log10(r) if log_scale else r
    ticks = np.array([0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20])
    colorbar = {"title": "sqrt(CRLB) [m]"}
    if log_scale:
        colorbar.update(tickvals=np.log10(ticks), ticktext=[f"{t:g}" for t in ticks])
    fig = go.Figure(
        go.Heatmap(
            x=a,
            y=c,
            z=z,
            colorscale="Viridis",
            colorbar=colorbar,
            customdata=r,
            hovertemplate="along %{x:.1f} m<br>across %{y:.1f} m"
            "<br>sqrt(CRLB) %{customdata:.3f} m<extra></extra>",
        )
    )
    bs_t = tunnel.to_tunnel_frame(bs)
    fig.add_scatter(
        x=[bs_t[0]],
        y=[bs_t[1]],
        mode="markers+text",
        text=["BS"],
        textposition="top right",
        marker={"symbol": "triangle-up", "size": 13, "color": "white", "line": {"width": 1}},
        showlegend=False,
    )
    mode = "LOS + two wall reflections" if los else "NLOS: two wall reflections"
    fig.update_layout(
        title=f"sqrt(CRLB) — {mode}, σθ = {sigma_theta_deg:g}°, σd = {sigma_d:g} m "
        f"(median {np.median(r):.3g} m)",
        xaxis_title="along the tunnel [m]",
        yaxis_title="across [m] (from wall 2)",
        height=360,
        margin={"l": 60, "r": 20, "t": 50, "b": 50},
    )
    return fig


def crlb_explorer(scenario: str = "jiang2023-straight") -> Explorer:
    """Sliders for sigma_theta [deg] and sigma_d [m] and a LOS switch, redrawing the heat map."""
    if not isinstance(scenario, str) or not scenario:
        raise TypeError(f"scenario: expected a scenario name or a .toml path, got {scenario!r}")
    load_scenario(scenario)  # a wrong name is refused before the first map is computed
    controls = {
        "sigma_theta_deg": float_slider("σθ [deg]", 0.5, 0.1, 5.0, 0.1),
        "sigma_d": float_slider("σd [m]", 0.1, 0.05, 5.0, 0.05),
        "los": widgets.Checkbox(value=False, description="LOS path too"),
    }
    return Explorer(lambda **kw: crlb_figure(scenario=scenario, **kw), controls)
