"""Notebook 08 figures: the position error bound along the route with the SR-NF overlay, the
PEB / SR-NF share against array size, and the answer of a design sweep (the tracker's error along
the route beside its bound and prediction, the unit yield per array).

Builders are pure (data -> figure) and take the results of :mod:`tunnelkit.design`.
"""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .._checks import attributes
from .._validate import instance, positive, sequence, text
from .common import COLORS, figure_inputs

__all__ = ["design_answer_figure", "route_figure", "route_traces", "size_figure"]

_KIND_COLORS = {
    "wall": "#1f77b4",
    "ceiling": "#d62728",
    "road": "#8c564b",
    "rrm": "#2ca02c",
}


#: colours of the predicted-error lines, one per impairment level
_ACHIEVABLE_COLORS = ("#ff7f0e", "#9467bd", "#17becf", "#e377c2")


def _finite(v: np.ndarray) -> list:
    """Plotly-friendly list: non-finite values become gaps (None)."""
    return [float(x) if np.isfinite(x) else None for x in np.asarray(v, float)]


def _scatter(**kw) -> dict:
    """A scatter trace as a plain dict (validated once, by the figure that receives it)."""
    return {"type": "scatter", **kw}


def route_traces(
    bounds,
    *,
    variants: dict | None = None,
    target: float | None = None,
    predicted: dict | None = None,
) -> list:
    """Trace dicts on axes (x, y) PEB [cm] along the tunnel and (x, y2) SR-NF mismatch per surface.

    Order: 0 PEB, 1 SR-NF not valid (markers on the PEB), 2.. one dashed trace per variant
    (``{"no curvature": RouteBounds, ...}``), then one solid trace per predicted error (a prediction, not a bound)
    (``{"0.5° phase error": design.PredictedError, ...}``), then the target line (if given), then
    one mismatch trace per surface kind and the ``eps_phi`` line on (x, y2).
    """
    attributes("bounds", bounds, ("x", "peb", "srnf_valid", "spec"), "a design.RouteBounds")
    figure_inputs(mappings={"variants": variants, "predicted": predicted})
    if target is not None:
        positive("target", target)
    x = bounds.x
    peb_cm = 100 * bounds.peb
    bad = ~bounds.srnf_valid
    traces = [
        _scatter(
            x=x,
            y=_finite(peb_cm),
            mode="lines+markers",
            name=f"PEB {bounds.spec.label}",
            line={"color": COLORS.get("ours", "#1f77b4"), "width": 2.5},
            marker={"size": 5},
        ),
        _scatter(
            x=x[bad],
            y=_finite(peb_cm[bad]),
            mode="markers",
            name="SR-NF not valid",
            marker={"symbol": "x", "size": 10, "color": "#d62728"},
        ),
    ]
    for i, (name, b) in enumerate((variants or {}).items()):
        traces.append(
            _scatter(
                x=b.x,
                y=_finite(100 * b.peb),
                mode="lines",
                name=f"PEB, {name}",
                line={"dash": ["dash", "dot", "dashdot"][i % 3], "width": 1.5},
            )
        )
    for i, (name, a) in enumerate((predicted or {}).items()):
        traces.append(
            _scatter(
                x=a.x,
                y=_finite(100 * a.predicted),
                mode="lines",
                name=f"predicted, {name}",
                line={"color": _ACHIEVABLE_COLORS[i % len(_ACHIEVABLE_COLORS)], "width": 2},
            )
        )
    if target is not None:
        traces.append(
            _scatter(
                x=[float(x.min()), float(x.max())],
                y=[100 * target, 100 * target],
                mode="lines",
                name="target",
                line={"color": "black", "dash": "dot", "width": 1},
            )
        )
    kinds = np.array(bounds.kinds)
    for k in dict.fromkeys(bounds.kinds[1:]):
        cols = kinds == k
        used = bounds.used[:, cols]
        if not used.any():
            continue
        mis = np.where(used, bounds.mismatch[:, cols], np.nan)
        with np.errstate(all="ignore"):
            worst = np.where(
                used.any(axis=1), np.nanmax(np.where(used, mis, -np.inf), axis=1), np.nan
            )
        traces.append(
            _scatter(
                x=x,
                y=_finite(worst),
                mode="lines+markers",
                name=f"mismatch, {k}",
                line={"color": _KIND_COLORS.get(k), "width": 1.5},
                marker={"size": 4},
                xaxis="x",
                yaxis="y2",
            )
        )
    traces.append(
        _scatter(
            x=[float(x.min()), float(x.max())],
            y=[bounds.eps_phi, bounds.eps_phi],
            mode="lines",
            name="ε_Φ",
            line={"color": "black", "dash": "dash", "width": 1},
            xaxis="x",
            yaxis="y2",
        )
    )
    return traces


def route_figure(
    bounds,
    *,
    variants: dict | None = None,
    target: float | None = None,
    predicted: dict | None = None,
    title: str = "",
    subtitle: str = "",
    meta: dict | None = None,
) -> go.Figure:
    """PEB along the tunnel (top, log) with SR-NF failures marked and the predicted error under
    impairments beside it; per-surface mismatch (bottom).

    ``layout.meta`` carries ``meta`` (for tests and lecture scripts).
    """
    figure_inputs(texts={"title": title, "subtitle": subtitle}, mappings={"meta": meta})
    layout = {
        "title": {"text": title, "subtitle": {"text": subtitle}, "x": 0.01, "xanchor": "left"},
        "height": 620,
        "autosize": True,
        "margin": {"l": 70, "r": 20, "t": 90, "b": 50},
        "xaxis": {"anchor": "y2", "title": {"text": "vehicle position x along the tunnel [m]"}},
        "yaxis": {
            "domain": [0.42, 1.0],
            "type": "log",
            "title": {"text": "position bound [cm]"},
        },
        "yaxis2": {
            "domain": [0.0, 0.34],
            "type": "log",
            "title": {"text": "SR-NF mismatch [rad]"},
        },
        "legend": {
            "font": {"size": 10},
            "bgcolor": "rgba(255,255,255,0.7)",
            "x": 0.99,
            "xanchor": "right",
            "y": 0.99,
            "yanchor": "top",
        },
        "meta": meta or {},
    }
    return go.Figure(
        {
            "data": route_traces(bounds, variants=variants, target=target, predicted=predicted),
            "layout": layout,
        }
    )


def size_figure(rows, *, mark: str | None = "10x10", title: str = "") -> go.Figure:
    """The snapshot PEB (median, 90th percentile over the route) and the SR-NF valid share
    against the number of elements; with Monte-Carlo rows, the tracker's RMSE (with its 95 %
    interval) and its bound, every unit's posterior CRLB over the drive (``pcrlb_rms_m``).

    The PEB bounds one epoch's unbiased fix, not the tracker (which fuses epochs and may go below
    it), and its percentile over the route bounds no error percentile: its traces are labelled
    a reference. Only the PCRLB is a bound of the RMSE beside it.

    ``rows``: :class:`tunnelkit.design.DesignRow` list (one sweep). ``mark`` highlights one
    array label (the paper's 10 x 10) when present.
    """
    rows = sequence("rows", rows)
    for i, r in enumerate(rows):
        attributes(f"rows[{i}]", r, ("array", "n_elements", "peb_median_m"), "a design.DesignRow")
    if mark is not None:
        text("mark", mark)
    figure_inputs(texts={"title": title})
    n = np.array([r.n_elements for r in rows])
    labels = [r.array for r in rows]
    med = 100 * np.array([r.peb_median_m for r in rows])
    p90 = 100 * np.array([r.peb_p90_m for r in rows])
    share = 100 * np.array([r.srnf_valid_share for r in rows])
    traces = [
        go.Scatter(
            x=n, y=_finite(med), mode="lines+markers", name="PEB median (a reference)", text=labels
        ),
        go.Scatter(
            x=n,
            y=_finite(p90),
            mode="lines+markers",
            name="PEB 90th pct (a reference)",
            line={"dash": "dash"},
        ),
        go.Scatter(
            x=n,
            y=share,
            mode="lines+markers",
            name="SR-NF valid share",
            yaxis="y2",
            line={"color": "#d62728"},
        ),
    ]
    rm = [r.rmse_m for r in rows]
    if any(v is not None for v in rm):
        lo = [r.rmse_ci95_m[0] if r.rmse_ci95_m else None for r in rows]
        hi = [r.rmse_ci95_m[1] if r.rmse_ci95_m else None for r in rows]
        y = [100 * v if v is not None else None for v in rm]
        traces.append(
            go.Scatter(
                x=n,
                y=y,
                mode="markers",
                name="tracker RMSE (95 % CI)",
                marker={"symbol": "diamond", "size": 9, "color": "black"},
                error_y={
                    "type": "data",
                    "symmetric": False,
                    "array": [100 * (h - v) if v is not None else None for v, h in zip(rm, hi)],
                    "arrayminus": [
                        100 * (v - lo_) if v is not None else None for v, lo_ in zip(rm, lo)
                    ],
                },
            )
        )
        pc = [r.pcrlb_rms_m for r in rows]
        traces.append(
            go.Scatter(
                x=n,
                y=[100 * v if v is not None else None for v in pc],
                mode="markers",
                name="PCRLB (bound of the RMSE)",
                marker={"symbol": "triangle-up", "size": 9, "color": "grey"},
            )
        )
    shapes = []
    if mark in labels:
        x0 = n[labels.index(mark)]
        shapes.append(
            {
                "type": "line",
                "x0": x0,
                "x1": x0,
                "y0": 0,
                "y1": 1,
                "yref": "paper",
                "line": {"color": "grey", "dash": "dot"},
            }
        )
    layout = {
        "title": {"text": title, "x": 0.01, "xanchor": "left"},
        "height": 460,
        "autosize": True,
        "margin": {"l": 70, "r": 80, "t": 60, "b": 50},
        "xaxis": {"type": "log", "title": {"text": "number of elements M"}},
        "yaxis": {"type": "log", "title": {"text": "position error, bound [cm]"}},
        "yaxis2": {
            "overlaying": "y",
            "side": "right",
            "range": [0, 105],
            "title": {"text": "SR-NF valid share [%]"},
        },
        "legend": {"x": 0.02, "y": 0.02, "bgcolor": "rgba(255,255,255,0.7)"},
        "shapes": shapes,
        "annotations": (
            [
                {
                    "x": float(np.log10(n[labels.index(mark)])),
                    "y": 1.0,
                    "yref": "paper",
                    "text": f"paper's {mark}",
                    "showarrow": False,
                    "yanchor": "bottom",
                }
            ]
            if mark in labels
            else []
        ),
    }
    return go.Figure({"data": traces, "layout": layout})


#: one colour per candidate array of :func:`design_answer_figure`, in the report's order
_ARRAY_COLORS = (
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf",
)  # fmt: skip


def _pct(v) -> str:
    return "-" if v is None else f"{100 * v:.0f} %"


def _cm_text(v) -> str:
    return "-" if v is None else (f"{100 * v:.3g} cm" if np.isfinite(v) else "inf")


def design_answer_figure(report) -> go.Figure:
    """The answer of a design sweep (:func:`tunnelkit.design.design_sweep`, ``tunnelkit design``).

    Top, per array along the route (log, cm): the tracker's median 2-D error per epoch over the
    Monte-Carlo drives (solid; its legend entry states the pooled ``share``-quantile over the
    settled route with its 95 % interval, Woodruff's over units), the ideal snapshot PEB (dotted, a lower
    bound of one epoch's fix, which the tracker, fusing epochs, may go below: a reference, not
    the tracker's bound) and the first-order predicted error under the impairments (dashed, a
    prediction, not a bound), and the target. Rows without Monte-Carlo (``--units 0``) show the PEB and the
    prediction only. Bottom: the unit yield per array (the share of manufactured units that meet
    the target on their own) with its Wilson 95 % interval, and the required yield; the verdict
    is in the hover.

    ``layout.meta``: ``{"arrays", "unit_yield" (None without Monte-Carlo), "required_yield",
    "target"}``.
    """
    from ..design.records import DesignReport  # the records, loaded on first use

    instance("report", report, DesignReport, "a tunnelkit.design.DesignReport")
    s = report.settings
    target = float(s["target"])
    share = float(s.get("share", 0.9))
    required = float(s["required_yield"])
    q = f"p{100 * share:g}"
    fig = make_subplots(
        rows=2,
        cols=1,
        row_heights=[0.64, 0.36],
        vertical_spacing=0.14,
        subplot_titles=(
            "error along the route: tracker (median over drives), snapshot PEB, prediction",
            "unit yield: share of units meeting the target on their own (Wilson 95 % interval)",
        ),
    )
    xs = [r.x_m for r in report.rows if r.x_m is not None and np.size(r.x_m)]
    for i, r in enumerate(report.rows):
        if r.x_m is None:
            continue
        color = _ARRAY_COLORS[i % len(_ARRAY_COLORS)]
        x = np.asarray(r.x_m, float)
        group = {"legendgroup": r.array, "legendgrouptitle": {"text": r.array}}
        hover = (
            f"{r.array} ({r.status})<br>x %{{x:.1f}} m: %{{y:.3g}} cm"
            "<extra>%{fullData.name}</extra>"
        )
        if r.error_median_epoch_m is not None:
            med = np.asarray(r.error_median_epoch_m, float)
            ci = r.error_p90_ci95_m
            pooled = f"{q} {_cm_text(r.error_p90_m)}" + (
                f" [{_cm_text(ci[0])}, {_cm_text(ci[1])}]" if ci else ""
            )
            fig.add_scatter(
                x=x[: med.size],
                y=_finite(100 * med),
                mode="lines",
                name=f"{r.array} tracker median ({pooled})",
                line={"color": color, "width": 2.5},
                hovertemplate=(
                    f"{r.array} ({r.status}): median over {r.runs} drives<br>"
                    "x %{x:.1f} m: %{y:.3g} cm<br>"
                    f"pooled {pooled} (settled route, 95 % CI)<br>"
                    f"RMSE {_cm_text(r.rmse_m)}; PCRLB {_cm_text(r.pcrlb_rms_m)}, hybrid bound "
                    f"{_cm_text(r.hybrid_bound_rms_m)} (lower bounds of the RMSE of trackers "
                    "unbiased for the route)<extra></extra>"
                ),
                **group,
                row=1,
                col=1,
            )
        for name, y, dash in (
            (f"{r.array} PEB (one epoch's bound, a reference)", r.peb_m, "dot"),
            (f"{r.array} predicted (not a bound)", r.predicted_m, "dash"),
        ):
            if y is not None:
                fig.add_scatter(
                    x=x,
                    y=_finite(100 * np.asarray(y, float)),
                    mode="lines",
                    name=name,
                    line={"color": color, "width": 1.5, "dash": dash},
                    hovertemplate=hover,
                    **group,
                    row=1,
                    col=1,
                )
    if xs:
        x0 = float(min(np.nanmin(v) for v in xs))
        x1 = float(max(np.nanmax(v) for v in xs))
        fig.add_scatter(
            x=[x0, x1],
            y=[100 * target, 100 * target],
            mode="lines",
            name=f"target {_cm_text(target)}",
            line={"color": "black", "width": 1.5, "dash": "longdashdot"},
            hoverinfo="name",
            legendgroup="targets",
            row=1,
            col=1,
        )
    labels = [r.array for r in report.rows]
    yields = [None if r.unit_yield is None else float(r.unit_yield) for r in report.rows]
    up, down, hovers = [], [], []
    for r, y in zip(report.rows, yields):
        ci = r.unit_yield_ci95
        up.append(None if y is None or not ci else 100 * (ci[1] - y))
        down.append(None if y is None or not ci else 100 * (y - ci[0]))
        ci_text = f" [{_pct(ci[0])}, {_pct(ci[1])}]" if ci else ""
        hovers.append(
            f"{r.array}: {r.status}<br>unit yield {_pct(y)}{ci_text}<br>"
            f"{r.units} units x {r.drives_per_unit} drives"
            + (f"<br>{r.reason}" if r.reason else "")
        )
    fig.add_scatter(
        x=labels,
        y=[None if y is None else 100 * y for y in yields],
        mode="markers",
        name="unit yield (95 % interval)",
        marker={
            "size": 11,
            "symbol": "diamond",
            "color": [_ARRAY_COLORS[i % len(_ARRAY_COLORS)] for i in range(len(labels))],
        },
        error_y={"type": "data", "symmetric": False, "array": up, "arrayminus": down},
        text=hovers,
        hovertemplate="%{text}<extra></extra>",
        legendgroup="yield",
        row=2,
        col=1,
    )
    fig.add_hline(
        y=100 * required,
        line={"color": "black", "width": 1.5, "dash": "longdashdot"},
        name=f"required yield {_pct(required)}",
        showlegend=True,
        legendgroup="targets",
        row=2,
        col=1,
    )
    if all(y is None for y in yields):
        fig.add_annotation(
            text="no Monte-Carlo (units 0): no unit yield, bounds and predictions only",
            x=0.5,
            y=50,
            xref="x2 domain",
            yref="y2",
            showarrow=False,
        )
    fig.update_yaxes(type="log", title_text="position error [cm]", row=1, col=1)
    fig.update_yaxes(range=[-3, 103], title_text="unit yield [%]", row=2, col=1)
    fig.update_xaxes(title_text="vehicle position x along the tunnel [m]", row=1, col=1)
    fig.update_xaxes(type="category", title_text="array", row=2, col=1)
    title = (
        f"{report.scenario}: {_cm_text(target)} on {100 * share:g} % of the route, "
        f"yield {_pct(required)}"
    )
    fig.update_layout(
        title={
            "text": title,
            "subtitle": {
                "text": "solid: tracker's median; dotted: PEB (one epoch's bound, not the "
                "tracker's); dashed: prediction (not a bound)"
            },
            "x": 0.01,
            "xanchor": "left",
        },
        height=760,
        autosize=True,
        margin={"l": 70, "r": 20, "t": 110, "b": 50},
        legend={"font": {"size": 10}, "groupclick": "toggleitem"},
        meta={
            "arrays": labels,
            "unit_yield": yields,
            "required_yield": required,
            "target": target,
        },
    )
    return fig
