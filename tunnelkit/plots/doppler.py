"""Figures of notebook 06 (Halili 2022): the drive, Doppler/delay curves, profiles, errors, bounds."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .._validate import instance, sequence, text
from ..constants import C
from ..doppler_drive import DopplerToaMeasurements, Drive
from ..metrics import ecdf
from .common import figure_inputs, reveal_overlaps

__all__ = [
    "APPROACH_COLORS",
    "approach_cdfs",
    "doppler_delay_figure",
    "drive_topview",
    "error_time_figure",
    "information_figure",
    "pcrlb_figure",
    "profiles_figure",
    "regime_figure",
]

#: one colour per approach (the paper's three) and per role
APPROACH_COLORS = {
    "EKF DS": "#1f77b4",
    "KF DS and ToA": "#d62728",
    "EKF DS and KF ToA": "#9467bd",
    "truth": "#2ca02c",
    "tx": "#000000",
    "measured": "#7f7f7f",
}
_SIGMA_DASH = {"103.70 Hz": "solid", "32.79 Hz": "dash", "10.37 Hz": "dot", "dynamic": "dashdot"}
_MARGIN = {"l": 60, "r": 20, "t": 50, "b": 50}
# figures with subplot titles: the figure title gets its own band above them
_MARGIN_SUB = {**_MARGIN, "t": 90}


def drive_topview(
    drive, tracks: Mapping[str, np.ndarray] | None = None, *, title: str = ""
) -> go.Figure:
    """Top view: tube walls, transmitter, true path and (optionally) estimated paths (T, 2) each.

    The tube is 1.3 km long and 10 m wide, so the y axis is stretched.
    """
    instance("drive", drive, Drive)
    if tracks is not None and not isinstance(tracks, Mapping):
        raise TypeError(
            f"tracks: expected a mapping name -> positions, got {type(tracks).__name__}"
        )
    title = text("title", title, empty=True)
    cfg = drive.config
    x0, x1 = float(drive.position[:, 0].min()) - 20, float(drive.position[:, 0].max()) + 20
    fig = go.Figure()
    for y in (-cfg.width / 2, cfg.width / 2):
        fig.add_scatter(
            x=[x0, x1],
            y=[y, y],
            mode="lines",
            line={"color": "#444", "width": 3},
            name="wall",
            showlegend=y > 0,
            hoverinfo="skip",
        )
    fig.add_scatter(
        x=drive.position[:, 0],
        y=drive.position[:, 1],
        mode="lines",
        name="truth",
        line={"color": APPROACH_COLORS["truth"], "width": 3},
    )
    for name, p in (tracks or {}).items():
        p = np.asarray(p)
        fig.add_scatter(
            x=p[:, 0],
            y=p[:, 1],
            mode="lines",
            name=name,
            line={"color": APPROACH_COLORS.get(name), "width": 1.5},
        )
    fig.add_scatter(
        x=[drive.tx[0]],
        y=[drive.tx[1]],
        mode="markers+text",
        name="transmitter (RSU)",
        marker={"symbol": "triangle-down", "size": 14, "color": APPROACH_COLORS["tx"]},
        text=["Tx"],
        textposition="top center",
    )
    ys = [np.asarray(p)[:, 1] for p in (tracks or {}).values()]
    lo = min([-cfg.width / 2 - 2] + [float(y.min()) - 1 for y in ys])
    hi = max([cfg.width / 2 + 2] + [float(y.max()) + 1 for y in ys])
    fig.update_layout(
        title=title or "The drive from above (y stretched)",
        xaxis_title="x along the tunnel [m]",
        yaxis_title="y across [m]",
        height=330,
        margin=_MARGIN,
        yaxis_range=[lo, hi],
    )
    return reveal_overlaps(fig)


def doppler_delay_figure(drive, meas=None) -> go.Figure:
    """Doppler over time (line of sight, multipath peak, measured) and the ToA error in ns.

    The right panel shows what the delay estimate adds to the geometric delay ``r / c``: the
    multipath pull of the impulse-response peak and, if ``meas`` is given, noise, NLOS and clock.
    """
    instance("drive", drive, Drive)
    if meas is not None:
        instance("meas", meas, DopplerToaMeasurements)
    fig = make_subplots(
        rows=1, cols=2, subplot_titles=("Doppler shift [Hz]", "ToA minus line-of-sight delay [ns]")
    )
    t = drive.t
    grey = {"size": 2, "color": APPROACH_COLORS["measured"]}
    if meas is not None:
        fig.add_scatter(
            x=t, y=meas.doppler, mode="markers", marker=grey, name="measured", row=1, col=1
        )
        fig.add_scatter(
            x=t,
            y=(meas.toa - drive.toa_los) * 1e9,
            mode="markers",
            marker=grey,
            name="measured ToA (noise, NLOS, clock)",
            row=1,
            col=2,
        )
    fig.add_scatter(
        x=t,
        y=drive.doppler_los,
        mode="lines",
        name="line of sight",
        line={"color": APPROACH_COLORS["truth"], "width": 2},
        row=1,
        col=1,
    )
    peak = {"color": "#ff7f0e", "width": 1}
    fig.add_scatter(
        x=t,
        y=drive.doppler_peak,
        mode="lines",
        name="multipath peak (noise-free)",
        line=peak,
        legendgroup="peak",
        row=1,
        col=1,
    )
    fig.add_scatter(
        x=t,
        y=(drive.toa_peak - drive.toa_los) * 1e9,
        mode="lines",
        line=peak,
        legendgroup="peak",
        showlegend=False,
        row=1,
        col=2,
    )
    for col in (1, 2):
        fig.add_vline(
            x=float(t[drive.closest_index]), line={"dash": "dot", "color": "#000"}, row=1, col=col
        )
    fig.update_xaxes(title_text="time [s] (dotted: the pass)")
    fig.update_layout(
        height=400,
        margin=_MARGIN_SUB,
        title="Approach: Doppler > 0; after the pass: Doppler < 0",
    )
    return fig


def profiles_figure(profiles: Mapping[str, np.ndarray]) -> go.Figure:
    """Synthetic power-delay and Doppler power profiles over time (the paper's Fig. 2)."""
    figure_inputs(mappings={"profiles": profiles})
    fig = make_subplots(
        rows=1, cols=2, subplot_titles=("(a) power-delay profile", "(b) Doppler power profile")
    )
    fig.add_heatmap(
        x=profiles["t"],
        y=profiles["delay"] * 1e6,
        z=profiles["pdp_db"].T,
        zmin=-50,
        zmax=0,
        colorscale="Viridis",
        colorbar={"title": "dB", "x": 1.0},
        row=1,
        col=1,
    )
    fig.add_heatmap(
        x=profiles["t"],
        y=profiles["doppler"],
        z=profiles["dpp_db"].T,
        zmin=-50,
        zmax=0,
        colorscale="Viridis",
        showscale=False,
        row=1,
        col=2,
    )
    fig.update_xaxes(title_text="time [s]")
    fig.update_yaxes(title_text="delay [us]", row=1, col=1)
    fig.update_yaxes(title_text="Doppler [Hz]", row=1, col=2)
    fig.update_layout(height=400, margin=_MARGIN_SUB)
    return fig


def error_time_figure(drive, tracks: Mapping[str, np.ndarray], *, title: str = "") -> go.Figure:
    """Fig. 3 in synthetic form: (a) along-track and (b) lateral error, (c) position error over time."""
    instance("drive", drive, Drive)
    figure_inputs(texts={"title": title}, mappings={"tracks": tracks})
    fig = make_subplots(
        rows=3,
        cols=1,
        shared_xaxes=True,
        vertical_spacing=0.06,
        subplot_titles=(
            "(a) along-track error [m]",
            "(b) lateral error [m]",
            "(c) position error [m]",
        ),
    )
    for name, p in tracks.items():
        d = np.asarray(p) - drive.position
        color = APPROACH_COLORS.get(name)
        for row, y in ((1, d[:, 0]), (2, d[:, 1]), (3, np.hypot(d[:, 0], d[:, 1]))):
            fig.add_scatter(
                x=drive.t,
                y=y,
                mode="lines",
                name=name,
                legendgroup=name,
                showlegend=row == 1,
                line={"color": color, "width": 1.5},
                row=row,
                col=1,
            )
    for row in (1, 2, 3):
        fig.add_vline(
            x=float(drive.t[drive.closest_index]),
            line={"dash": "dot", "color": "#000"},
            row=row,
            col=1,
        )
    fig.update_xaxes(title_text="time [s]", row=3, col=1)
    fig.update_layout(
        height=620,
        margin=_MARGIN_SUB,
        title=title or "Estimation error over the drive (dotted: the pass)",
    )
    return reveal_overlaps(fig)


def approach_cdfs(
    errors: Mapping[tuple[str, str], np.ndarray],
    paper_p90: Mapping[tuple[str, str], float] | None = None,
    *,
    approaches=("EKF DS", "KF DS and ToA", "EKF DS and KF ToA"),
) -> go.Figure:
    """Fig. 4 in synthetic form: CDF of the error per sigma, one panel per approach.

    ``paper_p90`` (approach, sigma) -> the paper's measured 90 % point, drawn as a cross at 0.9.
    The panels (one per approach) share their x range; a line's colour and dash name its sigma,
    the same in every panel, so the legend (one entry per sigma) reads for all three.
    """
    figure_inputs(mappings={"errors": errors, "paper_p90": paper_p90})
    approaches = sequence("approaches", approaches)
    fig = make_subplots(
        rows=1,
        cols=len(approaches),
        shared_yaxes=True,
        shared_xaxes=True,
        subplot_titles=[f"({'abc'[i]}) {a}" for i, a in enumerate(approaches)],
    )
    labels = list(dict.fromkeys(label for _, label in errors))
    palette = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#ff7f0e")
    sigma_color = {lab: palette[i % len(palette)] for i, lab in enumerate(labels)}
    paper_in_legend = False
    for col, name in enumerate(approaches, start=1):
        for (approach, label), e in errors.items():
            if approach != name:
                continue
            x, p = ecdf(e)
            step = max(1, x.size // 800)
            fig.add_scatter(
                x=x[::step],
                y=p[::step],
                mode="lines",
                name=f"ours {label}",
                legendgroup=label,
                showlegend=col == 1,
                line={"color": sigma_color[label], "dash": _SIGMA_DASH.get(label)},
                row=1,
                col=col,
            )
        for (approach, label), v in (paper_p90 or {}).items():
            if approach == name and v is not None:
                fig.add_scatter(
                    x=[v],
                    y=[0.9],
                    mode="markers",
                    marker={"symbol": "x", "size": 9, "color": "#000"},
                    name="paper p90 (measured)",
                    legendgroup="paper",
                    showlegend=not paper_in_legend,
                    hovertext=f"paper, measured: {label}",
                    row=1,
                    col=col,
                )
                paper_in_legend = True
    fig.add_hline(y=0.9, line={"dash": "dot", "color": "#999"})
    fig.update_xaxes(matches="x")
    fig.update_xaxes(title_text="error [m]")
    fig.update_yaxes(title_text="CDF", range=[0, 1.02], row=1, col=1)
    fig.update_layout(
        height=400,
        margin=_MARGIN_SUB,
        title="CDF of the position error per sigma (lines: synthetic; crosses: paper's measured p90)",
    )
    return reveal_overlaps(fig)


def pcrlb_figure(drive, bounds: Mapping[str, np.ndarray], *, title: str = "") -> go.Figure:
    """sqrt of the posterior CRLB of x (along) and y (across) over time, one line per setting."""
    instance("drive", drive, Drive)
    figure_inputs(texts={"title": title}, mappings={"bounds": bounds})
    fig = make_subplots(
        rows=1,
        cols=2,
        shared_yaxes=True,
        subplot_titles=("along the tunnel: sqrt(PCRLB_xx) [m]", "across: sqrt(PCRLB_yy) [m]"),
    )
    palette = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]
    for i, (name, P) in enumerate(bounds.items()):
        for col, k in ((1, 0), (2, 1)):
            fig.add_scatter(
                x=drive.t,
                y=np.sqrt(P[:, k, k]),
                mode="lines",
                name=name,
                legendgroup=name,
                showlegend=col == 1,
                line={"color": palette[i % len(palette)]},
                row=1,
                col=col,
            )
    for col in (1, 2):
        fig.add_vline(
            x=float(drive.t[drive.closest_index]),
            line={"dash": "dot", "color": "#000"},
            row=1,
            col=col,
        )
    fig.update_yaxes(type="log")
    fig.update_xaxes(title_text="time [s]")
    fig.update_layout(
        height=400,
        margin=_MARGIN_SUB,
        title=title or "What one transmitter can observe: posterior CRLB",
    )
    return reveal_overlaps(fig)


def information_figure(
    drive, setup, *, sigma_hz: float = 32.79, sigma_range: float = 1.0
) -> go.Figure:
    """Fisher information of one epoch on x and y (velocity known) along the drive: Doppler vs ToA."""
    instance("drive", drive, Drive)
    from ..tracking.doppler import snapshot_fim

    idx = np.arange(0, len(drive.t), 4)
    rows = {"Doppler": [], "ToA (range)": []}
    for k in idx:
        p, v = drive.position[k], drive.velocity[k]
        rows["Doppler"].append(np.diag(snapshot_fim(p, v, setup, sigma_hz=sigma_hz)))
        rows["ToA (range)"].append(np.diag(snapshot_fim(p, v, setup, sigma_range=sigma_range)))
    fig = make_subplots(
        rows=1,
        cols=2,
        shared_yaxes=True,
        subplot_titles=("information on x (along) [1/m^2]", "information on y (across) [1/m^2]"),
    )
    for name, color in (("Doppler", "#1f77b4"), ("ToA (range)", "#d62728")):
        arr = np.maximum(np.array(rows[name]), 1e-18)
        for col in (1, 2):
            fig.add_scatter(
                x=drive.t[idx],
                y=arr[:, col - 1],
                mode="lines",
                name=name,
                legendgroup=name,
                showlegend=col == 1,
                line={"color": color},
                row=1,
                col=col,
            )
    fig.update_yaxes(type="log", range=[-16, 2])
    fig.update_xaxes(title_text="time [s]")
    fig.update_layout(
        height=380,
        margin=_MARGIN_SUB,
        title=f"One epoch's Fisher information (sigma_D = {sigma_hz:g} Hz, sigma_r = {sigma_range:g} m"
        f" = {sigma_range / C * 1e9:.2f} ns)",
    )
    return fig


def regime_figure(settings, means: Mapping[str, np.ndarray], *, title: str = "") -> go.Figure:
    """Grouped bars: mean error of each approach (``means[name]``, one per setting) per setting."""
    settings = sequence("settings", settings)
    figure_inputs(texts={"title": title}, mappings={"means": means})
    fig = go.Figure()
    for name, vals in means.items():
        fig.add_bar(
            x=list(settings),
            y=np.asarray(vals),
            name=name,
            marker_color=APPROACH_COLORS.get(name.split(" (")[0]),
        )
    fig.update_layout(
        barmode="group",
        height=380,
        margin=_MARGIN,
        yaxis_title="mean error [m]",
        title=title or "Which approach wins depends on the Doppler errors",
    )
    return fig
