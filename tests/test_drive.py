"""The synthetic Halili drive: geometry, pinned Doppler sign, multipath, noise, clocks, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit import doppler_drive as dv
from tunnelkit.constants import C
from tunnelkit.doppler_drive import drive as drive_model
from tunnelkit.doppler_drive import measurement
from tunnelkit.geometry import Plane
from tunnelkit.reflection import specular_point
from tunnelkit.scenarios import ScenarioError

CLEAN = dict(dv.IDEAL)


@pytest.fixture(scope="module")
def drive():
    return dv.make_drive()


def test_paper_setup(drive):
    cfg = drive.config
    assert cfg.dt == pytest.approx(0.032)  # 0.8 m at 90 km/h
    assert len(drive.t) == 1688
    assert drive.t[-1] == pytest.approx(53.984, abs=1e-9)
    assert np.mean(drive.velocity[:, 0]) == pytest.approx(25.0, abs=0.1)  # 90 km/h on average
    assert drive.t[drive.closest_index] == pytest.approx(37.0, abs=cfg.dt)  # passes near second 37
    assert cfg.delay_resolution == pytest.approx(12.5e-9)  # 80 MHz (sec. 3.1)
    assert cfg.doppler_resolution == pytest.approx(32.04, abs=0.01)  # 32 snapshots of 975.3 us
    assert np.all(np.abs(drive.position[:, 1]) < cfg.width / 2)


def test_doppler_sign_against_geometry(drive):
    """Approach positive, recede negative, zero at the closest point; f_D = -(f_c/c) dr/dt."""
    k = drive.closest_index
    f = drive.doppler_los
    assert np.all(f[: k - 1] > 0) and np.all(f[k + 2 :] < 0)
    assert abs(f[k]) < 0.05 * np.abs(f).max()
    # independent check: finite difference of the slant range while moving along the velocity
    eps = 1e-4
    r_plus = dv.slant_range(drive.position + eps * drive.velocity, drive.tx_xy, drive.dz)
    r_minus = dv.slant_range(drive.position - eps * drive.velocity, drive.tx_xy, drive.dz)
    f_fd = -(drive.config.fc / C) * (r_plus - r_minus) / (2 * eps)
    assert np.max(np.abs(f_fd - f)) < 1e-3  # Hz
    # far from the transmitter the shift approaches f_c v / c = 1.35 GHz x 25 m/s / c = 112.6 Hz
    assert 100 < f[0] < 114 and -114 < f[-1] < -100


def test_doppler_shift_single_points():
    tx = np.array([0.0, 0.0])
    v = np.array([10.0, 0.0])
    assert dv.doppler_shift([-100.0, 0.0], v, tx, 1e9) == pytest.approx(
        1e9 * 10 / C
    )  # head-on approach
    assert dv.doppler_shift([100.0, 0.0], v, tx, 1e9) == pytest.approx(-1e9 * 10 / C)
    assert dv.doppler_shift([0.0, 5.0], v, tx, 1e9) == pytest.approx(0.0, abs=1e-12)
    # the height offset lowers the shift by cos(elevation)
    assert dv.doppler_shift([-3.0, 0.0], v, tx, 1e9, dz=4.0) == pytest.approx(1e9 * 10 / C * 3 / 5)


def test_images_equal_unfolded_specular_paths():
    """Single-bounce image distances equal the lengths of the specular paths (brute force)."""
    cfg = dv.DriveConfig(max_order=1)
    tx = np.array([50.0, cfg.tx_y, cfg.tx_z])
    src, order = dv.image_sources(cfg, tx)
    assert order[0] == 0 and np.allclose(src[0], tx) and len(src) == 5
    rx = np.array([10.0, cfg.lane_y, cfg.rx_height])
    planes = [
        Plane(np.array([0, 1.0, 0]), -cfg.width / 2),
        Plane(np.array([0, 1.0, 0]), cfg.width / 2),
        Plane(np.array([0, 0, 1.0]), 0.0),
        Plane(np.array([0, 0, 1.0]), -cfg.height),
    ]
    lengths = []
    for pl in planes:
        s = specular_point(tx, rx, pl)
        lengths.append(np.linalg.norm(s - tx) + np.linalg.norm(rx - s))
        assert np.any(np.all(np.isclose(src[1:], pl.mirror(tx)), axis=1))
    got = np.sort(np.linalg.norm(src[1:] - rx, axis=1))
    assert np.allclose(got, np.sort(lengths), atol=1e-9)


def test_no_multipath_means_no_bias():
    d = dv.make_drive(reflection_coeff=0.0)
    assert np.max(np.abs(d.toa_peak - d.toa_los)) < 0.02e-9
    assert np.max(np.abs(d.doppler_peak - d.doppler_los)) < 0.02


def test_multipath_biases_the_delay_late(drive):
    bias = (drive.toa_peak - drive.toa_los) * C
    assert np.max(bias) > 1.0  # merged reflections pull the CIR peak late by metres somewhere
    assert np.median(np.abs(bias)) < drive.config.delay_resolution * C  # within one resolution cell


def test_measure_is_seeded_and_documented(drive):
    a = dv.measure(drive, np.random.default_rng(3))
    b = dv.measure(drive, np.random.default_rng(3))
    c = dv.measure(drive, np.random.default_rng(4))
    assert np.array_equal(a.doppler, b.doppler) and np.array_equal(a.toa, b.toa)
    assert not np.array_equal(a.doppler, c.doppler)
    assert np.all(np.isfinite(a.doppler)) and not a.dropped.any()
    # the parts add up to the measurement wherever no outlier replaced it
    ok = ~a.outlier
    rebuilt = (
        drive.doppler_los
        + a.parts["doppler_multipath"]
        + a.parts["cfo"]
        + a.parts["doppler_bias"]
        + a.parts["doppler_white"]
    )
    assert np.allclose(rebuilt[ok], a.doppler[ok])
    toa = (
        drive.toa_los
        + a.parts["toa_multipath"]
        + a.parts["toa_nlos"]
        + a.parts["clock"]
        + a.parts["toa_white"]
    )
    assert np.allclose(toa, a.toa, rtol=0, atol=1e-15)
    assert np.all(a.parts["toa_nlos"] >= 0)  # excess delay never arrives early


def test_noise_statistics():
    d = dv.make_drive(**{**CLEAN, "doppler_noise_hz": 5.0, "noise_ref_range": 1e9})
    m = dv.measure(d, np.random.default_rng(0))
    assert np.std(m.doppler - d.doppler_peak) == pytest.approx(5.0, rel=0.06)
    d = dv.make_drive(**{**CLEAN, "doppler_bias_hz": 10.0})
    m = dv.measure(d, np.random.default_rng(1))
    lag1 = np.corrcoef(m.parts["doppler_bias"][:-1], m.parts["doppler_bias"][1:])[0, 1]
    assert lag1 == pytest.approx(np.exp(-0.8 / 20.0), abs=0.02)  # Gauss-Markov, 20 m correlation


def test_clean_measurements_and_clock():
    d = dv.make_drive(**{**CLEAN, "clock_offset_s": 50e-9, "clock_drift": 1e-9, "cfo_hz": 3.0})
    m = dv.measure(d, np.random.default_rng(0))
    assert np.allclose(m.doppler, d.doppler_peak + 3.0)
    assert np.allclose(m.toa, d.toa_peak + 50e-9 + 1e-9 * d.t, rtol=0, atol=1e-16)


def test_dropped_epochs_are_marked():
    d = dv.make_drive(drop_prob=0.1)
    m = dv.measure(d, np.random.default_rng(2))
    assert 0.07 < m.dropped.mean() < 0.13
    assert np.array_equal(np.isnan(m.doppler), m.dropped) and np.array_equal(
        np.isnan(m.toa), m.dropped
    )


def test_gnss_fix(drive):
    fix = dv.gnss_fix(drive, np.random.default_rng(0))
    assert np.linalg.norm(fix.position - drive.position[0]) < 4 * drive.config.gnss_sigma_m
    assert fix.covariance.shape == (4, 4)
    with pytest.raises(ValueError, match="velocity"):
        dv.GnssFix(position=np.zeros(2), velocity=np.zeros(2), sigma_p=1.0, sigma_v=1.0)


def test_profiles(drive):
    pr = dv.delay_doppler_profiles(drive, every=40)
    assert pr["pdp_db"].shape == (len(pr["t"]), len(pr["delay"]))
    assert pr["pdp_db"].max() == pytest.approx(0.0) and pr["dpp_db"].max() == pytest.approx(0.0)
    # the strongest Doppler bin is positive before the pass and negative after it
    peak = pr["doppler"][np.argmax(pr["dpp_db"], axis=1)]
    assert peak[0] > 80 and peak[-1] < -80


def test_scenario_file_matches_defaults(tmp_path):
    assert dv.load_drive_config("halili2022-drive") == dv.DriveConfig()
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\npaper = "halili2022"\n[vehicle]\nspeed = 25.0\nwarp = 9\n')
    with pytest.raises(ScenarioError, match=r"vehicle\.warp"):
        dv.load_drive_config(str(bad))
    bad.write_text('name = "x"\npaper = "halili2022"\n[vehicle]\nspeed = 0.0\n')
    with pytest.raises(ScenarioError, match="speed"):
        dv.load_drive_config(str(bad))


@pytest.mark.parametrize(
    "field, value, match",
    [
        ("speed", 0.0, "speed"),
        ("doppler_noise_hz", -1.0, "doppler_noise_hz"),
        ("lane_y", 6.0, "lane_y"),
        ("tx_z", 5.5, "tx_z"),
        ("outlier_prob", 1.5, "outlier_prob"),
        ("max_order", 2.5, "max_order"),
        ("speed_amplitude", 30.0, "speed_amplitude"),
        ("pass_time", 60.0, "pass_time"),
    ],
)
def test_bad_config(field, value, match):
    with pytest.raises((ValueError, TypeError), match=match):
        dv.DriveConfig(**{field: value})


def test_bad_calls(drive):
    with pytest.raises(TypeError, match="rng"):
        dv.measure(drive, 0)
    with pytest.raises(TypeError, match="drive"):
        dv.measure("drive", np.random.default_rng(0))
    with pytest.raises(ValueError, match="warp"):
        dv.make_drive(warp=1.0)


def test_gauss_markov_is_stationary_from_the_first_sample():
    x = np.array(
        [measurement._gauss_markov(np.random.default_rng(s), 5, 2.0, 0.9) for s in range(20000)]
    )
    assert np.allclose(x.std(axis=0), 2.0, rtol=0.03)
    assert np.corrcoef(x[:, 0], x[:, 1])[0, 1] == pytest.approx(0.9, abs=0.01)
    assert np.corrcoef(x[:, 3], x[:, 4])[0, 1] == pytest.approx(0.9, abs=0.01)


def test_speed_profile_distance_is_the_integral_of_the_speed():
    """Brute force for the closed-form distance: trapezoidal integral of v(t) on a fine grid."""
    cfg = dv.DriveConfig(speed_amplitude=3.0, speed_period=11.0)
    t = np.linspace(0.0, cfg.duration, 200_001)
    s, v = drive_model._speed_profile(cfg, t)
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    assert np.allclose(s, integral, atol=1e-6)


def test_parabolic_peak_is_exact_on_a_parabola():
    grid = np.tile(np.linspace(-2.0, 2.0, 41), (3, 1))
    true = np.array([-0.537, 0.0, 1.234])
    mag = 5.0 - (grid - true[:, None]) ** 2
    assert np.allclose(drive_model._peak(grid, mag), true, atol=1e-12)
