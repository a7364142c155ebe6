"""The line of sight's sigmas by measured elevation (tunnelkit.design.los)."""

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit.design.los import (
    ElevationSigmas,
    elevation_sigmas,
    los_errors,
    los_only,
    told_by_elevation,
)
from tunnelkit.studies.los_only import los_design


def test_table_is_the_rms_in_equal_count_bins_of_the_measured_elevation():
    rng = np.random.default_rng(4)
    psi = rng.uniform(-0.4, 0.0, 400)
    scale = np.where(psi < -0.2, 0.002, 0.03)  # steep: accurate; shallow: degrees off
    err = np.c_[psi, scale * rng.standard_normal(400), 2 * scale * rng.standard_normal(400)]
    t = elevation_sigmas(err, 4)
    order = np.argsort(psi)
    for b, chunk in enumerate(np.array_split(order, 4)):  # brute force: sorted, cut in four
        np.testing.assert_allclose(t.sigma_azimuth[b], np.sqrt(np.mean(err[chunk, 1] ** 2)))
        np.testing.assert_allclose(t.sigma_elevation[b], np.sqrt(np.mean(err[chunk, 2] ** 2)))
        assert psi[chunk].min() <= t.elevation[b] <= psi[chunk].max()
    assert t.sigma_elevation[0] < 0.2 * t.sigma_elevation[-1]


def test_table_reads_between_and_beyond_its_bins_and_round_trips():
    t = ElevationSigmas(np.radians([-20.0, -10.0, 0.0]), np.radians([0.2, 1.0, 3.0]),
                        np.radians([0.3, 2.0, 4.0]))  # fmt: skip
    az, el = t.at(np.radians([-30.0, -15.0, -10.0, 5.0]))
    np.testing.assert_allclose(np.degrees(az), [0.2, 0.6, 1.0, 3.0])
    np.testing.assert_allclose(np.degrees(el), [0.3, 1.15, 2.0, 4.0])
    back = ElevationSigmas.from_dict(t.as_dict())
    np.testing.assert_allclose(back.sigma_elevation, t.sigma_elevation)
    want = "-20.0 deg: 0.20 / 0.30 deg; -10.0 deg: 1.00 / 2.00 deg; 0.0 deg: 3.00 / 4.00 deg"
    assert t.describe() == back.describe() == want


def test_bad_tables_are_refused_by_name():
    with pytest.raises(ValueError, match="elevation"):
        ElevationSigmas(np.array([0.1, 0.0]), np.ones(2) * 0.01, np.ones(2) * 0.01)
    with pytest.raises(ValueError, match="sigma_azimuth"):
        ElevationSigmas(np.array([0.0, 0.1]), np.array([0.01, -0.01]), np.ones(2) * 0.01)
    with pytest.raises(ValueError, match="sigma_elevation"):
        ElevationSigmas(np.array([0.0, 0.1]), np.ones(2) * 0.01, np.array([0.01, 4.0]))
    with pytest.raises(ValueError, match="table"):
        ElevationSigmas.from_dict({"elevation": [0.0]})
    with pytest.raises(ValueError, match="errors"):
        elevation_sigmas(np.zeros((5, 3)), 4)
    with pytest.raises(ValueError, match="bins"):
        elevation_sigmas(np.ones((10, 3)), 0)
    with pytest.raises(ValueError, match=r"^errors: tied"):
        elevation_sigmas(np.c_[np.r_[np.zeros(8), 0.1, 0.2], np.ones((10, 2))], 4)
    with pytest.raises(ValueError, match=r"^drives:"):
        los_errors([])


@pytest.fixture(scope="module")
def drive():
    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight")
    rng = np.random.default_rng(3)
    return tk.simulation.simulate_drive(route, rng, condition="L", extraction="ml", n_epochs=4)


def test_errors_on_the_image_channel_are_small_and_the_drive_is_told_them(drive):
    e = los_errors([drive])  # eq. 1's own tensor: the ML fit at its bound, millidegrees
    assert e.shape == (4, 3) and np.all(np.abs(np.degrees(e[:, 1:])) < 0.02)
    assert np.all(e[:, 0] < 0)  # the site above the road: the line of sight arrives from below
    t = ElevationSigmas(np.array([-0.3, 0.0]), np.radians([0.1, 2.0]), np.radians([0.2, 3.0]))
    los = los_only(drive)
    told = told_by_elevation(los, t, 1.5, 0.5)
    assert told.reports_covariance
    for ep in told.epochs:
        saz, sel = t.at(ep.psi)
        np.testing.assert_allclose(ep.cov[:, 0, 0], saz**2)
        np.testing.assert_allclose(ep.cov[:, 1, 1], sel**2)
        np.testing.assert_allclose(ep.sigma_d, 0.5)
    design = los_design(np.radians(1.0)).with_(noise=tk.tracking.javelin.ReportedNoise())
    ev = tk.simulation.evaluate(told, design)
    assert np.all(np.isfinite(ev.estimates))
    with pytest.raises(ValueError, match=r"^sigma_kappa:"):
        told_by_elevation(los, t, -1.0, 0.5)
    with pytest.raises(TypeError, match=r"^table:"):
        told_by_elevation(los, {"elevation": [0.0]}, 1.0, 0.5)


def test_errors_are_measured_against_the_true_direction_at_a_steep_angle(drive):
    """A site 30 m above the road (elevations of -35 to -40 deg) and every measurement put on the
    true line of sight, then 1 deg off in both angles: the errors are those, exactly."""
    from dataclasses import replace

    los = los_only(drive)
    site = los.base_station + np.array([0.0, 0.0, 25.0])
    v = los.truth - site
    az, el = np.arctan2(v[:, 1], v[:, 0]), np.arctan2(v[:, 2], np.hypot(v[:, 0], v[:, 1]))
    assert np.all(np.degrees(el) < -30)
    off = np.radians(1.0)
    epochs = [replace(ep, phi=np.array([az[k] + off]), psi=np.array([el[k] - off]))
              for k, ep in enumerate(los.epochs)]  # fmt: skip
    e = los_errors([replace(los, epochs=epochs, base_station=site)])
    np.testing.assert_allclose(e[:, 1], off, atol=1e-12)
    np.testing.assert_allclose(e[:, 2], -off, atol=1e-12)
    np.testing.assert_allclose(e[:, 0], el - off, atol=1e-12)


def test_los_error_rows_wrap_the_azimuth_against_the_sight_by_hand():
    """los_error_rows: (measured elevation, azimuth error wrapped to +-pi, elevation error)
    against atan2 by hand, across the +-pi seam; one row as the direct drive records it; bad
    shapes refused by name."""
    from tunnelkit.design.los import los_error_rows

    rng = np.random.default_rng(5)
    sight = rng.normal(size=(50, 3)) * [20.0, 20.0, 3.0]
    az = np.arctan2(sight[:, 1], sight[:, 0])
    el = np.arctan2(sight[:, 2], np.hypot(sight[:, 0], sight[:, 1]))
    d_az, d_el = rng.uniform(-0.1, 0.1, (2, 50))
    phi = az + d_az + np.where(rng.random(50) < 0.5, 2 * np.pi, 0.0)  # some a turn around
    rows = los_error_rows(phi, el + d_el, sight)
    np.testing.assert_allclose(rows[:, 0], el + d_el, atol=1e-12)
    np.testing.assert_allclose(rows[:, 1], d_az, atol=1e-12)
    np.testing.assert_allclose(rows[:, 2], d_el, atol=1e-12)
    one = los_error_rows(phi[:1], el[:1] + d_el[:1], [sight[0]])
    np.testing.assert_array_equal(one, rows[:1])
    with pytest.raises(ValueError, match=r"^sight"):
        los_error_rows(phi, el, sight[:3])
    with pytest.raises(ValueError, match=r"^psi"):
        los_error_rows(phi, el[:3], sight)
