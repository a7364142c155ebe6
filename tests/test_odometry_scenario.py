"""Odometry as a scenario input: the ``[odometry]`` section's figures and units, its refusals,
and every consumer (the drive simulator, the design's drives and bounds, a row of sites, the
long-tunnel study) taking the drive's model unless told another."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit.odometry import AUTOMOTIVE, WHITE, Odometry
from tunnelkit.scenarios import ScenarioError, load_scenario

PRESETS = Path(__file__).resolve().parent.parent / "data" / "scenarios"
BASE = (PRESETS / "example-rectangular-28ghz.toml").read_text()


def _file(tmp_path, section: str, name: str = "odo") -> Path:
    p = tmp_path / f"{name}.toml"
    p.write_text(BASE.replace('name = "example-rectangular-28ghz"', f'name = "{name}"') + section)
    return p


def test_without_the_section_the_drive_carries_the_paper_model():
    sc = load_scenario("example-rectangular-28ghz")
    assert sc.odometry() == WHITE and sc.trajectory().odometry == WHITE
    for name in ("italiano2026-straight", "italiano2026-slalom"):
        assert load_scenario(name).trajectory().odometry == WHITE


def test_the_mont_blanc_preset_drives_on_a_cars_odometry():
    sc = load_scenario("mont-blanc-28ghz")
    assert sc.odometry() == AUTOMOTIVE and sc.odometry().label == "automotive"
    assert sc.trajectory().odometry == AUTOMOTIVE


def test_the_section_names_a_model_and_replaces_terms_in_data_sheet_units(tmp_path):
    sec = (
        '\n[odometry]\nmodel = "automotive"\n'
        "speed_scale = 0.005\nspeed_noise = 0.1\nheading_bias_deg = 2.0\n"
        "heading_drift_deg_per_sqrt_h = 0.6\nyaw_rate_bias_deg_per_h = 36.0\n"
        "heading_noise_deg = 0.5\nrate_hz = 20.0\ndropout = 0.25\n"
    )
    odo = load_scenario(str(_file(tmp_path, sec))).odometry()
    deg = np.pi / 180.0
    want = Odometry(
        speed_scale=0.005, speed_noise=0.1, heading_bias=2.0 * deg,
        heading_drift=0.6 * deg / 60.0, yaw_rate_bias=36.0 * deg / 3600.0,
        heading_noise=0.5 * deg, rate=20.0, dropout=0.25,
    )  # fmt: skip
    for field in want.__dataclass_fields__:
        assert getattr(odo, field) == pytest.approx(getattr(want, field), rel=1e-12), field
    assert odo.label == "custom"
    # a section names its model (no silent default); "white" with a term is white plus that term
    auto = '\n[odometry]\nmodel = "automotive"\n'
    assert load_scenario(str(_file(tmp_path, auto, "a"))).odometry() == AUTOMOTIVE
    with pytest.raises(ScenarioError, match=r"odometry\.model"):
        load_scenario(str(_file(tmp_path, "\n[odometry]\nspeed_scale = 0.01\n", "m")))
    w = load_scenario(str(_file(tmp_path, '\n[odometry]\nmodel = "white"\n', "w"))).odometry()
    assert w == WHITE and w.label == "white"
    ws = '\n[odometry]\nmodel = "white"\nspeed_scale = 0.01\n'
    assert load_scenario(str(_file(tmp_path, ws, "ws"))).odometry() == replace(
        WHITE, speed_scale=0.01
    )
    # a message per epoch: rate 0
    r0s = '\n[odometry]\nmodel = "automotive"\nrate_hz = 0\n'
    r0 = load_scenario(str(_file(tmp_path, r0s, "r0"))).odometry()
    assert r0.rate is None and r0 == replace(AUTOMOTIVE, rate=None)


@pytest.mark.parametrize(
    ("line", "key"),
    [
        ("speed_scale = 1.0", "odometry.speed_scale"),  # a scale factor of 100 %
        ("speed_scale = -0.01", "odometry.speed_scale"),
        ("heading_drift_deg_per_sqrt_h = -0.1", "odometry.heading_drift_deg_per_sqrt_h"),
        ("yaw_rate_bias_deg_per_h = -1", "odometry.yaw_rate_bias_deg_per_h"),
        ("dropout = 1.0", "odometry.dropout"),
        ("rate_hz = -10", "odometry.rate_hz"),
        ('model = "gps"', "odometry.model"),
        ("speed_noise = 400.0", "odometry.speed_noise"),  # a speed error faster than sound
        ("speed_noise = 0.0", "odometry.speed_noise"),  # a perfect sensor
        ("heading_noise_deg = 0", "odometry.heading_noise_deg"),
        ("scale = 0.01", "odometry.scale"),
    ],
)
def test_the_section_refuses_what_no_odometry_does_naming_the_key(tmp_path, line, key):
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        body = line if line.startswith("model") else f'model = "automotive"\n{line}'
        load_scenario(str(_file(tmp_path, f"\n[odometry]\n{body}\n")))


def test_the_drive_simulator_draws_the_drives_model_unless_told_another():
    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight")
    car = replace(route, trajectory=replace(route.trajectory, odometry=AUTOMOTIVE))
    kw = {"condition": "L", "extraction": "ml", "n_epochs": 12}
    own = tk.simulation.simulate_drive(car, np.random.default_rng(3), **kw)
    told = tk.simulation.simulate_drive(route, np.random.default_rng(3), odometry=AUTOMOTIVE, **kw)
    white = tk.simulation.simulate_drive(route, np.random.default_rng(3), **kw)
    np.testing.assert_array_equal(own.speed, told.speed)
    np.testing.assert_array_equal(own.heading, told.heading)
    assert np.isnan(own.speed).any() and not np.isnan(white.speed).any()  # 10 Hz, 10 % lost
    # told another model, the drive's is set aside
    other = tk.simulation.simulate_drive(car, np.random.default_rng(3), odometry=WHITE, **kw)
    np.testing.assert_array_equal(other.speed, white.speed)


def test_the_design_and_a_row_of_sites_take_the_drives_model():
    from tunnelkit.design import DesignSetup, drive_pcrlb
    from tunnelkit.design.sites import SiteRow, site_drive, site_route

    setup = DesignSetup.from_scenario("mont-blanc-28ghz")
    row = SiteRow.along(setup, 200.0, 400.0, speed=19.44)
    assert row.setup.trajectory.odometry == AUTOMOTIVE
    route = site_route(row, "4x4")
    own = site_drive(row, route, np.random.default_rng(5), n_epochs=40)
    told = site_drive(row, route, np.random.default_rng(5), n_epochs=40, odometry=AUTOMOTIVE)
    np.testing.assert_array_equal(own.heading, told.heading)
    # the drive's bound with the car's repeating errors as states; told white, lower
    T = 30
    info = np.broadcast_to(np.eye(2) / 0.1**2, (T, 2, 2))
    car = drive_pcrlb(setup, info)
    np.testing.assert_array_equal(car, drive_pcrlb(setup, info, odometry=AUTOMOTIVE))
    white = drive_pcrlb(setup, info, odometry=WHITE)
    assert np.all(white <= car + 1e-12) and car[-1] > white[-1]


def test_the_long_tunnel_study_drives_on_the_scenarios_model_by_default():
    from tunnelkit.design import DesignSetup
    from tunnelkit.design.longtunnel import long_tunnel_study

    setup = DesignSetup.from_scenario("mont-blanc-28ghz")
    kw = {"length": 300.0, "runs": 1, "speed": 19.44, "seed": 4}
    own = long_tunnel_study(setup, ("4x4",), (200.0,), **kw)
    named = long_tunnel_study(setup, ("4x4",), (200.0,), odometry="automotive", **kw)
    assert own.odometry == AUTOMOTIVE and own.to_json()["odometry"] == "automotive"
    for k in ("p90", "rmse", "dr_p90", "bound"):
        assert own.rows[0][k] == named.rows[0][k], k
    assert own.to_json()["odometry_figures"]["speed_scale"] == AUTOMOTIVE.speed_scale
    with pytest.raises(ValueError, match="odometry"):
        long_tunnel_study(setup, ("4x4",), (200.0,), odometry="gyro", **kw)


def test_the_designs_tracker_is_told_the_drives_white_noise():
    from tunnelkit.design.arrayjob import javelin_config
    from tunnelkit.tracking.javelin.arraydesign import array_design

    crlb = {"d": 0.01, "direction": 0.001, "kappa": 1.0}
    paper = array_design(crlb, 0.0, None)
    assert javelin_config(crlb, 0.0, None, WHITE) == paper == javelin_config(crlb, 0.0, None)
    quiet = Odometry.white(0.05, float(np.radians(0.25)))
    cfg = javelin_config(crlb, 0.0, None, replace(AUTOMOTIVE, speed_noise=0.05)).config
    assert cfg.sigma_speed == 0.05 and cfg.sigma_heading == AUTOMOTIVE.heading_noise
    cfg = javelin_config(crlb, 0.0, None, quiet).config
    assert (cfg.sigma_speed, cfg.sigma_heading) == (0.05, quiet.heading_noise)


def test_the_drive_bound_of_messages_without_white_noise_of_one_kind():
    """A drive whose messages carry no white noise of one kind (a model built in code; a file
    refuses it) is bounded by the bias-state recursion, which takes a zero, not refused."""
    from tunnelkit.design import DesignSetup, drive_pcrlb

    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    T = 20
    info = np.broadcast_to(np.eye(2) / 0.1**2, (T, 2, 2))
    for odo in (replace(WHITE, heading_noise=0.0), replace(AUTOMOTIVE, speed_noise=0.0)):
        quiet = replace(setup, trajectory=replace(setup.trajectory, odometry=odo))
        b = drive_pcrlb(quiet, info)
        np.testing.assert_array_equal(b, drive_pcrlb(quiet, info, odometry=odo))
        assert np.all(np.isfinite(b)) and np.all(b > 0)
