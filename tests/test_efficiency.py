import numpy as np
import pytest

from tunnelkit import channel, signal_route
from tunnelkit.efficiency import drive_efficiency, efficiency_rows
from tunnelkit.plots import efficiency_figure


@pytest.fixture(scope="module")
def two():
    return signal_route.SignalRoute.from_scenario("italiano2026-straight", kinds=("los", "road"))


@pytest.fixture(scope="module")
def rows(two):
    return drive_efficiency(two, [6, 12], 3, 0, refines=("joint", "ml"))


def test_ml_sits_on_the_bound_and_the_paper_route_does_not(rows):
    assert len(rows) == 2 * 2 * 2  # epochs x routes x paths
    at = {(r["epoch"], r["route"], r["path"]): r for r in rows}
    for k in (6, 12):
        ml = at[(k, "ml", "los")]
        assert ml["matched"] == 3 and ml["no kappa"] == 0
        # 3 snapshots: a loose factor (the chi distribution of an RMS over 3 draws)
        assert ml["RMSE dir [deg]"] < 3 * ml["CRLB dir [deg]"]
        assert ml["RMSE kappa [m]"] < 3 * ml["CRLB kappa [m]"]
        # the paper's route (free spatial factor, then TLS) stays well above it even with two
        # well-separated paths (measured: 5-6x the bound in kappa at these epochs)
        paper = at[(k, "joint", "los")]
        assert paper["RMSE kappa [m]"] > 4 * paper["CRLB kappa [m]"]
        assert paper["RMSE dir [deg]"] > 2 * ml["RMSE dir [deg]"]
        assert paper["CRLB dir [deg]"] == ml["CRLB dir [deg]"]  # one bound per path
    assert at[(6, "ml", "los")]["range [m]"] > at[(12, "ml", "los")]["range [m]"]


def test_efficiency_rows_and_figure(rows):
    data = efficiency_rows(rows, "los")
    assert set(data) == {"joint", "ml"}
    assert np.all(np.diff(data["ml"]["range"]) > 0)  # sorted by range
    fig = efficiency_figure(rows, "los")
    assert len(fig.data) == 2 * 2 + 2  # two routes and the bound, two panels
    with pytest.raises(ValueError, match=r"^path"):
        efficiency_rows(rows, "rrm")


def test_an_impairment_lifts_the_ml_estimate_off_the_bound(two):
    wide = two.with_impairments(
        channel.Impairments(spatial_wideband=True), np.random.default_rng(0)
    )
    r = {x["path"]: x for x in drive_efficiency(wide, [12], 2, 0, refines=("ml",))}
    assert r["los"]["RMSE kappa [m]"] > 10 * r["los"]["CRLB kappa [m]"]


def test_bad_input(two):
    with pytest.raises(ValueError, match=r"^epochs"):
        drive_efficiency(two, [], 1, 0)
    with pytest.raises(ValueError, match=r"^refines"):
        drive_efficiency(two, [3], 1, 0, refines=())
    with pytest.raises(ValueError, match=r"^n_snapshots"):
        drive_efficiency(two, [3], 0, 0)
