"""The answer of a design sweep as a figure (:func:`tunnelkit.plots.design.design_answer_figure`)
and ``tunnelkit design --plot``: traces, styles and meta from a small real sweep, a bounds-only
report, a bad report refused, the HTML written and a missing directory refused naming ``plot``;
the size figure's labels (:func:`tunnelkit.plots.design.size_figure`): the PEB a reference, the
PCRLB the bound beside the tracker's RMSE."""

from __future__ import annotations

import json

import numpy as np
import plotly.graph_objects as go
import pytest

from tunnelkit import design
from tunnelkit.cli import main
from tunnelkit.plots.design import __all__ as plots_all
from tunnelkit.plots.design import design_answer_figure, size_figure

SCENARIO = "example-rectangular-28ghz"
ARRAYS = ["4x4", "8x8"]
PEB_NAME = "PEB (one epoch's bound, a reference)"


@pytest.fixture(scope="module")
def setup():
    return design.DesignSetup.from_scenario(SCENARIO)


@pytest.fixture(scope="module")
def report(setup):
    return design.design_sweep(
        setup,
        ARRAYS,
        target=0.1,
        units=2,
        max_units=2,
        drives_per_unit=1,
        n_epochs=20,
        settle=0.5,
        impairments={"phase_error_deg": 1.0},
    )


@pytest.fixture(scope="module")
def bounds_only(setup):
    return design.design_sweep(
        setup, ARRAYS, target=0.1, units=0, n_epochs=20, impairments={"phase_error_deg": 1.0}
    )


def _top(fig):
    return [t for t in fig.data if t.yaxis == "y"]


def _cm(v):
    return np.array([np.nan if y is None else y for y in v], float) / 100


def test_exported():
    assert "design_answer_figure" in plots_all


def test_figure_of_a_monte_carlo_sweep(report):
    fig = design_answer_figure(report)
    assert isinstance(fig, go.Figure)
    meta = fig.layout.meta
    assert meta["arrays"] == ARRAYS
    assert meta["unit_yield"] == [r.unit_yield for r in report.rows]
    assert meta["required_yield"] == report.settings["required_yield"] == 0.95
    assert meta["target"] == 0.1
    title = fig.layout.title.text
    assert SCENARIO in title and "10 cm" in title and "95 %" in title

    top = _top(fig)
    # per array: median (solid), PEB (dotted), prediction (dashed); then the target
    assert len(top) == 3 * len(ARRAYS) + 1
    for i, r in enumerate(report.rows):
        med, peb, pred = top[3 * i : 3 * i + 3]
        assert med.legendgroup == peb.legendgroup == pred.legendgroup == r.array
        assert med.line.dash is None and "median" in med.name
        assert f"{100 * r.error_p90_m:.3g} cm" in med.name  # the pooled p90 in the legend
        assert peb.line.dash == "dot" and peb.name == f"{r.array} {PEB_NAME}"
        assert pred.line.dash == "dash" and pred.name == f"{r.array} predicted (not a bound)"
        np.testing.assert_allclose(_cm(med.y), r.error_median_epoch_m, rtol=1e-12)
        np.testing.assert_allclose(_cm(peb.y), r.peb_m, rtol=1e-12)
        np.testing.assert_allclose(_cm(pred.y), r.predicted_m, rtol=1e-12)
        np.testing.assert_allclose(peb.x, r.x_m)
    target = top[-1]
    assert "target" in target.name and set(target.y) == {10.0}
    assert fig.layout.yaxis.type == "log"

    (yield_trace,) = [t for t in fig.data if t.yaxis == "y2"]
    assert list(yield_trace.x) == ARRAYS
    np.testing.assert_allclose(yield_trace.y, [100 * r.unit_yield for r in report.rows])
    for j, r in enumerate(report.rows):
        lo, hi = r.unit_yield_ci95
        assert yield_trace.y[j] - yield_trace.error_y.arrayminus[j] == pytest.approx(100 * lo)
        assert yield_trace.y[j] + yield_trace.error_y.array[j] == pytest.approx(100 * hi)
        assert r.status in yield_trace.text[j]
    (required,) = [s for s in fig.layout.shapes if s.yref == "y2"]
    assert required.y0 == required.y1 == pytest.approx(95.0) and required.showlegend


def test_bounds_only_report_shows_bounds_and_predictions(bounds_only):
    fig = design_answer_figure(bounds_only)
    top = _top(fig)
    assert [t.name for t in top] == [
        f"{a} {k}" for a in ARRAYS for k in (PEB_NAME, "predicted (not a bound)")
    ] + ["target 10 cm"]
    assert len({t.name for t in top}) == len(top)  # no legend entry repeated
    assert not any("median" in (t.name or "") for t in fig.data)
    assert fig.layout.meta["unit_yield"] == [None, None]
    assert any("no Monte-Carlo" in a.text for a in fig.layout.annotations)


def test_size_figure_labels_the_peb_a_reference_and_plots_the_bound(report, bounds_only):
    fig = size_figure(report.rows, mark=None)
    by_name = {t.name: t for t in fig.data}
    assert "PEB median (a reference)" in by_name and "PEB 90th pct (a reference)" in by_name
    rmse, pcrlb = by_name["tracker RMSE (95 % CI)"], by_name["PCRLB (bound of the RMSE)"]
    np.testing.assert_allclose(_cm(rmse.y), [r.rmse_m for r in report.rows], rtol=1e-12)
    np.testing.assert_allclose(_cm(pcrlb.y), [r.pcrlb_rms_m for r in report.rows], rtol=1e-12)
    assert not any("bound" in t.name for t in fig.data if "PEB" in t.name)
    # without Monte-Carlo: no tracker, no PCRLB
    names = [t.name for t in size_figure(bounds_only.rows, mark=None).data]
    assert not any("RMSE" in n for n in names), names


@pytest.mark.parametrize("bad", [None, {"rows": []}, "report", []])
def test_bad_report_is_refused(bad):
    with pytest.raises(TypeError, match=r"^report: expected a tunnelkit\.design\.DesignReport"):
        design_answer_figure(bad)


def test_cli_writes_the_figure(tmp_path, capsys):
    out = tmp_path / "answer.html"
    argv = ["design", SCENARIO, "--arrays", "4x4", "8x8", "--units", "2", "--max-units", "2"]
    argv += ["--drives-per-unit", "1", "--n-epochs", "12", "--phase-error-deg", "1"]
    argv += ["--settle", "0.5", "--target", "0.1", "--no-progress", "--format", "json"]
    assert main([*argv, "--plot", str(out)]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["arrays"][0]["array"] == "4x4"  # stdout stays valid JSON
    assert cap.err.strip().endswith(f"figure written to {out}")
    html = out.read_text()
    assert "plotly" in html.lower() and f"{SCENARIO}: 10 cm" in html and "unit yield" in html


def test_cli_writes_the_figure_without_monte_carlo(tmp_path, capsys):
    out = tmp_path / "bounds.html"
    argv = ["design", SCENARIO, "--arrays", "4x4", "--units", "0", "--n-epochs", "12"]
    argv += ["--settle", "0.5"]
    assert main([*argv, "--plot", str(out)]) == 0
    assert "figure written to" in capsys.readouterr().err
    assert "PEB (one epoch" in out.read_text()


def test_cli_missing_directory_names_plot(tmp_path, capsys):
    out = tmp_path / "no-such-dir" / "answer.html"
    argv = ["design", SCENARIO, "--arrays", "4x4", "--units", "0", "--n-epochs", "12"]
    argv += ["--settle", "0.5"]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--plot", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "plot" in err and "does not exist" in err
    assert not out.parent.exists()
