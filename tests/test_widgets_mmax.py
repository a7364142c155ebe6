"""The Mmax explorer: pure figure callback, programmatic slider moves, unreachable bad input."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import tunnelkit
from tunnelkit import fresnel
from tunnelkit.widgets.mmax import TRACE_INDEX, Y_U_MARGIN, mmax_explorer, mmax_figure


def test_exported_from_widgets_package():
    assert tunnelkit.widgets.mmax_figure is mmax_figure
    assert tunnelkit.widgets.mmax_explorer is mmax_explorer


def test_figure_layout_is_stable_and_verdict_readable():
    fig = mmax_figure()  # the paper's example, M = 10
    assert fig.layout.title.text.startswith("SR-NF valid for M = 10")
    meta = fig.layout.meta
    assert meta["valid"] is True and meta["mmax_exact"] == 15
    assert meta["mmax_eq25"] == pytest.approx(9.88, abs=0.01)
    assert meta["verdict"] == fig.layout.title.text
    assert len(fig.data) == len(TRACE_INDEX) == 19
    exact = fig.data[TRACE_INDEX["mismatch_exact"]]
    assert exact.name == "exact" and exact.xaxis == "x2"
    want = np.abs(fresnel.mismatch_profile(fresnel.ula_positions(10, 5.9e9), 3.5, 3.0, 2.5, 5.9e9))
    np.testing.assert_allclose(exact.y, want, atol=1e-12)
    assert np.max(exact.y) == pytest.approx(meta["mismatch"])
    assert fig.data[TRACE_INDEX["mmax_exact"]].xaxis == "x3"
    assert fig.layout.xaxis3.type == "log" and fig.layout.yaxis3.type == "log"
    assert [a.text[:3] for a in fig.layout.annotations] == ["(a)", "(b)", "(c)"]


def test_verdict_flips_exactly_at_the_exact_mmax():
    m = fresnel.mmax_exact(20.0, 3.0, 2.0, 28e9, 0.15)
    kw = dict(R=20.0, W=3.0, y_u=2.0, z_u=0.0, eps_phi=0.15, fc=28e9)
    assert mmax_figure(M=m, **kw).layout.meta["valid"]
    bad = mmax_figure(M=m + 1, **kw)
    assert not bad.layout.meta["valid"]
    assert bad.layout.title.text.startswith("SR-NF not valid")


def test_explorer_driven_programmatically():
    ex = mmax_explorer()
    fig = ex.figure
    assert (
        fig.layout.title.text == mmax_figure(**ex.values).layout.title.text
    )  # built before display
    before = np.array(fig.data[TRACE_INDEX["mismatch_exact"]].y)
    ex.set(M=40)
    after = np.array(fig.data[TRACE_INDEX["mismatch_exact"]].y)
    assert after.shape == (40,) and before.shape == (10,)
    assert fig.layout.title.text.startswith("SR-NF not valid for M = 40")
    assert fig.layout.meta["mismatch"] == pytest.approx(
        fresnel.phase_mismatch(40, 3.5, 3.0, 2.5, 5.9e9)
    )
    ex.set(fc=28e9, R=100.0)  # 28 GHz, far away: 40 antennas are fine
    assert fig.layout.title.text.startswith("SR-NF valid for M = 40")
    assert fig.layout.meta["mmax_exact"] == fresnel.mmax_exact(100.0, 3.0, 2.5, 28e9, 0.15)
    ex.set(z_u=-3.3)
    assert fig.layout.meta["mismatch"] == pytest.approx(
        fresnel.phase_mismatch(40, 100.0, 3.0, 2.5, 28e9, z_u=-3.3)
    )
    with pytest.raises(ValueError, match="no such control"):
        ex.set(N=3)


def test_lowering_W_clamps_y_u_before_the_redraw():
    ex = mmax_explorer()
    ex.set(W=2.0)  # y_u was 2.5: must not raise, y_u follows below the wall
    assert ex.values["y_u"] == pytest.approx(2.0 - Y_U_MARGIN)
    assert ex.controls["y_u"].max == pytest.approx(2.0 - Y_U_MARGIN)
    assert "SR-NF" in ex.figure.layout.title.text
    ex.set(y_u=5.0)  # beyond the slider's max: clamped by the widget, never reaches W
    assert ex.values["y_u"] < ex.values["W"]
    ex.set(W=10.0)
    assert ex.controls["y_u"].max == pytest.approx(10.0 - Y_U_MARGIN)


def test_sliders_report_on_release_only():
    ex = mmax_explorer()
    sliders = [w for w in ex.controls.values() if hasattr(w, "continuous_update")]
    assert len(sliders) == 6 and not any(w.continuous_update for w in sliders)
    assert sorted(ex.controls["fc"].options, key=lambda o: o[1])[0][1] == 3.5e9


def test_no_slider_corner_raises():
    ex = mmax_explorer()
    c = ex.controls
    corners = {k: (c[k].min, c[k].max) for k in ("R", "W", "z_u", "eps_phi", "M")}
    fcs = [v for _, v in c["fc"].options]
    for R, W, z_u, eps, M in itertools.product(*corners.values()):
        for y_u in (c["y_u"].min, W - Y_U_MARGIN):
            fig = mmax_figure(R=R, W=W, y_u=y_u, z_u=z_u, eps_phi=eps, fc=fcs[-1], M=M)
            assert fig.layout.title.text.startswith("SR-NF")
    for fc in fcs:  # the other carriers at the harshest corner (UE at the wall, far, big eps)
        mmax_figure(R=150.0, W=10.0, y_u=10.0 - Y_U_MARGIN, z_u=5.0, eps_phi=1.0, fc=fc, M=256)


def test_explorer_refuses_unreachable_start_values():
    with pytest.raises(ValueError, match=r"^fc:"):
        mmax_explorer(fc=6e9)
    with pytest.raises(ValueError, match=r"^y_u:"):
        mmax_explorer(y_u=3.0)


def test_subtitle_flags_an_array_longer_than_the_wall_distance():
    long = mmax_figure(W=1.0, y_u=0.9, M=256, fc=3.5e9)
    assert "reaches the wall" in long.layout.title.subtitle.text
    assert "reaches the wall" not in mmax_figure().layout.title.subtitle.text
    assert len(long.data) == len(TRACE_INDEX)  # same layout, the far antenna's path is omitted
