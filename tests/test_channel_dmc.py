"""channel: dense diffuse multipath (DMC) has the covariance and the power its closed form says."""

import numpy as np
import pytest

from tunnelkit import channel
from tunnelkit import propagation as P
from tunnelkit.arrays import make_array


@pytest.fixture(scope="module")
def small():
    tun = P.semicircular_tunnel()
    arr = make_array(2, 2, fc=5.9e9, azimuth=0.0, elevation=np.radians(-30), origin=[0, 0, 4.8])
    paths = P.trace_paths(tun, arr, [18.0, -2.5, 1.5], [-12.0, 0.0, 0.0], fc=5.9e9)
    return arr, paths


def test_taps_are_finer_than_the_resolution_and_sum_to_one():
    spec = channel.DiffuseSpec(0.1, decay_s=20e-9, oversample=4)
    dtau, w = spec.taps(240e3, 410)
    assert dtau == pytest.approx(1 / (4 * 410 * 240e3))
    assert w.sum() == pytest.approx(1.0) and np.all(np.diff(w) < 0)
    assert w[1] / w[0] == pytest.approx(np.exp(-dtau / 20e-9))
    # at most one unambiguous delay 1 / Df
    assert spec.taps(240e3, 4)[1].size <= 4 * 4


def test_fft_synthesis_equals_the_tap_sum():
    spec = channel.DiffuseSpec(0.3, decay_s=50e-9, oversample=3)
    df, nf, tau0 = 240e3, 7, 31e-9
    D = channel.diffuse_tensor(spec, (2, nf, 3), df, tau0, 1.0, np.random.default_rng(5))
    beta_rng = np.random.default_rng(5)
    dtau, w = spec.taps(df, nf)
    p = spec.power(1.0)
    beta = (beta_rng.standard_normal((2, w.size)) + 1j * beta_rng.standard_normal((2, w.size))) * (
        np.sqrt(p * w / 2)
    )
    tau = tau0 + dtau * np.arange(w.size)
    ref = beta @ np.exp(-2j * np.pi * df * tau[:, None] * np.arange(nf)[None, :])
    np.testing.assert_allclose(D[:, :, 0], ref, rtol=1e-10, atol=1e-14)
    np.testing.assert_array_equal(D[:, :, 0], D[:, :, 2])  # constant over the slot's symbols


def test_empirical_covariance_matches_the_closed_form():
    spec = channel.DiffuseSpec(0.2, decay_s=30e-9)
    df, nf, tau0 = 240e3, 6, 40e-9
    rng = np.random.default_rng(11)
    n = 20000
    D = channel.diffuse_tensor(spec, (n, nf, 2), df, tau0, 1.0, rng)  # elements as draws
    emp = D[:, :, 0].T @ D[:, :, 0].conj() / n
    ref = spec.power(1.0) * spec.tone_covariance(df, nf, tau0)
    # 20000 draws: the sampling error of each entry is about 1/sqrt(n) of the power
    assert np.abs(emp - ref).max() < 4 * spec.power(1.0) / np.sqrt(n)
    assert np.abs(ref).max() > 0.9 * spec.power(1.0)  # the test can fail: entries are not tiny
    # spatially white: two elements uncorrelated
    cross = np.mean(D[0::2, :, 0] * D[1::2, :, 0].conj())
    assert abs(cross) < 4 * spec.power(1.0) / np.sqrt(n / 2)


def test_channel_tensor_adds_the_share_of_the_power(small):
    _arr, paths = small
    cfg = channel.SRSConfig()
    H0 = channel.channel_tensor(paths, cfg, n_tones=64, n_symbols=2)
    spec = channel.DiffuseSpec(0.25)
    rng = np.random.default_rng(2)
    d = [
        channel.channel_tensor(paths, cfg, n_tones=64, n_symbols=2, dmc=spec, rng=rng) - H0
        for _ in range(300)
    ]
    p_dmc = np.mean([np.mean(np.abs(x) ** 2) for x in d])
    p_spec = cfg.tx_power * sum(abs(p.gain) ** 2 for p in paths)
    assert p_dmc / (p_dmc + p_spec) == pytest.approx(0.25, rel=0.05)
    # share 0 and no dmc: the tensor untouched, the generator not consumed
    r = np.random.default_rng(4)
    H1 = channel.channel_tensor(
        paths, cfg, n_tones=64, n_symbols=2, dmc=channel.DiffuseSpec(0.0), rng=r
    )
    np.testing.assert_array_equal(H1, H0)
    assert r.random() == np.random.default_rng(4).random()


def test_synthesize_draws_dmc_from_its_generator(small):
    _arr, paths = small
    cfg = channel.SRSConfig()
    spec = channel.DiffuseSpec(0.1)
    a = channel.synthesize(paths, cfg, np.random.default_rng(1), n_tones=8, dmc=spec)
    b = channel.synthesize(paths, cfg, np.random.default_rng(1), n_tones=8, dmc=spec)
    c = channel.synthesize(paths, cfg, np.random.default_rng(1), n_tones=8)
    np.testing.assert_array_equal(a.H, b.H)
    assert np.abs(a.H - c.H).max() > 0


@pytest.mark.parametrize(
    "kw, name",
    [
        (dict(share=1.0), "share"),
        (dict(share=-0.1), "share"),
        (dict(share=float("nan")), "share"),
        (dict(share=0.1, decay_s=0.0), "decay_s"),
        (dict(share=0.1, decay_s=float("nan")), "decay_s"),
        (dict(share=0.1, oversample=0), "oversample"),
        (dict(share=0.1, span=-1.0), "span"),
    ],
)
def test_bad_diffuse_spec_names_the_field(kw, name):
    with pytest.raises((ValueError, TypeError), match=name):
        channel.DiffuseSpec(**kw)


def test_dmc_needs_a_generator_and_a_spec(small):
    _arr, paths = small
    cfg = channel.SRSConfig()
    with pytest.raises(ValueError, match="rng"):
        channel.channel_tensor(paths, cfg, n_tones=4, dmc=channel.DiffuseSpec(0.1))
    with pytest.raises(TypeError, match="dmc"):
        channel.channel_tensor(paths, cfg, n_tones=4, dmc=0.1, rng=np.random.default_rng(0))
    with pytest.raises(TypeError, match="dmc"):
        channel.Impairments(dmc=0.1)
