"""Notebook 08 explorer: the pure callback's figure layout and the explorer's wiring."""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from tunnelkit import design
from tunnelkit.plots.design import route_figure, size_figure
from tunnelkit.widgets.design import design_explorer, design_figure


def test_figure_meta_and_title():
    fig = design_figure(n=8, target=0.15)
    assert isinstance(fig, go.Figure)
    m = fig.layout.meta
    assert m["array"] == "8x8" and m["n_elements"] == 64 and m["fits"]
    assert m["srnf_valid_share"] == 0.0  # the ceiling, 20 cm above the array
    assert fig.layout.title.text.startswith(f"Predicted to meet: {m['predicted']} ")
    assert "(a prediction)" in fig.layout.title.text
    # 3x3's predicted error (its paths weighed one block at a time) misses 0.15 m on part of
    # the route; 4x4 meets it
    assert m["predicted"] == "4x4"
    names = [t.name for t in fig.data]
    assert names[:2] == ["PEB 8x8", "SR-NF not valid"] and "mismatch, ceiling" in names


def test_figure_follows_the_mount():
    # a mount 1 m lower moves the ceiling's reflection point away: SR-NF holds for larger arrays
    high = design_figure(n=4, mount_height=5.8).layout.meta
    low = design_figure(n=4, mount_height=4.8).layout.meta
    assert low["srnf_valid_share"] > high["srnf_valid_share"]


def test_design_that_does_not_fit_gives_a_message_not_an_exception():
    fig = design_figure(n=32, fc_ghz=3.0, mount_height=5.9)
    assert fig.layout.meta["fits"] is False
    assert "arrays:" in fig.layout.title.text


def test_explorer_driven_programmatically():
    ex = design_explorer(target=0.15, units=2)
    assert ex.figure.layout.meta["array"] == "8x8"
    ex.set(n=4)
    assert ex.figure.layout.meta["array"] == "4x4"
    ex.set(fc_ghz=5.9, bandwidth_mhz=100.0)
    assert "5.9 GHz" in ex.figure.layout.title.subtitle.text
    assert all(not getattr(w, "continuous_update", False) for w in ex.controls.values())


def test_size_figure_marks_the_papers_array():
    setup = design.DesignSetup.from_scenario("italiano2026-straight")
    rep = design.design_sweep(setup, ["4x4", "10x10"])
    fig = size_figure(rep.rows, mark="10x10")
    assert fig.layout.shapes[0].x0 == 100
    b = design.route_bounds(setup, "10x10")
    rf = route_figure(b, target=0.2)
    assert np.allclose([v for v in rf.data[0].y if v is not None], 100 * b.peb[np.isfinite(b.peb)])


def test_impairment_sliders_move_the_prediction_not_the_peb():
    ideal = design_figure(n=8, target=0.1).layout.meta
    cal = design_figure(n=8, target=0.1, phase_error_deg=2.0, gain_error_db=0.2).layout.meta
    # no impairment: the tracker's block-weighted fix, never below the PEB
    assert ideal["predicted_median_m"] >= ideal["peb_median_m"]
    assert cal["peb_median_m"] == ideal["peb_median_m"]
    assert cal["predicted_median_m"] > 10 * ideal["predicted_median_m"]
    assert cal["met_share"] < ideal["met_share"]
    fig = design_figure(n=8, target=0.1, dmc_share=0.1)
    assert "predicted, impaired" in [t.name for t in fig.data]


def test_monte_carlo_summary_states_the_verdict_and_interval():
    from tunnelkit.widgets.design import monte_carlo_summary

    row = design.DesignRow("4x4", 16, 0.02, status="undecided", reason="few units")
    row.error_p90_m, row.error_p90_ci95_m = 0.05, [0.01, 0.09]
    row.units, row.runs, row.unit_yield, row.unit_yield_ci95 = 3, 6, 2 / 3, [0.21, 0.94]
    row.predicted_p90_m, row.peb_p90_m = 0.02, 0.01
    text = monte_carlo_summary(row)
    assert text.startswith("4x4: undecided — 66.7 % of 3 units") and "[21, 94] %" in text
    assert "[1, 9] cm over 6 drives" in text and "not a bound" in text
    assert monte_carlo_summary(design.DesignRow("2x2", 4, 0.01, reason="x")).endswith(": x")
