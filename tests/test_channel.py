import numpy as np
import pytest

from tunnelkit import channel, signal_route
from tunnelkit import propagation as P
from tunnelkit.arrays import make_array
from tunnelkit.constants import K_B, C


@pytest.fixture(scope="module")
def small():
    tun = P.semicircular_tunnel()
    arr = make_array(2, 3, fc=5.9e9, azimuth=0.0, elevation=np.radians(-30), origin=[0, 0, 4.8])
    paths = P.trace_paths(tun, arr, [18.0, -2.5, 1.5], [-12.0, 0.0, 0.0], fc=5.9e9)
    return arr, paths


def test_srs_numbers_of_section_4_2():
    cfg = channel.SRSConfig()
    assert cfg.n_tones == 410 and cfg.tone_spacing == 240e3
    assert cfg.symbol_period == pytest.approx(35.677e-6, rel=1e-4)
    te = 298 + 290 * (10**0.5 - 1)
    assert cfg.noise_temperature == pytest.approx(te)
    assert cfg.noise_power == pytest.approx(K_B * 100e6 * te)
    assert cfg.tx_power == pytest.approx(0.19953, rel=1e-4)
    with pytest.raises(ValueError, match="n_rb"):
        channel.SRSConfig(n_rb=300)


def test_tensor_follows_eq1_term_by_term(small):
    arr, paths = small
    cfg = channel.SRSConfig()
    bias = 12e-9
    H = channel.channel_tensor(paths, cfg, clock_bias=bias, n_tones=5, n_symbols=3)
    ref = np.zeros((arr.M, 5, 3), complex)
    for p in paths:
        for m in range(arr.M):
            for s in range(5):
                for k in range(3):
                    ref[m, s, k] += (
                        np.sqrt(cfg.tx_power)
                        * p.gain
                        * np.exp(2j * np.pi * cfg.fc / C * (p.lengths[m] - p.lengths[0]))
                        * np.exp(-2j * np.pi * s * cfg.tone_spacing * (p.length / C + bias))
                        * np.exp(2j * np.pi * k * p.doppler * cfg.symbol_period)
                    )
    np.testing.assert_allclose(H, ref, rtol=1e-12, atol=0)


def test_srnf_switch_changes_reflections_only(small):
    _arr, paths = small
    cfg = channel.SRSConfig()
    los = [p for p in paths if p.kind == "los"]
    refl = [p for p in paths if p.kind != "los"]
    a = channel.channel_tensor(los, cfg, model="srnf", n_tones=4)
    np.testing.assert_allclose(a, channel.channel_tensor(los, cfg, n_tones=4), atol=0)
    b = channel.channel_tensor(refl, cfg, model="srnf", n_tones=4)
    assert np.max(np.abs(b - channel.channel_tensor(refl, cfg, n_tones=4))) > 1e-3 * np.max(
        np.abs(b)
    )


def test_noise_and_clock_bias_are_seeded_and_calibrated():
    rng = np.random.default_rng(3)
    b = channel.sample_clock_bias(rng, 50e-9, 100e-9, size=20000)
    assert np.all(np.abs(b) <= 100e-9)
    # std of N(0, 50 ns) truncated at +-2 sigma: 0.8796 * 50 ns
    assert np.std(b) == pytest.approx(0.8796 * 50e-9, rel=0.03)
    assert channel.sample_clock_bias(np.random.default_rng(1)) == channel.sample_clock_bias(
        np.random.default_rng(1)
    )
    z = channel.add_noise(np.zeros((20, 30, 40)), 2.0, np.random.default_rng(0))
    assert np.mean(np.abs(z) ** 2) == pytest.approx(2.0, rel=0.02)
    with pytest.raises(TypeError, match="rng"):
        channel.sample_clock_bias(0)


def test_bad_input(small):
    _arr, paths = small
    cfg = channel.SRSConfig()
    with pytest.raises(ValueError, match="paths"):
        channel.channel_tensor([], cfg)
    with pytest.raises(ValueError, match="model"):
        channel.channel_tensor(paths, cfg, model="planar")
    with pytest.raises(TypeError, match="config"):
        channel.channel_tensor(paths, {"fc": 5.9e9})
    with pytest.raises(ValueError, match="H"):
        channel.add_noise(np.full((2, 2, 2), np.nan), 1.0, np.random.default_rng(0))


def test_simulate_epoch_route_recovers_the_los():
    ep = signal_route.simulate_epoch(
        "italiano2026-straight", 20, np.random.default_rng(5), kinds=("los", "road", "rrm")
    )
    m = ep.measurements
    los = ep.paths[0]
    i = int(np.flatnonzero(ep.truth_index == 0)[0])
    assert m.d[i] == pytest.approx(los.length + C * ep.snapshot.clock_bias, abs=0.02)
    assert np.degrees(np.arccos(np.clip(m.direction[i] @ los.direction, -1, 1))) < 1.0
    assert m.phi[i] == pytest.approx(los.azimuth, abs=0.02) and m.psi[i] == pytest.approx(
        los.elevation, abs=0.02
    )
    assert m.v[i] == pytest.approx(los.velocity, abs=0.05)
    assert m.z.shape == (4 * len(m) - 1,) and m.delta_d[0] == 0
    with pytest.raises(ValueError, match="k"):
        signal_route.simulate_epoch("italiano2026-straight", 999, np.random.default_rng(0))
