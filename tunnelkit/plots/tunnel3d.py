"""Figures of notebook 03: the tunnel in 3-D with its paths, CPD factors, estimates, wave origins."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .._checks import attributes
from .._domains import interval
from .._validate import finite_array, integer, nonnegative, sequence, text, vector
from .common import figure_inputs
from .tables import TableFigure, table

__all__ = [
    "PATH_COLORS",
    "factors_figure",
    "paths_table_figure",
    "tunnel3d_figure",
    "wave_origins_figure",
]

#: one colour per path family
PATH_COLORS = {
    "los": "#2ca02c",
    "wall": "#8c564b",
    "ceiling": "#d62728",
    "road": "#7f7f7f",
    "rrm": "#9467bd",
}


def _facet_mesh(f, color: str, opacity: float, name: str, show: bool) -> go.Mesh3d:
    c = f.corners()
    return go.Mesh3d(
        x=c[:, 0],
        y=c[:, 1],
        z=c[:, 2],
        i=[0, 0],
        j=[1, 2],
        k=[2, 3],
        color=color,
        opacity=opacity,
        name=name,
        showlegend=show,
        hoverinfo="name",
        flatshading=True,
    )


def tunnel3d_figure(
    tunnel,
    arrays: Sequence = (),
    paths: Sequence = (),
    ue=None,
    *,
    title: str = "",
    x_range: tuple[float, float] | None = None,
) -> go.Figure:
    """The tunnel's facets (translucent), RRM plates (purple), arrays, UE and the paths.

    Each path is drawn UE -> reflection point -> array reference antenna, coloured by family.
    ``x_range`` crops the drawn tunnel along x (facets are clipped to it).
    """
    attributes("tunnel", tunnel, ("facets", "x_range"), "a propagation.Tunnel3D")
    arrays = sequence("arrays", arrays, empty=True)  # empty: the tunnel alone
    paths = sequence("paths", paths, empty=True)
    if ue is not None:
        ue = vector("ue", ue, 3)
    if x_range is not None:
        x_range = interval("x_range", x_range)
    figure_inputs(texts={"title": title})
    fig = go.Figure()
    xr = tunnel.x_range if x_range is None else x_range
    for i, f in enumerate(tunnel.facets):
        c = f.corner.copy()
        u = f.edge_u.copy()
        if abs(u[0]) > 0:  # clip the extrusion along x
            c[0], u[0] = xr[0], xr[1] - xr[0]
        road = f.kind == "road"
        fig.add_trace(
            _facet_mesh(
                replace(f, corner=c, edge_u=u),
                "#636363" if road else "#bdbdbd",
                0.35 if road else 0.12,
                "road surface" if road else "tunnel facets",
                i in (0, len(tunnel.facets) - 1),
            )
        )
    for j, p in enumerate(tunnel.plates):
        fig.add_trace(_facet_mesh(p, PATH_COLORS["rrm"], 0.9, "RRM plates", j == 0))
    for b in tunnel.blockers:
        lo, hi = b.lo, b.hi
        xs, ys, zs = np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]], [lo[2], hi[2]], indexing="ij")
        fig.add_trace(
            go.Mesh3d(
                x=xs.ravel(),
                y=ys.ravel(),
                z=zs.ravel(),
                alphahull=0,
                color="#ff7f0e",
                opacity=0.5,
                name=b.name,
            )
        )
    for a in arrays:
        w = a.world
        fig.add_scatter3d(
            x=w[:, 0],
            y=w[:, 1],
            z=w[:, 2],
            mode="markers",
            marker={"size": 2, "color": "black"},
            name=f"array {a.name}",
        )
    seen = set()
    for p in paths:
        a0 = p.point - p.direction * p.kappa_srnf  # the array's reference antenna
        pts = np.stack([p.ue, a0]) if p.kind == "los" else np.stack([p.ue, p.point, a0])
        fig.add_scatter3d(
            x=pts[:, 0],
            y=pts[:, 1],
            z=pts[:, 2],
            mode="lines",
            line={"color": PATH_COLORS.get(p.surface_kind, "black"), "width": 4},
            name=p.surface_kind,
            legendgroup=p.surface_kind,
            showlegend=p.surface_kind not in seen,
            hovertext=p.surface or "LoS",
        )
        seen.add(p.surface_kind)
    if ue is not None:
        ue = np.asarray(ue, float)
        fig.add_scatter3d(
            x=[ue[0]],
            y=[ue[1]],
            z=[ue[2]],
            mode="markers",
            marker={"size": 5, "color": "#1f77b4"},
            name="vehicle (UE)",
        )
    fig.update_layout(
        title=title,
        height=520,
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        scene={
            "aspectmode": "data",
            "xaxis_title": "x [m]",
            "yaxis_title": "y [m]",
            "zaxis_title": "z [m]",
            # far enough out that both ends (the base station's included) stay in the view
            "camera": {"eye": {"x": -0.7, "y": -3.0, "z": 1.3}},
        },
    )
    return fig


def paths_table_figure(rows: Sequence[dict], *, title: str = "") -> TableFigure:
    """A table from a list of dicts (same keys; floats shown with 4 significant digits), as HTML."""
    rows = sequence("rows", rows, empty=True)
    if not rows:
        return table([], [], title=text("title", title, empty=True))
    if not all(isinstance(r, dict) for r in rows):
        raise TypeError("rows: expected dicts (one per path)")
    keys = list(rows[0])
    return table(keys, [[r[k] for k in keys] for r in rows], title=title)


def factors_figure(
    factors,
    *,
    unwrapped=None,
    shape: tuple[int, int] | None = None,
    title: str = "Phase [rad] of the CPD factor matrices (normalised, eq. 12-13)",
) -> go.Figure:
    """Phase of the three factor matrices: spatial (unwrapped, per path), frequency, time."""
    factors = sequence("factors", factors)
    if len(factors) != 3:
        raise ValueError(f"factors: expected the three factor matrices, got {len(factors)}")
    if shape is not None:
        shape = tuple(integer("shape", n, minimum=1) for n in sequence("shape", shape))
    if unwrapped is not None:
        unwrapped = finite_array("unwrapped", unwrapped, ndim=2)
    figure_inputs(texts={"title": title})
    bs, bf, bt = factors
    fig = make_subplots(
        rows=1,
        cols=3,
        subplot_titles=(  # short: three panels side by side in a narrow output area
            "(a) spatial, unwrapped (eq. 16)",
            "(b) frequency",
            "(c) time",
        ),
    )
    sp = unwrapped if unwrapped is not None else np.unwrap(np.angle(bs), axis=0)
    # one colour per path in all three panels (left to itself, plotly would colour each trace
    # by its index, so panels (b) and (c) would show colours the legend does not have)
    palette = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")
    for j_ in range(bf.shape[1]):
        color = palette[j_ % len(palette)]
        panels = (
            (sp[:, j_], "lines"),
            (np.unwrap(np.angle(bf[:, j_])), "lines"),
            (np.unwrap(np.angle(bt[:, j_])), "lines+markers"),
        )
        for col, (y, mode) in enumerate(panels, start=1):
            fig.add_scatter(
                y=y,
                mode=mode,
                name=f"path {j_}",
                legendgroup=f"C{j_}",
                showlegend=None if col == 1 else False,  # one legend entry per path
                line={"color": color},
                marker={"color": color},
                row=1,
                col=col,
            )
    fig.update_xaxes(title_text="antenna m", row=1, col=1)
    fig.update_xaxes(title_text="tone s", row=1, col=2)
    fig.update_xaxes(title_text="symbol k", row=1, col=3)
    fig.update_layout(title=title, height=380, margin={"l": 50, "r": 10, "t": 90, "b": 40})
    return fig


def wave_origins_figure(
    origins: dict[str, np.ndarray],
    trajectory=None,
    bs=None,
    *,
    title: str = "Estimated wave origins, colour = altitude (cf. Fig. 5)",
    z_range: tuple[float, float] = (0.0, 5.0),
    margin_m: float = 30.0,
) -> go.Figure:
    """Top view (x, y) of estimated wave origins coloured by altitude z, one marker per series.

    With a ``trajectory`` or ``bs``, the view spans their x extent plus ``margin_m`` on each side;
    origins beyond it (a wild estimate metres or kilometres away would squash the rest into a
    strip) are left out and counted in the title."""
    if not isinstance(origins, dict):
        raise TypeError(f"origins: expected a dict name -> points (n, 3), got {origins!r:.40}")
    named = {"trajectory": trajectory, "bs": bs}
    anchors = [finite_array(k, a).reshape(-1, 3)[:, 0] for k, a in named.items() if a is not None]
    z_range = interval("z_range", z_range)
    margin_m, title = nonnegative("margin_m", margin_m), text("title", title, empty=True)
    fig = go.Figure()
    symbols = ["circle", "x", "diamond", "square"]
    x_lim = None
    if anchors:
        xs = np.concatenate(anchors)
        x_lim = (float(xs.min()) - margin_m, float(xs.max()) + margin_m)
    n_out = 0
    for i, (name, pts) in enumerate(origins.items()):
        pts = np.asarray(pts, float).reshape(-1, 3)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if x_lim is not None:
            keep = (pts[:, 0] >= x_lim[0]) & (pts[:, 0] <= x_lim[1])
            n_out += int(np.sum(~keep))
            pts = pts[keep]
        fig.add_scatter(
            x=pts[:, 0],
            y=pts[:, 1],
            mode="markers",
            name=name,
            marker={
                "color": pts[:, 2],
                "colorscale": "YlOrRd",
                "cmin": z_range[0],
                "cmax": z_range[1],
                "size": 6,
                "symbol": symbols[i % 4],
                "colorbar": {"title": "z [m]"} if i == 0 else None,
                "line": {"width": 0.5, "color": "#444"},
            },
        )
    if trajectory is not None:
        pos = np.asarray(trajectory)
        fig.add_scatter(
            x=pos[:, 0],
            y=pos[:, 1],
            mode="lines",
            name="UE trajectory",
            line={"color": "#1f77b4", "width": 3},
        )
    if bs is not None:
        fig.add_scatter(
            x=[bs[0]],
            y=[bs[1]],
            mode="markers",
            name="BS",
            marker={"symbol": "square", "size": 12, "color": "red"},
        )
    if n_out:
        title = f"{title}; {n_out} origin(s) beyond x = {x_lim[0]:.0f}..{x_lim[1]:.0f} m not shown"
    fig.update_layout(
        title=title,
        height=420,
        xaxis_title="x [m]",
        yaxis_title="y [m]",
        legend={"orientation": "h", "y": -0.2},
        margin={"l": 60, "r": 20, "t": 50, "b": 40},
    )
    fig.update_yaxes(scaleanchor="x", scaleratio=1)
    return fig
