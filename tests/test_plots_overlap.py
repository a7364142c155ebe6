"""Figures keep every line visible and every colour named (tools/figcheck.py finds the defects)."""

import importlib.util
from pathlib import Path

import numpy as np
import plotly.graph_objects as go
import pytest

from tunnelkit.plots import cdf_figure, factors_figure, wave_origins_figure
from tunnelkit.plots.common import line_figure, reveal_overlaps
from tunnelkit.plots.doppler import approach_cdfs

_spec = importlib.util.spec_from_file_location(
    "figcheck", Path(__file__).resolve().parents[1] / "tools" / "figcheck.py"
)
figcheck = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(figcheck)


def _json(fig):
    return fig.to_plotly_json()


def test_the_checker_finds_each_defect_class():
    t = np.linspace(0, 1, 50)
    hidden = go.Figure([go.Scatter(x=t, y=t**2, name="EKF"), go.Scatter(x=t, y=t**2, name="UKF")])
    assert any("hidden under 'UKF'" in p for p in figcheck.figure_problems(_json(hidden)))
    twice = go.Figure([go.Scatter(x=t, y=t, name="p90"), go.Scatter(x=t, y=2 * t, name="p90")])
    assert any("repeated" in p for p in figcheck.figure_problems(_json(twice)))
    unnamed = go.Figure(
        [
            go.Scatter(x=t, y=t, name="a", line={"color": "#111111"}),
            go.Scatter(x=t, y=2 * t, name="b", line={"color": "#222222"}),
            go.Scatter(x=t, y=3 * t, name="c", showlegend=False, line={"color": "#333333"}),
        ]
    )
    assert any("no legend entry" in p for p in figcheck.figure_problems(_json(unnamed)))
    distinct = go.Figure([go.Scatter(x=t, y=t, name="a"), go.Scatter(x=t, y=t + 1, name="b")])
    assert figcheck.figure_problems(_json(distinct)) == []


def test_coinciding_lines_are_revealed_and_distinct_ones_left_alone():
    t = np.linspace(0, 10, 101)
    y = np.exp(-t)
    fig = line_figure(t, {"EKF": y, "UKF": y * (1 + 1e-5), "UPF": 2 * y})
    assert figcheck.figure_problems(_json(fig)) == []
    assert fig.data[1].line.dash == "dash" and fig.data[0].line.width > 2
    assert fig.data[2].line.dash is None  # not under anything
    cdf = cdf_figure({"EKF": y, "UKF": y})
    assert figcheck.figure_problems(_json(cdf)) == []
    assert reveal_overlaps(go.Figure()) is not None
    with pytest.raises(TypeError, match="fig"):
        reveal_overlaps({"data": []})


def test_factor_panels_and_the_cdf_panels_name_every_colour_once():
    rng = np.random.default_rng(0)
    f = [rng.normal(size=(n, 3)) + 1j * rng.normal(size=(n, 3)) for n in (9, 20, 12)]
    assert figcheck.figure_problems(_json(factors_figure(f))) == []
    errs = {(a, s): rng.rayleigh(1.0, 200) for a in ("A", "B") for s in ("10 Hz", "30 Hz")}
    p90 = {
        (a, s): 1.0 + len(a + s) / 10 + (s == "30 Hz")
        for a in ("A", "B")
        for s in ("10 Hz", "30 Hz")
    }
    fig = approach_cdfs(errs, p90, approaches=("A", "B"))
    assert figcheck.figure_problems(_json(fig)) == []
    assert fig.layout.xaxis2.matches == "x"  # the panels share their x range


def test_a_wild_origin_does_not_squash_the_view_and_is_counted():
    traj = np.column_stack([np.linspace(45, 5, 20), np.full(20, -2.5), np.full(20, 1.5)])
    pts = np.vstack([traj[:5] + np.array([0.0, 0.0, 3.0]), [[172.0, 0.0, 2.0]]])
    fig = wave_origins_figure({"est": pts}, traj, np.array([0.0, 0.0, 4.8]))
    assert np.max(fig.data[0].x) < 80
    assert "1 origin(s) beyond" in fig.layout.title.text
