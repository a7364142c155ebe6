"""Shared plotting helpers: colours per algorithm, line plots, empirical CDFs."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import plotly.graph_objects as go

from ..metrics import ecdf

__all__ = ["COLORS", "cdf_figure", "line_figure"]

#: one colour per role/algorithm, used by every notebook so legends read the same everywhere
COLORS = {
    "truth": "#2ca02c",
    "bs": "#000000",
    "vs": "#7f7f7f",
    "LS": "#8c564b",
    "TSWLS": "#9467bd",
    "EKF": "#1f77b4",
    "UKF": "#ff7f0e",
    "UPF": "#d62728",
    "CRLB": "#000000",
    "JAVELIN": "#1f77b4",
    "TeNFiLoc": "#d62728",
}


def line_figure(
    x,
    series: Mapping[str, np.ndarray],
    *,
    title: str = "",
    xaxis: str = "",
    yaxis: str = "",
    dash: Mapping[str, str] | None = None,
    log_y: bool = False,
) -> go.Figure:
    """One line per entry of ``series`` against ``x``."""
    fig = go.Figure()
    for name, y in series.items():
        fig.add_scatter(
            x=np.asarray(x),
            y=np.asarray(y),
            mode="lines",
            name=name,
            line={"color": COLORS.get(name.split()[0]), "dash": (dash or {}).get(name)},
        )
    fig.update_layout(
        title=title,
        xaxis_title=xaxis,
        yaxis_title=yaxis,
        height=380,
        margin={"l": 60, "r": 20, "t": 50, "b": 50},
    )
    if log_y:
        fig.update_yaxes(type="log")
    return fig


def cdf_figure(
    errors: Mapping[str, np.ndarray], *, title: str = "", xaxis: str = "error [m]"
) -> go.Figure:
    """Empirical CDFs of error samples, one line each."""
    fig = go.Figure()
    for name, e in errors.items():
        x, p = ecdf(e)
        fig.add_scatter(
            x=x,
            y=p,
            mode="lines",
            name=name,
            line={"color": COLORS.get(name.split()[0]), "shape": "hv"},
        )
    fig.update_layout(
        title=title,
        xaxis_title=xaxis,
        yaxis_title="CDF",
        height=380,
        yaxis_range=[0, 1.02],
        margin={"l": 60, "r": 20, "t": 50, "b": 50},
    )
    return fig
