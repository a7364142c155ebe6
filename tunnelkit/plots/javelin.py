"""Figures for notebook 04 (JAVELIN): trajectories (Fig. 6), error CDFs (Fig. 7), one epoch of the
tracker (measurements, gates, associations, births and deaths) and tables."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import plotly.graph_objects as go

from .._checks import attributes
from .._domains import nonnegative_array
from .._validate import (
    choice,
    finite_array,
    integer,
    sequence,
    text,
    vector,
)
from .common import COLORS, figure_inputs
from .tables import TableFigure, table

__all__ = ["epoch_figure", "javelin_table_figure", "tracks_count_figure", "trajectories_figure"]

_PALETTE = ["#1f77b4", "#d62728", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22"]


def _color(name: str, i: int) -> str:
    return COLORS.get(name.split()[0].split("-")[0], _PALETTE[i % len(_PALETTE)])


_FAMILY_SYMBOL = {"JAVELIN": "circle-open", "TeNFiLoc": "x"}
_MORE_SYMBOLS = ["diamond-open", "square-open", "triangle-up-open", "cross", "star-open"]


def method_styles(names) -> dict[str, dict]:
    """A distinct (symbol, colour) per method name: the paper's style (JAVELIN blue circles,
    TeNFiLoc red crosses) for the first of each family, other symbols and colours after it, so
    "JAVELIN (ours)" and "JAVELIN (paper)" never share a marker."""
    out, used_sym, used_col = {}, set(), set()
    spare_sym = iter(_MORE_SYMBOLS * 3)
    spare_col = iter([c for c in _PALETTE if c not in COLORS.values()] + _PALETTE)
    for i, name in enumerate(names):
        fam = name.split()[0].split("-")[0]
        sym = _FAMILY_SYMBOL.get(fam, "circle")
        col = _color(name, i)
        while sym in used_sym:
            sym = next(spare_sym)
        while col in used_col:
            col = next(spare_col)
        used_sym.add(sym)
        used_col.add(col)
        out[name] = {"symbol": sym, "color": col}
    return out


def trajectories_figure(
    truth, estimates: Mapping[str, np.ndarray], *, base_station=None, title: str = ""
) -> go.Figure:
    """Top view (x, y) of the true trajectory and each method's estimates (the paper's Fig. 6)."""
    truth = finite_array("truth", truth, ndim=2)
    if truth.shape[1] < 2:
        raise ValueError(f"truth: expected positions (T, 2 or 3), got shape {truth.shape}")
    if not isinstance(estimates, Mapping):
        raise TypeError(f"estimates: expected a mapping name -> positions, got {estimates!r:.40}")
    if base_station is not None:
        base_station = vector("base_station", base_station, (2, 3))
    title = text("title", title, empty=True)
    fig = go.Figure()
    fig.add_scatter(
        x=truth[:, 0],
        y=truth[:, 1],
        mode="lines+markers",
        name="truth",
        marker={"symbol": "asterisk", "size": 6, "color": COLORS["truth"]},
        line={"color": COLORS["truth"]},
    )
    styles = method_styles(list(estimates))
    for name, est in estimates.items():
        est = np.asarray(est, float)
        fig.add_scatter(
            x=est[:, 0], y=est[:, 1], mode="markers", name=name, marker={**styles[name], "size": 7}
        )
    if base_station is not None:
        fig.add_scatter(
            x=[base_station[0]],
            y=[base_station[1]],
            mode="markers",
            name="BS",
            marker={"symbol": "square", "size": 10, "color": COLORS["bs"]},
        )
    fig.update_layout(
        title=title,
        xaxis_title="x along the tunnel [m]",
        yaxis_title="y across [m]",
        height=380,
        margin={"l": 60, "r": 20, "t": 50, "b": 50},
    )
    fig.update_yaxes(range=[-5.5, 5.5])
    return fig


def _ellipse(center, cov, n_sigma: float = 2.0, n: int = 40) -> tuple[np.ndarray, np.ndarray]:
    w, V = np.linalg.eigh(0.5 * (cov + cov.T))
    t = np.linspace(0, 2 * np.pi, n)
    pts = (V @ (np.sqrt(np.maximum(w, 0))[:, None] * np.vstack([np.cos(t), np.sin(t)]))) * n_sigma
    return center[0] + pts[0], center[1] + pts[1]


def epoch_figure(
    report,
    *,
    truth=None,
    base_station=(0.0, 0.0, 0.0),
    true_vues=None,
    plane: str = "yz",
    title: str | None = None,
) -> go.Figure:
    """One epoch of :class:`tunnelkit.tracking.javelin.StepReport` in the tunnel cross-section.

    ``plane="yz"``: the UE and its VUEs share ``x`` (section 3.2), so the cross-section at the
    UE's ``x`` shows every track: prior positions with their 2-sigma ellipses (the gates' spatial
    footprint), where each measured arrival ray crosses that plane (Algorithm 3's
    ``Intersection``), association lines, births (green) and deaths (red crosses), and the
    posterior positions. ``plane="xy"`` gives the top view of the same.
    """
    attributes("report", report, ("prior_positions", "prior_cov"), "a javelin StepReport")
    if truth is not None:
        truth = vector("truth", truth, 3)
    base_station = vector("base_station", base_station, 3)
    if true_vues is not None:
        true_vues = sequence("true_vues", true_vues, empty=True)
    plane = choice("plane", plane, ("yz", "xy"))
    figure_inputs(texts={"title": title})
    from ..tracking.javelin.manage import intersection

    ax = (1, 2) if plane == "yz" else (0, 1)
    fig = go.Figure()
    prior = np.asarray(report.prior_positions)
    bs = np.asarray(base_station, float)
    x_u = prior[0, 0]
    # prior tracks and their ellipses
    for i, (p, cov) in enumerate(zip(prior, report.prior_cov)):
        if i == 0:
            c2 = cov[np.ix_(ax, ax)]
        else:
            c2 = cov if plane == "yz" else np.diag([report.prior_cov[0][0, 0], cov[0, 0]])
        ex, ey = _ellipse(p[list(ax)], c2)
        name = "UE prior" if i == 0 else f"VUE {report.prior_ids[i - 1]} prior"
        dead = report.manage is not None and i > 0 and report.prior_ids[i - 1] in report.manage.dead
        fig.add_scatter(
            x=ex,
            y=ey,
            mode="lines",
            name=name,
            showlegend=i < 2,
            legendgroup="prior",
            line={
                "color": "#1f77b4" if i == 0 else "#7f7f7f",
                "dash": "dot" if dead else "solid",
                "width": 1,
            },
        )
        fig.add_scatter(
            x=[p[ax[0]]],
            y=[p[ax[1]]],
            mode="markers+text",
            showlegend=False,
            text=["UE" if i == 0 else str(report.prior_ids[i - 1])],
            textposition="top center",
            marker={
                "symbol": "x" if dead else "circle-open",
                "size": 10,
                "color": "#d62728" if dead else ("#1f77b4" if i == 0 else "#7f7f7f"),
            },
        )
    # measurements: the arrival ray at x = x_u
    m = report.paths
    pts = []
    for j in range(len(m)):
        yz = intersection(m.phi[j], m.psi[j], x_u, bs)
        pts.append(None if yz is None else np.array([x_u, *yz]))
    xs = [p[ax[0]] for p in pts if p is not None]
    ys = [p[ax[1]] for p in pts if p is not None]
    lab = [f"path {j}" for j, p in enumerate(pts) if p is not None]
    fig.add_scatter(
        x=xs,
        y=ys,
        mode="markers+text",
        name="measured rays at x_u",
        text=lab,
        textposition="bottom center",
        marker={"symbol": "diamond", "size": 9, "color": "#ff7f0e"},
    )
    # associations (prior track -> measurement)
    for i, j in report.associated:
        if pts[j] is None:
            continue
        fig.add_scatter(
            x=[prior[i, ax[0]], pts[j][ax[0]]],
            y=[prior[i, ax[1]], pts[j][ax[1]]],
            mode="lines",
            showlegend=False,
            line={"color": "#ff7f0e", "width": 2},
        )
    # posterior and births
    post = np.asarray(report.positions)
    born = set(report.manage.born) if report.manage is not None else set()
    ids = [0, *report.ids]
    shown = set()
    for i, p in enumerate(post):
        is_born = ids[i] in born
        name = "birth" if is_born else ("UE posterior" if i == 0 else "VUE posterior")
        fig.add_scatter(
            x=[p[ax[0]]],
            y=[p[ax[1]]],
            mode="markers",
            name=name,
            legendgroup=name,
            showlegend=name not in shown,
            marker={
                "symbol": "star" if is_born else "circle",
                "size": 11 if is_born else 7,
                "color": "#2ca02c" if is_born else ("#1f77b4" if i == 0 else "#444"),
            },
        )
        shown.add(name)
    if truth is not None:
        t = np.asarray(truth, float)
        fig.add_scatter(
            x=[t[ax[0]]],
            y=[t[ax[1]]],
            mode="markers",
            name="true UE",
            marker={
                "symbol": "asterisk",
                "size": 12,
                "color": COLORS["truth"],
                "line": {"width": 2, "color": COLORS["truth"]},
            },
        )
    if true_vues is not None and len(true_vues):
        tv = np.asarray(true_vues, float)
        fig.add_scatter(
            x=tv[:, ax[0]],
            y=tv[:, ax[1]],
            mode="markers",
            name="true VUEs",
            marker={"symbol": "asterisk-open", "size": 10, "color": COLORS["truth"]},
        )
    if plane == "yz":
        th = np.linspace(0, np.pi, 60)
        fig.add_scatter(
            x=5 * np.cos(th),
            y=5 * np.sin(th),
            mode="lines",
            name="tunnel (r = 5 m)",
            line={"color": "#bbbbbb", "width": 1},
        )
    n_b = len(born)
    n_d = len(report.manage.dead) if report.manage is not None else 0
    los = report.manage.los if report.manage is not None else False
    ttl = title or (
        f"epoch {report.k}: {len(m)} paths, {len(report.associated)} associated, "
        f"{n_b} births, {n_d} deaths, LoS {'yes' if los else 'no'}"
    )
    fig.update_layout(
        title=ttl,
        xaxis_title=("y" if plane == "yz" else "x") + " [m]",
        yaxis_title=("z" if plane == "yz" else "y") + " [m]",
        height=460,
        margin={"l": 60, "r": 20, "t": 50, "b": 50},
    )
    if plane == "yz":
        fig.update_xaxes(range=[-16, 16])
        fig.update_yaxes(range=[-8, 10], scaleanchor="x", scaleratio=1)
    return fig


def tracks_count_figure(
    t, n_tracks, los=None, *, title: str = "tracked states per epoch"
) -> go.Figure:
    """Number of tracks (UE + VUEs) over time, with the epochs whose LoS existed shaded."""
    t = finite_array("t", t, ndim=1)
    n_tracks = nonnegative_array("n_tracks", n_tracks, shape=(len(t),))
    if los is not None:
        los = np.asarray(los)
        if los.dtype.kind not in "bi" or los.shape != t.shape:
            raise TypeError(
                f"los: expected {len(t)} booleans, got {los.dtype} of shape {los.shape}"
            )
    title = text("title", title, empty=True)
    fig = go.Figure()
    fig.add_scatter(
        x=np.asarray(t),
        y=np.asarray(n_tracks),
        mode="lines+markers",
        name="L_hat",
        line={"shape": "hv", "color": COLORS["JAVELIN"]},
    )
    if los is not None:
        fig.add_bar(
            x=np.asarray(t),
            y=np.where(np.asarray(los), 0.5, 0.0),
            name="LoS present",
            marker={"color": "#2ca02c"},
            opacity=0.4,
        )
    fig.update_layout(
        title=title,
        xaxis_title="t [s]",
        yaxis_title="tracks",
        height=300,
        margin={"l": 60, "r": 20, "t": 50, "b": 50},
    )
    return fig


def javelin_table_figure(
    columns: Sequence[str], rows: Sequence[Sequence], *, title: str = "", digits: int = 2
) -> TableFigure:
    """A table (numbers rounded to ``digits``, ``None`` or NaN as a dash), shown as HTML."""
    digits = integer("digits", digits, minimum=0, maximum=15)

    def fmt(v):
        if v is None:
            return "-"
        if isinstance(v, float):
            return f"{v:.{digits}f}" if np.isfinite(v) else "-"
        return str(v)

    return table(columns, rows, title=title, fmt=fmt)
