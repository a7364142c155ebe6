"""Figures of notebook 02 (SR-NF validity, Mmax): top view of Fig. 2, mismatch, Mmax vs range.

The ``*_traces`` functions return plain trace dicts placed on given axes, so the explorer
(:mod:`tunnelkit.widgets.mmax`) composes them into one figure cheaply; the ``*_figure`` functions
wrap the same traces into stand-alone figures for the notebook.
"""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from .. import fresnel
from .._domains import positive_array
from .._validate import finite_array, instance, integer, positive, text
from ..constants import wavelength
from ..fresnel.bounds import carrier_tolerance, wall_geometry
from .common import COLORS

__all__ = [
    "FRESNEL_COLORS",
    "derivation_figure",
    "fresnel_topview",
    "geometry_traces",
    "mismatch_figure",
    "mismatch_traces",
    "mmax_range_figure",
    "mmax_range_traces",
    "ratio_map_figure",
]

#: one colour per curve, shared by every figure of notebook 02
FRESNEL_COLORS = {
    "true": "#1f77b4",
    "sr": "#d62728",
    "exact": "#000000",
    "eq25": "#1f77b4",
    "eq37": "#ff7f0e",
    "second": "#2ca02c",
    "fraunhofer": "#7f7f7f",
    "eps": "#d62728",
    "wall": "#444444",
    "bs": COLORS["bs"],
    "ue": COLORS["truth"],
}

_MARGIN = {"l": 60, "r": 20, "t": 60, "b": 50}


def _real(name: str, value):
    """Real numbers (NaN allowed), text and complex refused."""
    a = np.asarray(value) if not isinstance(value, str | bytes) else None
    if a is None or a.dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected real numbers, got {type(value).__name__}")
    return a


def _point(R, W, y_u, fc, eps_phi=1.0, z_u=0.0, **axes) -> tuple[float, ...]:
    """The design point (R, W, y_u, fc, eps_phi, z_u) as floats, validated with the theorem's
    rules (errors name the parameter); ``axes`` (xaxis, yaxis, legend) checked as names."""
    for k, v in axes.items():
        text(k, v)
    R, W, y_u, z_u = (float(v) for v in wall_geometry(R, W, y_u, z_u))
    fc, eps_phi = (float(v) for v in carrier_tolerance(fc, eps_phi))
    return R, W, y_u, fc, eps_phi, z_u


def _polyline(points: list[np.ndarray]) -> tuple[list, list]:
    """Segments joined with ``None`` breaks: [[p0, p1], [q0, q1, q2], ...] -> x, y lists."""
    xs: list = []
    ys: list = []
    for seg in points:
        xs += [*seg[:, 0].tolist(), None]
        ys += [*seg[:, 1].tolist(), None]
    return xs, ys


def geometry_traces(
    M: int,
    R: float,
    W: float,
    y_u: float,
    fc: float,
    *,
    xaxis: str = "x",
    yaxis: str = "y",
    legend: str = "legend",
) -> list[dict]:
    """Top view of Fig. 2: wall, ULA, UE, VUE, true paths (solid), VUE paths (dashed) and the
    SR-NF paths (dotted red) for the first and the last antenna. Eight traces, fixed order:
    wall, BS array, UE, VUE, true paths, VUE paths, SR-NF paths, reflector p0."""
    M = integer("M", M, minimum=2, maximum=100_000)
    R, W, y_u, fc, _, _ = _point(R, W, y_u, fc, xaxis=xaxis, yaxis=yaxis, legend=legend)
    y = np.arange(M) * wavelength(fc) / 2.0
    a = 2.0 * W - y_u
    ue, pv = np.array([R, y_u]), np.array([R, a])
    ps0 = np.array([R * W / a, W])  # eq. 32
    edge = [m for m in sorted({0, M - 1}) if y[m] < W]  # an antenna beyond the wall has no path
    true, virt, sr = [], [], []
    for m in edge:
        pm = np.array([0.0, y[m]])
        t = (W - y[m]) / (a - y[m])
        sm = pm + t * (pv - pm)  # specular point of antenna m
        true.append(np.stack([ue, sm, pm]))
        virt.append(np.stack([sm, pv]))
        sr.append(np.stack([ue, ps0, pm]))
    ax = {"xaxis": xaxis, "yaxis": yaxis, "legend": legend}
    x_hi = 1.08 * R
    tx, ty = _polyline(true)
    vx, vy = _polyline(virt)
    sx, sy = _polyline(sr)
    c = FRESNEL_COLORS
    return [
        {
            "type": "scatter",
            "name": "wall y = W",
            "x": [-0.05 * R, x_hi],
            "y": [W, W],
            "mode": "lines",
            "line": {"color": c["wall"], "width": 4},
            **ax,
        },
        {
            "type": "scatter",
            "name": f"BS array ({M} antennas)",
            "x": np.zeros(M),
            "y": y,
            "mode": "markers",
            "marker": {"symbol": "square", "size": 5, "color": c["bs"]},
            **ax,
        },
        {
            "type": "scatter",
            "name": "UE",
            "x": [R],
            "y": [y_u],
            "mode": "markers+text",
            "text": ["UE"],
            "textposition": "bottom left",  # inside the x range, which ends just past R
            "cliponaxis": False,
            "marker": {"size": 11, "color": c["ue"]},
            **ax,
        },
        {
            "type": "scatter",
            "name": "VUE (2W - y_u)",
            "x": [R],
            "y": [a],
            "mode": "markers+text",
            "text": ["VUE"],
            "textposition": "top left",
            "cliponaxis": False,
            "marker": {"size": 11, "color": c["ue"], "symbol": "circle-open", "line": {"width": 2}},
            **ax,
        },
        {
            "type": "scatter",
            "name": "true paths",
            "x": tx,
            "y": ty,
            "mode": "lines",
            "line": {"color": c["true"], "width": 2},
            **ax,
        },
        {
            "type": "scatter",
            "name": "paths from the VUE",
            "x": vx,
            "y": vy,
            "mode": "lines",
            "line": {"color": c["true"], "width": 1.5, "dash": "dash"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "SR-NF model paths",
            "x": sx,
            "y": sy,
            "mode": "lines",
            "line": {"color": c["sr"], "width": 2, "dash": "dot"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "reflector p0 (eq. 32)",
            "x": [ps0[0]],
            "y": [ps0[1]],
            "mode": "markers",
            "marker": {"symbol": "x", "size": 10, "color": c["sr"]},
            **ax,
        },
    ]


def mismatch_traces(
    M: int,
    R: float,
    W: float,
    y_u: float,
    fc: float,
    eps_phi: float,
    *,
    z_u: float = 0.0,
    xaxis: str = "x",
    yaxis: str = "y",
    legend: str = "legend",
) -> list[dict]:
    """|phase mismatch| [rad] across the ULA: exact (with ``z_u``), eq. 33, corrected second order,
    and the tolerance ``eps_phi``. Four traces, fixed order."""
    R, W, y_u, fc, eps_phi, z_u = _point(
        R, W, y_u, fc, eps_phi, z_u, xaxis=xaxis, yaxis=yaxis, legend=legend
    )
    prof = fresnel.aperture_profile(M, R, W, y_u, fc)
    exact = fresnel.mismatch_profile(
        np.column_stack([np.zeros(M), prof.y, np.zeros(M)]), R, W, y_u, fc, z_u=z_u
    )
    if z_u != 0.0:  # the second-order term with the UE off the array plane
        rho = np.sqrt(R**2 + (2 * W - y_u) ** 2 + z_u**2)
        second = (
            (2 * np.pi / wavelength(fc))
            * (W - y_u)
            / (2 * rho * W)
            * prof.y**2
            * (R**2 + z_u**2)
            / rho**2
        )
    else:
        second = prof.mismatch_second_order
    ax = {"xaxis": xaxis, "yaxis": yaxis, "legend": legend}
    c = FRESNEL_COLORS
    y_cm = prof.y * 100.0
    return [
        {
            "type": "scatter",
            "name": "exact",
            "x": y_cm,
            "y": np.abs(exact),
            "mode": "lines+markers",
            "marker": {"size": 4},
            "line": {"color": c["exact"], "width": 2},
            **ax,
        },
        {
            "type": "scatter",
            "name": "eq. 33 (paraxial)",
            "x": y_cm,
            "y": np.abs(prof.mismatch_paraxial),
            "mode": "lines",
            "line": {"color": c["eq25"], "dash": "dash"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "2nd order, non-paraxial",
            "x": y_cm,
            "y": np.abs(second),
            "mode": "lines",
            "line": {"color": c["second"], "dash": "dot"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "ε_Φ",
            "x": [y_cm[0], y_cm[-1]],
            "y": [eps_phi, eps_phi],
            "mode": "lines",
            "line": {"color": c["eps"], "width": 1, "dash": "longdash"},
            **ax,
        },
    ]


def mmax_range_traces(
    R: float,
    W: float,
    y_u: float,
    fc: float,
    eps_phi: float,
    M: int,
    *,
    z_u: float = 0.0,
    R_grid=None,
    exact_here: int | None = None,
    xaxis: str = "x",
    yaxis: str = "y",
    legend: str = "legend",
) -> list[dict]:
    """Mmax vs R (log-log): exact ULA, eq. 25, eq. 37, corrected second order, the Fraunhofer
    ``1 + sqrt(2R/lambda)`` law (the ``sqrt(R/lambda)`` scaling), the chosen M and the design
    point. Seven traces, fixed order."""
    R, W, y_u, fc, eps_phi, z_u = _point(
        R, W, y_u, fc, eps_phi, z_u, xaxis=xaxis, yaxis=yaxis, legend=legend
    )
    M = integer("M", M, minimum=1)
    Rg = (
        np.geomspace(0.5, 500.0, 61) if R_grid is None else positive_array("R_grid", R_grid, ndim=1)
    )
    if exact_here is not None:
        exact_here = integer("exact_here", exact_here, minimum=1)
    a = 2.0 * W - y_u
    exact = fresnel.mmax_exact_grid(Rg, W, y_u, fc, eps_phi, z_u=z_u)
    eq25 = fresnel.mmax_2d(Rg, W, y_u, fc, eps_phi)
    eq37 = fresnel.mmax_3d(
        np.column_stack([Rg, np.full_like(Rg, a), np.full_like(Rg, z_u)]), fc, eps_phi
    )
    second = fresnel.mmax_nonparaxial(Rg, W, y_u, fc, eps_phi, z_u=z_u)
    fraun = fresnel.mmax_fraunhofer(Rg, fc)
    if exact_here is None:
        exact_here = fresnel.mmax_exact(R, W, y_u, fc, eps_phi, z_u=z_u)
    ok = M <= exact_here
    ax = {"xaxis": xaxis, "yaxis": yaxis, "legend": legend}
    c = FRESNEL_COLORS
    return [
        {
            "type": "scatter",
            "name": "exact (ULA)",
            "x": Rg,
            "y": np.maximum(exact, 1),
            "mode": "lines",
            "line": {"color": c["exact"], "width": 2.5, "shape": "hv"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "eq. 25",
            "x": Rg,
            "y": eq25,
            "mode": "lines",
            "line": {"color": c["eq25"], "dash": "dash"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "eq. 37",
            "x": Rg,
            "y": eq37,
            "mode": "lines",
            "line": {"color": c["eq37"], "dash": "dashdot"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "2nd order, non-paraxial",
            "x": Rg,
            "y": second,
            "mode": "lines",
            "line": {"color": c["second"], "dash": "dot"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "1 + √(2R/λ) (Fraunhofer)",
            "x": Rg,
            "y": fraun,
            "mode": "lines",
            "line": {"color": c["fraunhofer"], "width": 1},
            **ax,
        },
        {
            "type": "scatter",
            "name": f"M = {M}",
            "x": [Rg[0], Rg[-1]],
            "y": [M, M],
            "mode": "lines",
            "line": {"color": c["eps"], "width": 1, "dash": "longdash"},
            **ax,
        },
        {
            "type": "scatter",
            "name": "this design",
            "x": [R],
            "y": [M],
            "mode": "markers",
            "marker": {
                "size": 12,
                "symbol": "star",
                "color": "#2ca02c" if ok else "#d62728",
                "line": {"width": 1, "color": "black"},
            },
            **ax,
        },
    ]


def _figure(
    traces: list[dict],
    title: str,
    xtitle: str,
    ytitle: str,
    *,
    height: int = 380,
    log: bool = False,
) -> go.Figure:
    layout = {
        "title": {"text": title},
        "height": height,
        "margin": _MARGIN,
        "xaxis": {"title": {"text": xtitle}},
        "yaxis": {"title": {"text": ytitle}},
    }
    if log:
        layout["xaxis"]["type"] = layout["yaxis"]["type"] = "log"
    return go.Figure({"data": traces, "layout": layout})


def fresnel_topview(M: int, R: float, W: float, y_u: float, fc: float) -> go.Figure:
    """Fig. 2 of the paper for one geometry (stand-alone figure)."""
    return _figure(
        geometry_traces(M, R, W, y_u, fc),
        f"Top view: R = {R:g} m, W = {W:g} m, y_u = {y_u:g} m, M = {M}",
        "x along the tunnel [m]",
        "y across [m]",
    )


def mismatch_figure(
    M: int, R: float, W: float, y_u: float, fc: float, eps_phi: float, *, z_u: float = 0.0
) -> go.Figure:
    """|Phase mismatch| across an ``M``-element ULA: exact vs eq. 33 vs corrected 2nd order."""
    return _figure(
        mismatch_traces(M, R, W, y_u, fc, eps_phi, z_u=z_u),
        f"Phase mismatch across the aperture (M = {M}, fc = {fc / 1e9:g} GHz)",
        "antenna position y_m [cm]",
        "|Δφ_m| [rad]",
    )


def mmax_range_figure(
    R: float,
    W: float,
    y_u: float,
    fc: float,
    eps_phi: float,
    M: int,
    *,
    z_u: float = 0.0,
    R_grid=None,
) -> go.Figure:
    """Mmax vs R on log-log axes (exact, eq. 25, eq. 37, 2nd order, Fraunhofer law)."""
    return _figure(
        mmax_range_traces(R, W, y_u, fc, eps_phi, M, z_u=z_u, R_grid=R_grid),
        f"Mmax vs R (W = {W:g} m, y_u = {y_u:g} m, fc = {fc / 1e9:g} GHz, ε = {eps_phi:g} rad)",
        "R [m]",
        "Mmax",
        log=True,
    )


def derivation_figure(profile: fresnel.ApertureProfile, *, lam: float) -> go.Figure:
    """Error of each approximation of the proof (eq. 28, 31, 33) in phase [rad] across the ULA."""
    instance("profile", profile, fresnel.ApertureProfile)
    lam = positive("lam", lam)
    k = 2 * np.pi / lam
    y_cm = profile.y * 100
    series = {
        "eq. 28 − exact δ*": k * (profile.delta_star_fresnel - profile.delta_star),
        "eq. 31 − exact δ^SR": k * (profile.delta_sr_fresnel - profile.delta_sr),
        "eq. 33 − exact Δ": profile.mismatch_paraxial - profile.mismatch,
        "exact Δ (for scale)": profile.mismatch,
    }
    dash = [None, None, "dash", "dot"]
    traces = [
        {"type": "scatter", "name": n, "x": y_cm, "y": v, "mode": "lines", "line": {"dash": d}}
        for (n, v), d in zip(series.items(), dash)
    ]
    return _figure(
        traces,
        "Phase error of each approximation in the proof of Theorem 3.1",
        "antenna position y_m [cm]",
        "phase error [rad]",
    )


def ratio_map_figure(
    R_grid,
    y_grid,
    ratio,
    *,
    title: str = "eq. 25 / exact Mmax",
    W: float | None = None,
    colorbar_title: str | None = None,
) -> go.Figure:
    """Heat map of a ratio (e.g. bound / exact Mmax) over (R, y_u), 1 = tight, log colour scale."""
    R_grid = positive_array("R_grid", R_grid, ndim=1)
    y_grid = finite_array("y_grid", y_grid, ndim=1)
    # NaN: no ratio there (e.g. a capped exact search), shown blank
    r = np.asarray(_real("ratio", ratio), dtype=float)
    if r.shape != (len(y_grid), len(R_grid)):
        raise ValueError(f"ratio: expected shape ({len(y_grid)}, {len(R_grid)}), got {r.shape}")
    if np.any(r <= 0) or np.any(np.isinf(r)):
        raise ValueError("ratio: must be > 0 and finite (NaN for no value)")
    title = text("title", title)
    if W is not None:
        W = positive("W", W)
    if colorbar_title is not None:
        colorbar_title = text("colorbar_title", colorbar_title)
    # the colour bar names the ratio it shows (the title's, unless told), not just "ratio"
    colorbar_title = title if colorbar_title is None else colorbar_title
    ticks = np.array([0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0])
    fig = go.Figure(
        go.Heatmap(
            x=np.asarray(R_grid),
            y=np.asarray(y_grid),
            z=np.log2(r),
            zmid=0,
            colorscale="RdBu",
            customdata=r,
            colorbar={
                "title": {"text": colorbar_title, "side": "right"},
                "tickvals": np.log2(ticks),
                "ticktext": [f"{t:g}" for t in ticks],
            },
            hovertemplate="R %{x:.2f} m<br>y_u %{y:.2f} m<br>ratio %{customdata:.3f}<extra></extra>",
        )
    )
    fig.update_layout(
        title=title,
        height=420,
        margin=_MARGIN,
        xaxis_title="R [m]",
        yaxis_title="y_u [m]" + (f" (wall at W = {W:g} m)" if W else ""),
        xaxis_type="log",
    )
    return fig
