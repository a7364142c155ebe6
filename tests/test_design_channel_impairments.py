"""The design's channel Monte-Carlo carries the impairments into the synthesised tensor and the
extraction (the bound mode draws them from the error model; the channel mode must synthesise
them)."""

from __future__ import annotations

import numpy as np
import pytest

import tunnelkit.extraction
import tunnelkit.simulation
from tunnelkit.design import DesignImpairments, DesignSetup, sweep_montecarlo


class _Stop(Exception):
    pass


@pytest.fixture(scope="module")
def setup():
    return DesignSetup.from_scenario("italiano2026-straight")


def _first_drive_route(setup, monkeypatch, **kw):
    """The route the channel-mode sweep hands its first drive (the drive itself not run)."""
    seen = []

    def fake_drive(route, rng, **_):
        seen.append(route)
        raise _Stop

    monkeypatch.setattr(tunnelkit.simulation, "simulate_drive", fake_drive)
    with pytest.raises(_Stop):
        sweep_montecarlo(setup, ["2x2"], 1, 0, mode="channel", n_epochs=1, **kw)
    (route,) = seen
    return route


def test_channel_mode_synthesises_the_impairments_and_models_the_wideband_term(setup, monkeypatch):
    imp = DesignImpairments(
        phase_error_deg=1.0, gain_error_db=0.3, spatial_wideband=True, wideband_model=True
    )
    route = _first_drive_route(setup, monkeypatch, impairments=imp)
    assert route.impairments.spatial_wideband
    assert route.impairments.phase_sigma_deg == 1.0 and route.impairments.gain_sigma_db == 0.3
    # every mounted array's calibration error drawn for this run
    assert set(route.calibration) == {a.name for a in route.arrays}
    for cal in route.calibration.values():
        assert cal.shape == (4,) and not np.allclose(cal, 1.0)
    assert route.options.wideband_model
    # its fits judged against noise + the impairment power it was told about
    assert route.options.model_error_floor

    # and the epoch's extraction is asked to model the wideband term
    asked = {}

    def fake_extract(H, n_paths, arr, cfg, **kw):
        asked.update(kw)
        raise _Stop

    monkeypatch.setattr(tunnelkit.extraction, "extract_paths", fake_extract)
    with pytest.raises(_Stop):
        route.epoch(0, np.random.default_rng(0))
    assert asked.get("wideband") is True


def test_ideal_channel_mode_stays_the_ideal_route(setup, monkeypatch):
    route = _first_drive_route(setup, monkeypatch)
    assert not route.calibration and not route.options.wideband_model
    assert not route.options.model_error_floor and route.options.bias_budget is None
    with pytest.raises(TypeError, match="impairments"):
        sweep_montecarlo(setup, ["2x2"], 1, 0, mode="channel", impairments={"phase": 1.0})
    with pytest.raises(TypeError, match="wideband_model"):
        route.with_options(wideband_model="yes")
