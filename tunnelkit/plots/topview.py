"""Top view of Jiang's 2-D tunnel: walls, base station, virtual stations, vehicle and paths."""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from .._domains import interval
from .._validate import finite_array, text, vector
from ..reflection import specular_point
from ..tunnel2d import Tunnel2D
from .common import COLORS

__all__ = ["tunnel_topview"]


def _text_away(d) -> str:
    """A plotly ``textposition`` that puts a marker's label on the side ``d`` points to."""
    return ("top" if d[1] >= 0 else "bottom") + " " + ("right" if d[0] >= 0 else "left")


def tunnel_topview(
    tunnel: Tunnel2D,
    base_station,
    *,
    vehicle=None,
    along=(-30.0, 160.0),
    trajectory=None,
    title: str = "Tunnel top view",
) -> go.Figure:
    """Walls over an ``along`` range, the base station, both virtual stations and, for a vehicle,
    the two wall-reflected paths (solid) with their virtual-station equivalents (dotted)."""
    if not isinstance(tunnel, Tunnel2D):
        raise TypeError(f"tunnel: expected a tunnel2d.Tunnel2D, got {type(tunnel).__name__}")
    bs = vector("base_station", base_station, 2)
    a = np.asarray(interval("along", along))
    if vehicle is not None:
        vehicle = vector("vehicle", vehicle, 2)
    if trajectory is not None:
        trajectory = finite_array("trajectory", trajectory, ndim=2)
        if trajectory.shape[1] < 2:
            raise ValueError(f"trajectory: expected shape (T, 2), got {trajectory.shape}")
    title = text("title", title)
    vs = tunnel.virtual_stations(bs)
    fig = go.Figure()
    for k in range(2):
        ends = tunnel.from_tunnel_frame(
            np.stack([a, np.full(2, tunnel.width if k == 0 else 0.0)], -1)
        )
        fig.add_scatter(
            x=ends[:, 0],
            y=ends[:, 1],
            mode="lines",
            name=f"wall {k + 1}",
            line={"color": "#444", "width": 4},
        )
    fig.add_scatter(
        x=[bs[0]],
        y=[bs[1]],
        mode="markers+text",
        name="base station",
        text=["BS"],
        # away from both virtual stations (they lie across the walls): back along the tunnel
        textposition=_text_away(-np.asarray(tunnel.axis, dtype=float)[:2]),
        marker={"symbol": "triangle-up", "size": 14, "color": COLORS["bs"]},
    )
    fig.add_scatter(
        x=vs[:, 0],
        y=vs[:, 1],
        mode="markers+text",
        name="virtual stations",
        text=["VS1", "VS2"],
        textposition=[_text_away(v - bs) for v in vs],
        marker={"symbol": "triangle-up-open", "size": 14, "color": COLORS["vs"]},
    )
    if trajectory is not None:
        tr = np.asarray(trajectory, dtype=float)
        fig.add_scatter(
            x=tr[:, 0],
            y=tr[:, 1],
            mode="lines",
            name="trajectory",
            line={"color": COLORS["truth"], "dash": "dot"},
        )
    if vehicle is not None:
        v = np.asarray(vehicle, dtype=float)
        for k, w in enumerate(tunnel.walls):
            r = specular_point(bs, v, w)
            fig.add_scatter(
                x=[bs[0], r[0], v[0]],
                y=[bs[1], r[1], v[1]],
                mode="lines",
                name=f"reflected path {k + 1}",
                line={"width": 2},
            )
            fig.add_scatter(
                x=[vs[k, 0], r[0]],
                y=[vs[k, 1], r[1]],
                mode="lines",
                showlegend=False,
                line={"dash": "dot", "color": COLORS["vs"], "width": 1},
                hoverinfo="skip",
            )
        fig.add_scatter(
            x=[v[0]],
            y=[v[1]],
            mode="markers",
            name="vehicle",
            marker={"symbol": "square", "size": 11, "color": COLORS["truth"]},
        )
    fig.update_layout(
        title=title,
        xaxis_title="x [m]",
        yaxis_title="y [m]",
        height=520,
        yaxis={"scaleanchor": "x", "scaleratio": 1},
        margin={"l": 60, "r": 20, "t": 50, "b": 50},
    )
    return fig
