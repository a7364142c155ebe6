"""Notebook 03: extraction routes against the Cramér-Rao bound along the drive."""

from __future__ import annotations

import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .._validate import sequence, text
from .common import figure_inputs

__all__ = ["efficiency_figure"]

#: one colour and a readable name per extraction route
ROUTE_STYLE = {
    "none": ("paper's eq. 13 roots", "#8c564b"),
    "column": ("paper, per-column roots", "#9467bd"),
    "joint": ("paper's route (CPD, eq. 13-24)", "#ff7f0e"),
    "coherent": ("coherent split", "#1f77b4"),
    "ml": ("joint ML (eq. 1)", "#2ca02c"),
}


def efficiency_figure(rows: list[dict], path: str = "los", *, title: str = "") -> go.Figure:
    """Direction (left) and curvature (right) RMSE against range, one line per route, the CRLB
    dashed; ``rows`` from :func:`tunnelkit.efficiency.drive_efficiency`, ``path`` a surface kind."""
    rows = sequence("rows", rows)
    path = text("path", path)
    figure_inputs(texts={"title": title})
    from ..efficiency import efficiency_rows

    data = efficiency_rows(rows, path)
    fig = make_subplots(
        rows=1,
        cols=2,
        subplot_titles=("direction RMSE [deg]", "curvature RMSE [m]"),
        horizontal_spacing=0.1,
    )
    for route, d in data.items():
        name, color = ROUTE_STYLE.get(route, (route, None))
        for col, key in ((1, "dir"), (2, "kappa")):
            fig.add_scatter(
                x=d["range"],
                y=d[key],
                mode="lines+markers",
                name=name,
                legendgroup=route,
                showlegend=col == 1,
                line={"color": color},
                row=1,
                col=col,
            )
    first = next(iter(data.values()))
    for col, key in ((1, "crlb_dir"), (2, "crlb_kappa")):
        fig.add_scatter(
            x=first["range"],
            y=first[key],
            mode="lines",
            name="CRLB (eq. 1)",
            legendgroup="crlb",
            showlegend=col == 1,
            line={"color": "#000000", "dash": "dash"},
            row=1,
            col=col,
        )
    fig.update_yaxes(type="log")
    fig.update_xaxes(title_text=f"range of the UE [m] ({path} path)")
    fig.update_layout(
        title=title or f"{path} path: estimators against the Cramér-Rao bound along the drive",
        height=420,
        margin={"l": 60, "r": 20, "t": 70, "b": 50},
    )
    return fig
