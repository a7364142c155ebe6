"""Shared plotting helpers: colours per algorithm, line plots, empirical CDFs."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import plotly.graph_objects as go

from .._validate import boolean, finite_array, instance, text
from ..metrics import ecdf

__all__ = ["COLORS", "cdf_figure", "line_figure", "reveal_overlaps"]

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


_DASHES = ("dash", "dot", "dashdot", "longdash")


def _close(u, v) -> bool:
    """Whether two coordinate arrays draw the same points (within 0.3 % of their span)."""
    if u is None or v is None:
        return u is None and v is None
    try:
        u, v = np.asarray(u, float), np.asarray(v, float)
    except (TypeError, ValueError):
        return False
    if u.shape != v.shape:
        return False
    both = np.concatenate([u.ravel(), v.ravel()])
    both = both[np.isfinite(both)]
    span = float(np.ptp(both)) if both.size else 0.0
    return bool(np.allclose(u, v, rtol=0, atol=3e-3 * span + 1e-300, equal_nan=True))


def figure_inputs(*, texts: Mapping | None = None, mappings: Mapping | None = None) -> None:
    """The checks at the top of a figure function, by parameter name: ``texts`` titles and labels
    (text; empty shows none; ``None`` the default), ``mappings`` name -> series tables (a dict;
    ``None`` for none). Errors name the parameter."""
    for name, value in (texts or {}).items():
        if value is not None:
            text(name, value, empty=True)
    for name, value in (mappings or {}).items():
        if value is not None:
            instance(name, value, Mapping, "a mapping (a dict)")


def reveal_overlaps(fig: go.Figure) -> go.Figure:
    """Keep every line visible where two coincide: a line drawn over an earlier one with the same
    points (EKF and UKF on a nearly linear problem) is dashed, and the earlier one widened, so
    both can be seen and told apart. Returns ``fig``, changed in place."""
    if not isinstance(fig, go.Figure):
        raise TypeError(f"fig: expected a plotly Figure, got {type(fig).__name__}")
    lines = [t for t in fig.data if "lines" in (getattr(t, "mode", None) or "lines")]
    for j, late in enumerate(lines):
        n_under = 0
        for early in lines[:j]:
            same_axes = (getattr(early, "xaxis", None), getattr(early, "yaxis", None)) == (
                getattr(late, "xaxis", None),
                getattr(late, "yaxis", None),
            )
            if same_axes and _close(early.x, late.x) and _close(early.y, late.y):
                if (late.line.dash or "solid") == (early.line.dash or "solid"):
                    late.line.dash = _DASHES[n_under % len(_DASHES)]
                early.line.width = max(early.line.width or 2, (late.line.width or 2) + 2)
                n_under += 1
    return fig


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
    if not isinstance(series, Mapping):
        raise TypeError(f"series: expected a mapping name -> values, got {type(series).__name__}")
    if dash is not None and not isinstance(dash, Mapping):
        raise TypeError(f"dash: expected a mapping name -> dash style, got {type(dash).__name__}")
    x = finite_array("x", np.atleast_1d(x), ndim=1)
    title, xaxis, yaxis = (
        text(k, v, empty=True) for k, v in (("title", title), ("xaxis", xaxis), ("yaxis", yaxis))
    )
    log_y = boolean("log_y", log_y)
    n = len(x)
    for name, y in series.items():
        if len(np.atleast_1d(np.asarray(y))) != n:
            raise ValueError(f"series: {name!r} has {len(np.atleast_1d(y))} values, x has {n}")
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
    return reveal_overlaps(fig)


def cdf_figure(
    errors: Mapping[str, np.ndarray], *, title: str = "", xaxis: str = "error [m]"
) -> go.Figure:
    """Empirical CDFs of error samples, one line each."""
    if not isinstance(errors, Mapping):
        raise TypeError(f"errors: expected a mapping name -> samples, got {type(errors).__name__}")
    title, xaxis = text("title", title, empty=True), text("xaxis", xaxis, empty=True)
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
    return reveal_overlaps(fig)
