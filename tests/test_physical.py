"""Physically impossible inputs are refused where they enter, naming the parameter and the unit:
a car faster than any road vehicle, a carrier in GHz or a subcarrier spacing in kHz where Hz are
meant, a radio with one tone, a transmit power of a megawatt of dBm, an array spacing of 1e308
m, a measurement more precise than a picometre, a range of 1e200 m; and the leftovers of the
first round of bad input fixed at their cause (an overflowing plane normal, a 2-way tensor shape,
a fit of no steps, an all-zero spatial factor)."""

from __future__ import annotations

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import _physical as physical
from tunnelkit import arrays, channel, crlb, geometry, positioning
from tunnelkit import doppler_drive as drive
from tunnelkit.extraction import coherent, decomposition


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (
            lambda: drive.make_drive(fc=1.35),
            r"fc: expected 1e\+08 to 3e\+11 Hz, got 1.35 \(fc is in Hz: did you mean 1.35e9",
        ),
        (lambda: channel.SRSConfig(fc=3.5), r"fc: .*did you mean 3.5e9"),
        (lambda: channel.SRSConfig(fc=1e12), r"fc: expected 1e\+08 to 3e\+11 Hz, got 1e\+12"),
        (lambda: channel.SRSConfig(scs=120), r"scs: .*did you mean 120e3"),
        (lambda: channel.SRSConfig(n_rb=1, comb=64), r"n_rb, comb: .* give 1 tone"),
        (lambda: channel.SRSConfig(tx_power_dbm=1e6), r"tx_power_dbm: expected -150 to 100 dBm"),
        (lambda: drive.make_drive(speed=400.0), r"speed: a speed of 40\d m/s, above 150 m/s"),
        (lambda: arrays.ura(4, 4, 1e308), r"spacing: expected 0 to 10 m"),
        (
            lambda: crlb.fim_toa_doa([1.0, 2.0], [[0, 0], [10, 0]], 1e-200, 1.0),
            r"sigma_theta: 1e-200 is below 1e-12",
        ),
        (
            lambda: positioning.ls_toa_doa([[0, 0], [10, 0]], [1e200, 1e200], [0.1, 0.2]),
            r"d_hat: ranges up to 1e\+06 m",
        ),
        (lambda: decomposition.check_rank((4, 4), 1), r"shape: expected a 3-way tensor shape"),
        (
            lambda: coherent.fit_sources(
                np.ones(16, complex), [[0, 0, 0.01]], arrays.ura(4, 4, 0.025), 5.9e9, max_nfev=0
            ),
            r"max_nfev: ",
        ),
        (
            lambda: coherent.split_component(
                np.zeros(16, complex), [[0, 0, 0.01]], arrays.ura(4, 4, 0.025), 5.9e9
            ),
            r"b: an all-zero spatial factor",
        ),
    ],
)
def test_impossible_inputs_are_refused_by_name(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_a_trajectory_faster_than_a_vehicle_is_refused():
    t = np.arange(3.0)
    ok = tk.scenarios.Trajectory(t, np.zeros((3, 2)), np.full((3, 2), [40.0, 0.0]))
    assert len(ok) == 3
    with pytest.raises(ValueError, match=r"velocity: a speed of 8.7e\+10 m/s, above 150 m/s"):
        tk.scenarios.Trajectory(t, np.zeros((3, 2)), np.full((3, 2), [8.7e10, 0.0]))


def test_a_slalom_scenario_at_light_speed_is_refused(tmp_path):
    """A slalom of wavelength 1e-9 m at 14 m/s swings sideways at ~1e11 m/s."""
    text = tk.scenarios.scenario_path("italiano2026-slalom").read_text()
    text = text.replace("slalom_wavelength = 25.0", "slalom_wavelength = 1e-9", 1)
    text = text.replace('name = "italiano2026-slalom"', 'name = "fast-slalom"', 1)
    f = tmp_path / "fast-slalom.toml"
    f.write_text(text)
    with pytest.raises(Exception, match=r"trajectory: velocity: a speed of .* above 150 m/s"):
        tk.load_scenario(f).trajectory(tk.load_scenario(f).tunnel())


def test_the_ranges_admit_every_preset():
    for name in tk.list_scenarios():
        sc = tk.load_scenario(name)
        if sc.family == "halili2022":  # its drive has no tunnel section: make_drive
            drive.make_drive(drive.load_drive_config(name))
            continue
        sc.trajectory(sc.tunnel())
        if "radio" in sc.sections:
            channel.SRSConfig.from_scenario(sc)
    assert physical.speeds("v", [[25.0, 3.0]]).shape == (1, 2)
    assert physical.carrier("fc", 28e9) == 28e9 and physical.subcarrier("scs", 120e3) == 120e3


def test_a_plane_with_huge_coefficients_keeps_its_normal():
    p = geometry.Plane(normal=[1e200, 1e200], offset=1e200)
    np.testing.assert_allclose(p.normal, [2**-0.5, 2**-0.5])
    assert p.offset == pytest.approx(2**-0.5)
    np.testing.assert_allclose(geometry.Plane(normal=[3.0, 4.0], offset=10.0).normal, [0.6, 0.8])


def test_a_tracker_step_at_light_speed_or_of_a_lifetime_is_refused():
    from tunnelkit.tracking.javelin import Javelin
    from tunnelkit.tracking.javelin.arraydesign import array_design

    design = array_design({"d": 1e-3, "direction": 1e-4, "kappa": 0.05})
    trk = Javelin(np.array([-30.0, -3.0, 1.2]), design)
    with pytest.raises(ValueError, match=r"speed: a speed of 4e\+08 m/s, above 150 m/s"):
        trk.step(None, 4e8, 0.0, 0.1)
    with pytest.raises(ValueError, match=r"dt: expected 0 to 60 s, got 1e\+09"):
        trk.step(None, 10.0, 0.0, 1e9)
    trk.step(None, 10.0, 0.0, 0.1)  # a car at 36 km/h for 0.1 s


def test_a_design_start_spread_of_100_km_is_refused():
    from tunnelkit import design

    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    with pytest.raises(ValueError, match=r"start_sigma: expected 0 to 1000 m, got 100000"):
        design.design_sweep(setup, ["4x4"], start_sigma=1e5)


def test_a_route_shorter_than_the_start_up_scores_nothing():
    """Three epochs (0.2 s) leave nothing after the 1 s start-up: the per-run RMSE is missing
    and the settled statistics refuse, never the whole route instead."""
    from tunnelkit import design

    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    r = design.sweep_montecarlo(setup, ["4x4"], 1, 0, n_epochs=3)["4x4"]
    assert r.settled.size == 0 and np.isnan(r.rmse_runs).all()
    with pytest.raises(ValueError, match=r"settled: a 0\.2 s route has no epoch after"):
        _ = r.rmse_settled
    with pytest.raises(ValueError, match="nothing settled to score"):
        r.settled_rms(np.ones(3))


def test_a_drive_of_a_nanometre_is_refused_not_scored_zero():
    from tunnelkit.simulation.variants import drive_variant

    with pytest.raises(ValueError, match=r"length: a 1e-09 m drive ends within the tracker.s 1 s"):
        drive_variant("italiano2026-straight", 1e-9)


def test_a_clock_bias_beyond_the_radio_limit_is_refused():
    """A 1 s bias wraps the phase ramp (240 kHz tones: whole cycles), so the tensor would carry
    none while the snapshot records 1 s; refused where it is given."""
    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight")
    with pytest.raises(ValueError, match=r"clock_bias: 1 s is beyond 1e-07 s"):
        route.epoch(0, np.random.default_rng(0), clock_bias=1.0)
    _, paths = route.paths(0)
    cfg = channel.SRSConfig(clock_bias_sigma=0.0, clock_bias_limit=0.0)
    with pytest.raises(ValueError, match=r"clock_bias: 1e-05 s is beyond 2.08333e-06 s"):
        channel.channel_tensor(paths, cfg, clock_bias=1e-5)
    snap = channel.synthesize(paths, route.config, np.random.default_rng(0), clock_bias=80e-9)
    assert snap.clock_bias == 80e-9


def test_containers_refuse_speeds_no_vehicle_has():
    from tunnelkit.tracking.javelin.measurement import PathMeasurements

    with pytest.raises(ValueError, match=r"v: a measured radial speed of 4e\+08 m/s, faster than"):
        PathMeasurements.from_arrays([0.1], [0.0], [10.0], [10.0], [4e8])
    # an extraction's outlier (a wrong path's Doppler) is carried for the tracker to gate
    assert PathMeasurements.from_arrays([0.1], [0.0], [10.0], [10.0], [550.0]).v[0] == 550.0
    assert PathMeasurements.from_arrays([0.1], [0.0], [10.0], [10.0], [np.nan]).v.size == 1
    d = tk.simulation.simulate_drive(
        "italiano2026-straight", np.random.default_rng(0), extraction="paper", n_epochs=2
    )
    import dataclasses

    with pytest.raises(ValueError, match=r"velocity: a speed of 3e\+08 m/s"):
        dataclasses.replace(d, velocity=np.full_like(d.velocity, 3e8 / np.sqrt(3)))


def test_an_information_so_small_its_bound_overflows_is_refused():
    with pytest.raises(ValueError, match="F: numerically singular"):
        crlb.crlb_trace(np.array([[2.22507386e-309, 0.0], [0.0, 1.0]]))
    with pytest.raises(ValueError, match="F: numerically singular"):
        crlb.crlb_trace(np.diag([1e-320, 1.0, 1.0]))
    assert crlb.crlb_trace(np.diag([4.0, 2.0])) == pytest.approx(0.75)


def test_a_predicted_error_larger_than_the_tunnel_is_no_fix():
    """A diffuse share of 1 - 1e-9 predicted errors of hundreds of kilometres in an 8 m tunnel:
    each such epoch is a gap (no fix), and a candidate with no other epoch is refused by name."""
    from tunnelkit import design

    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    rep = design.design_sweep(setup, ["4x4"], impairments={"dmc_share": 0.999999999})
    (row,) = rep.rows
    assert row.status == "error" and "beyond the tunnel's extent (200.2 m)" in row.reason
    ok = design.design_sweep(setup, ["8x8"], impairments={"dmc_share": 0.5}).rows[0]
    assert ok.status == "bound only" and np.isfinite(ok.predicted_p90_m)


def test_a_series_of_speeds_is_judged_speed_by_speed():
    assert physical.speeds("speed", np.full(1500, 10.0), vectors=False).shape == (1500,)
    with pytest.raises(ValueError, match=r"speed: a speed of 200 m/s"):
        physical.speeds("speed", [10.0, 200.0], vectors=False)
    with pytest.raises(ValueError, match=r"v: a speed of 387.3 m/s"):
        physical.speeds("v", np.full(1500, 10.0))  # one 1500-D velocity vector
