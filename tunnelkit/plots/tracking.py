"""Figures of notebook 05: tracks with a time slider, RMSE against the posterior CRLB, particle clouds."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .._checks import attributes
from .._domains import nonnegative_array
from .._validate import finite_array, integer, positive, sequence, text
from .common import COLORS, figure_inputs, line_figure, reveal_overlaps
from .tables import TableFigure, table
from .topview import tunnel_topview

__all__ = [
    "bound_ratio_figure",
    "particle_cloud_figure",
    "rmse_bound_figure",
    "table_figure",
    "tracks_figure",
]


def tracks_figure(
    tunnel,
    base_station,
    truth,
    estimates: Mapping[str, np.ndarray],
    *,
    period: float = 0.1,
    title: str = "One run, four estimators",
    every: int = 5,
) -> go.Figure:
    """Top view with the true track and each estimator's track; a slider (and play button) moves
    one marker per estimator along time. ``truth`` (T, >=2), ``estimates`` name -> (T, >=2)."""
    attributes("tunnel", tunnel, ("to_tunnel_frame",), "a tunnel (tunnel2d.Tunnel2D)")
    truth = finite_array("truth", truth, ndim=2)
    figure_inputs(texts={"title": title}, mappings={"estimates": estimates})
    period = positive("period", period)
    every = integer("every", every, minimum=1)
    truth = np.asarray(truth)[:, :2]
    lo, hi = tunnel.to_tunnel_frame(truth)[:, 0][[0, -1]]
    fig = tunnel_topview(tunnel, base_station, along=(min(lo, -5.0) - 10, hi + 15), title=title)
    fig.add_scatter(
        x=truth[:, 0],
        y=truth[:, 1],
        mode="lines",
        name="truth",
        line={"color": COLORS["truth"], "width": 3},
    )
    for name, e in estimates.items():
        e = np.asarray(e)[:, :2]
        fig.add_scatter(
            x=e[:, 0],
            y=e[:, 1],
            mode="lines",
            name=name,
            opacity=0.6,
            line={"color": COLORS.get(name), "width": 1},
        )
    names = ["truth", *estimates]
    tracks = {"truth": truth, **{n: np.asarray(e)[:, :2] for n, e in estimates.items()}}
    first = len(fig.data)
    for n in names:
        fig.add_scatter(
            x=tracks[n][:1, 0],
            y=tracks[n][:1, 1],
            mode="markers",
            name=f"{n} now",
            showlegend=False,
            marker={
                "color": COLORS.get(n),
                "size": 11 if n == "truth" else 8,
                "symbol": "circle-open" if n == "truth" else "x",
            },
        )
    idx = list(range(first, first + len(names)))
    ks = list(range(0, truth.shape[0], every)) + (
        [truth.shape[0] - 1] if (truth.shape[0] - 1) % every else []
    )
    fig.frames = [
        go.Frame(
            name=str(k),
            traces=idx,
            data=[go.Scatter(x=tracks[n][k : k + 1, 0], y=tracks[n][k : k + 1, 1]) for n in names],
        )
        for k in ks
    ]
    steps = [
        {
            "method": "animate",
            "label": f"{k * period:.1f}",
            "args": [[str(k)], {"mode": "immediate", "frame": {"duration": 0, "redraw": False}}],
        }
        for k in ks
    ]
    fig.update_layout(
        height=520,
        sliders=[{"steps": steps, "currentvalue": {"prefix": "t [s] = "}, "pad": {"t": 40}}],
        updatemenus=[
            {
                "type": "buttons",
                "showactive": False,
                "x": 0.0,
                "y": -0.08,
                "xanchor": "left",
                "buttons": [
                    {
                        "label": "play",
                        "method": "animate",
                        "args": [
                            None,
                            {"frame": {"duration": 80, "redraw": False}, "fromcurrent": True},
                        ],
                    }
                ],
            }
        ],
    )
    fig.update_yaxes(scaleanchor="x", scaleratio=1)
    return reveal_overlaps(fig)


#: the dashed curve's name: the posterior CRLB with the measurement information evaluated along
#: the one nominal path, an approximation of the bound over random drives about that path
BOUND_NAME = "sqrt(PCRLB), H along the nominal path (approx.)"


def rmse_bound_figure(
    t,
    rmse: Mapping[str, np.ndarray],
    bound,
    *,
    title: str = "",
    log_y: bool = True,
    bound_name: str = BOUND_NAME,
) -> go.Figure:
    """RMSE per epoch of each estimator with sqrt(posterior CRLB) dashed underneath, named
    ``bound_name`` (default: what it is, the bound of random drives with ``H`` evaluated along
    the nominal path, an approximation; in no case a bound on one drive's error)."""
    t = finite_array("t", t, ndim=1)
    bound_name = text("bound_name", bound_name)
    if not isinstance(rmse, Mapping):
        raise TypeError(f"rmse: expected a mapping name -> values, got {type(rmse).__name__}")
    bound = nonnegative_array("bound", bound, shape=(len(t),))
    series = {**rmse, "PCRLB": bound}
    fig = line_figure(
        t,
        series,
        title=title,
        xaxis="t [s]",
        yaxis="position RMSE [m]",
        dash={"PCRLB": "dash"},
        log_y=log_y,
    )
    fig.data[-1].name = bound_name
    return fig


def bound_ratio_figure(
    t,
    panels: Mapping[str, tuple[Mapping[str, np.ndarray], np.ndarray]],
    *,
    title: str = "RMSE / sqrt(PCRLB) per epoch",
) -> go.Figure:
    """One panel per truth: each filter's RMSE divided by sqrt(PCRLB), epoch by epoch, with the
    bound's level 1 dashed. ``panels`` maps a panel title to ``(rmse per filter (T,), bound (T,))``."""
    t = finite_array("t", t, ndim=1)
    if not isinstance(panels, Mapping) or not panels:
        raise TypeError(
            f"panels: expected a non-empty mapping title -> (rmse, bound), got {panels!r:.40}"
        )
    title = text("title", title, empty=True)
    fig = make_subplots(
        rows=1,
        cols=len(panels),
        subplot_titles=list(panels),
        shared_yaxes=True,
        horizontal_spacing=0.05,
    )
    t = np.asarray(t)
    for c, (rmse, bound) in enumerate(panels.values(), start=1):
        b = np.asarray(bound, dtype=float)
        for name, r in rmse.items():
            fig.add_scatter(
                x=t,
                y=np.asarray(r) / b,
                mode="lines",
                name=name,
                legendgroup=name,
                showlegend=c == 1,
                line={"color": COLORS.get(name)},
                row=1,
                col=c,
            )
        fig.add_hline(y=1.0, line={"dash": "dash", "color": COLORS["CRLB"]}, row=1, col=c)
        fig.update_xaxes(title_text="t [s]", row=1, col=c)
    fig.update_yaxes(title_text="RMSE / sqrt(PCRLB)", row=1, col=1)
    fig.update_layout(
        title=title,
        height=380,
        margin={"l": 60, "r": 20, "t": 90, "b": 50},
    )
    return reveal_overlaps(fig)


def particle_cloud_figure(
    snapshots: Sequence[Mapping], *, title: str = "UPF particle clouds", half_width: float = 3.0
) -> go.Figure:
    """One panel per snapshot ``{"k", "t", "particles" (N, >=2), "weights" (N,), "truth" (2,),
    "estimate" (2,)}``; marker area follows the weight. Axes span ``half_width`` around the truth."""
    snapshots = sequence("snapshots", snapshots)
    figure_inputs(texts={"title": title})
    half_width = positive("half_width", half_width)
    fig = make_subplots(
        rows=1,
        cols=len(snapshots),
        subplot_titles=[f"t = {s['t']:.1f} s" for s in snapshots],
        horizontal_spacing=0.06,
    )
    for c, s in enumerate(snapshots, start=1):
        p = np.asarray(s["particles"])[:, :2]
        w = np.asarray(s["weights"], dtype=float)
        size = 4 + 16 * np.sqrt(w / w.max())
        fig.add_scatter(
            x=p[:, 0],
            y=p[:, 1],
            mode="markers",
            name="particles",
            showlegend=c == 1,
            marker={"size": size, "color": COLORS["UPF"], "opacity": 0.35},
            row=1,
            col=c,
        )
        tr, est = np.asarray(s["truth"]), np.asarray(s["estimate"])
        fig.add_scatter(
            x=[tr[0]],
            y=[tr[1]],
            mode="markers",
            name="truth",
            showlegend=c == 1,
            marker={"color": COLORS["truth"], "size": 12, "symbol": "circle-open"},
            row=1,
            col=c,
        )
        fig.add_scatter(
            x=[est[0]],
            y=[est[1]],
            mode="markers",
            name="UPF estimate",
            showlegend=c == 1,
            marker={"color": "black", "size": 10, "symbol": "x"},
            row=1,
            col=c,
        )
        # wide enough for the cloud (its 99th percentile around the truth), never narrower than
        # half_width: a cloud cut at the panel's edge hides the very spread it is drawn for
        hw = max(half_width, 1.1 * float(np.percentile(np.abs(p - tr[:2]), 99)))
        fig.update_xaxes(range=[tr[0] - hw, tr[0] + hw], title_text="x [m]", row=1, col=c)
        fig.update_yaxes(range=[tr[1] - hw, tr[1] + hw], row=1, col=c)
    fig.update_yaxes(title_text="y [m]", row=1, col=1)
    fig.update_layout(title=title, height=380, margin={"l": 60, "r": 20, "t": 90, "b": 50})
    return fig


def table_figure(
    rows: Sequence[Mapping], columns: Sequence[str], *, title: str = ""
) -> TableFigure:
    """A table of dict rows (floats shown with 4 significant digits), shown as HTML."""
    columns = sequence("columns", columns, empty=True)
    rows = sequence("rows", rows, empty=True)
    for i, r in enumerate(rows):
        if not isinstance(r, Mapping):
            raise TypeError(f"rows: row {i} is a {type(r).__name__}, expected a mapping")
    return table(columns, [[r[c] for c in columns] for r in rows], title=title)
