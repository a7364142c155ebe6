import numpy as np
import pytest

from tunnelkit import calibration, channel, signal_route
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


def _eq1_reference(paths, cfg, bias, nf, nt):
    """Eq. 1 evaluated as the unimpaired code path does (for bit-identity)."""
    k0 = 2 * np.pi * cfg.fc / C
    delta = np.stack([p.delta() for p in paths], axis=1)
    tau = np.array([p.lengths[0] for p in paths]) / C + bias
    fd = np.array([p.doppler for p in paths])
    alpha = np.sqrt(cfg.tx_power) * np.array([p.gain for p in paths])
    bs = np.exp(1j * k0 * delta)
    bf = np.exp(-2j * np.pi * cfg.tone_spacing * np.arange(nf)[:, None] * tau[None, :])
    bt = np.exp(2j * np.pi * cfg.symbol_period * np.arange(nt)[:, None] * fd[None, :])
    return np.einsum("ml,sl,kl->msk", bs * alpha, bf, bt, optimize=True)


def test_impairments_off_leave_the_tensor_bit_identical(small):
    _arr, paths = small
    cfg = channel.SRSConfig()
    H = channel.channel_tensor(paths, cfg, clock_bias=7e-9)
    assert np.array_equal(H, _eq1_reference(paths, cfg, 7e-9, cfg.n_tones, cfg.n_symbols))
    off = channel.channel_tensor(
        paths, cfg, clock_bias=7e-9, calibration=None, spatial_wideband=False
    )
    assert np.array_equal(H, off)
    a = channel.synthesize(paths, cfg, np.random.default_rng(3), n_tones=16)
    b = channel.synthesize(
        paths, cfg, np.random.default_rng(3), n_tones=16, calibration=None, spatial_wideband=False
    )
    assert np.array_equal(a.H, b.H) and a.clock_bias == b.clock_bias
    # a route with no impairment (default, or all-zero impairments) draws nothing and
    # synthesises exactly the same epochs from the same generator
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight", kinds=("los", "road"))
    zero = route.with_impairments(channel.Impairments(), np.random.default_rng(5))
    assert zero.calibration == {}
    e1 = route.epoch(10, np.random.default_rng(9))
    e2 = zero.epoch(10, np.random.default_rng(9))
    assert np.array_equal(e1.snapshot.H, e2.snapshot.H)


def test_spatial_wideband_matches_a_direct_per_element_computation(small):
    """Per element and tone, the physical phase ``-2 pi f_s tau_lm`` of the exact per-element
    delay ``tau_lm = ||s_l - p_m|| / c + b`` at the tone's frequency ``f_s = fc + (s - s_c) Df``
    (the band centred on fc), times two tone-independent conventions of eq. 1: the carrier's
    spatial phase with the printed sign (``exp(+j k0 delta_lm)`` for the physical
    ``exp(-j k0 delta_lm)``) and the path's phase taken at the lowest tone ``f_0``."""
    arr, paths = small
    cfg = channel.SRSConfig()
    bias, nf, nt = -20e-9, 7, 3
    H = channel.channel_tensor(
        paths, cfg, clock_bias=bias, n_tones=nf, n_symbols=nt, spatial_wideband=True
    )
    k0 = 2 * np.pi * cfg.fc / C
    f0 = cfg.fc - 0.5 * (nf - 1) * cfg.tone_spacing
    ref = np.zeros((arr.M, nf, nt), complex)
    for p in paths:
        tau_l = p.length / C + bias
        for m in range(arr.M):
            tau_lm = p.lengths[m] / C + bias
            dm = p.lengths[m] - p.lengths[0]
            for s in range(nf):
                f_s = f0 + s * cfg.tone_spacing
                for k in range(nt):
                    ref[m, s, k] += (
                        np.sqrt(cfg.tx_power)
                        * p.gain
                        * np.exp(-2j * np.pi * f_s * tau_lm)
                        * np.exp(2j * k0 * dm)  # eq. 1's printed sign of the carrier phase
                        * np.exp(2j * np.pi * f0 * tau_l)  # eq. 1: the phase at f_0 is the gain's
                        * np.exp(2j * np.pi * k * p.doppler * cfg.symbol_period)
                    )
    np.testing.assert_allclose(H, ref, rtol=1e-9, atol=1e-9 * np.abs(ref).max())
    # tone to tone, element m's phase advances by -2 pi Df tau_lm: its exact delay (one path)
    H1 = channel.channel_tensor(
        paths[:1], cfg, clock_bias=bias, n_tones=nf, n_symbols=nt, spatial_wideband=True
    )
    step = np.angle(H1[:, 1:, 0] / H1[:, :-1, 0])
    want = np.angle(np.exp(-2j * np.pi * cfg.tone_spacing * (paths[0].lengths / C + bias)))
    np.testing.assert_allclose(step, np.broadcast_to(want[:, None], step.shape), atol=1e-9)
    # at the band centre the tensor is eq. 1's: the term changes nothing there ...
    H0 = channel.channel_tensor(paths, cfg, clock_bias=bias, n_tones=nf, n_symbols=nt)
    sc = (nf - 1) // 2
    np.testing.assert_allclose(H[:, sc], H0[:, sc], rtol=1e-12, atol=0)
    np.testing.assert_allclose(H[0], H0[0], rtol=1e-12, atol=0)  # nor at the reference antenna
    # ... and grows towards both band edges
    for edge in (0, -1):
        assert np.max(np.abs(H[1:, edge] - H0[1:, edge])) > 1e-4 * np.max(np.abs(H0))


def test_calibration_error_has_the_stated_statistics(small):
    arr, paths = small
    g = calibration.draw_calibration(np.random.default_rng(0), 40_000, 3.0, 0.5)
    phase_deg = np.degrees(np.angle(g))
    gain_db = 20 * np.log10(np.abs(g))
    # 40 000 draws: the sample std is within 1.5 % (about 4 standard errors) of sigma
    assert np.std(phase_deg) == pytest.approx(3.0, rel=0.015)
    assert np.std(gain_db) == pytest.approx(0.5, rel=0.015)
    assert abs(np.mean(phase_deg)) < 0.06 and abs(np.mean(gain_db)) < 0.01
    assert abs(np.corrcoef(phase_deg, gain_db)[0, 1]) < 0.02
    # explicit calibration multiplies each element's slice, nothing else
    cfg = channel.SRSConfig()
    cal = calibration.draw_calibration(np.random.default_rng(1), arr.M, 5.0, 1.0)
    H0 = channel.channel_tensor(paths, cfg, n_tones=6, n_symbols=2)
    H1 = channel.channel_tensor(paths, cfg, n_tones=6, n_symbols=2, calibration=cal)
    np.testing.assert_allclose(H1, cal[:, None, None] * H0, rtol=1e-14, atol=0)
    # drawn once per array: every epoch of an impaired route uses the same vector
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    imp = channel.Impairments(phase_sigma_deg=2.0, gain_sigma_db=0.5)
    bad = route.with_impairments(imp, np.random.default_rng(2))
    assert set(bad.calibration) == {a.name for a in route.arrays}
    again = route.with_impairments(imp, np.random.default_rng(2))
    for name, v in bad.calibration.items():
        assert np.array_equal(v, again.calibration[name]) and v.shape == (100,)


def test_impairment_bad_input(small):
    _arr, paths = small
    cfg = channel.SRSConfig()
    with pytest.raises(ValueError, match=r"^phase_sigma_deg"):
        channel.Impairments(phase_sigma_deg=-1.0)
    with pytest.raises(ValueError, match=r"^gain_sigma_db"):
        calibration.draw_calibration(np.random.default_rng(0), 4, 1.0, float("nan"))
    with pytest.raises(TypeError, match=r"^spatial_wideband"):
        channel.channel_tensor(paths, cfg, n_tones=4, spatial_wideband=1)
    with pytest.raises(ValueError, match=r"^calibration"):
        channel.channel_tensor(paths, cfg, n_tones=4, calibration=np.ones(3))
    with pytest.raises(ValueError, match=r"^calibration"):
        channel.channel_tensor(paths, cfg, n_tones=4, calibration=np.zeros(paths[0].lengths.size))
    with pytest.raises(TypeError, match=r"^rng"):
        calibration.draw_calibration(0, 4, 1.0)
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    with pytest.raises(TypeError, match=r"^impairments"):
        route.with_impairments({"phase_sigma_deg": 1.0}, np.random.default_rng(0))
