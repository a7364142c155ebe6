"""The maximum-likelihood model with the spatial-wideband term (tunnelkit.extraction.ml.wideband):
its atoms against the channel's synthesis, its Gauss-Newton model against finite differences,
and the fit of a wideband tensor with and without it."""

import warnings

import numpy as np
import pytest
from fd_helpers import central_differences, flat, unflat

from tunnelkit import arrays, channel, propagation
from tunnelkit.channel import channel_tensor
from tunnelkit.constants import C
from tunnelkit.design import DesignImpairments, DesignSetup, path_error_model
from tunnelkit.extraction import ml, ml_truth

FC = 28e9
LAM = C / FC
K0 = 2 * np.pi / LAM
DF = 40e6  # 16 tones x 40 MHz: 640 MHz around 28 GHz, a term large enough to see
SRS = channel.SRSConfig(fc=FC, bandwidth=400e6, scs=120e3, n_rb=264, comb=4)


@pytest.fixture(scope="module")
def toy():
    """Two near-field paths on 6 x 6 elements, 16 tones, 4 symbols, the tensor of the wideband
    model (noiseless) and the problem."""
    pos = arrays.ura(6, 6, LAM / 2)
    th = np.array([[0.31, -0.22, 1 / 2.5], [-0.4, 0.15, 1 / 4.0]])
    mf, mt = np.array([0.4, -1.1]), np.array([0.2, -0.5])
    c = np.array([1.0 + 0.5j, 0.6 - 0.3j])
    prob0 = ml.WidebandProblem(np.ones((36, 16, 4), complex), pos, FC, DF)
    H = prob0.model(th, mf, mt, c)
    return ml.WidebandProblem(H, pos, FC, DF), (th, mf, mt), c


def test_atoms_are_the_per_element_per_tone_delay(toy):
    """Element m, tone s: eq. 1's atom times ``exp(-j 2 pi (f_s - fc) delta_m / c)``, with
    ``delta_m`` the exact path-length offset and ``f_s`` the tone around the band centre."""
    prob, (th, mf, mt), _ = toy
    got = prob.model(th[:1], mf[:1], mt[:1], np.ones(1))
    uz = np.sqrt(1 - th[0, 0] ** 2 - th[0, 1] ** 2)
    q = np.array([th[0, 0], th[0, 1], uz]) / th[0, 2]
    delta = np.linalg.norm(q - prob.pos, axis=1) - np.linalg.norm(q)
    s, k = np.arange(16), np.arange(4)
    f_s = FC + (s - 7.5) * DF
    ref = (
        np.exp(1j * K0 * delta)[:, None, None]
        * np.exp(-2j * np.pi * (f_s - FC)[None, :, None] * delta[:, None, None] / C)
        * np.exp(1j * s * mf[0])[None, :, None]
        * np.exp(1j * k * mt[0])[None, None, :]
    )
    np.testing.assert_allclose(got, ref, rtol=1e-10, atol=1e-10)
    # eq. 1's model differs at the band edges (the term is there to see)
    plain = ml.Problem(prob.H, prob.pos, FC).model(th[:1], mf[:1], mt[:1], np.ones(1))
    assert np.abs(plain - ref).max() > 0.03


def test_gradient_matches_central_differences_of_the_projected_cost(toy):
    prob, (th, mf, mt), _ = toy
    rng = np.random.default_rng(5)
    H = prob.H + 0.05 * (rng.standard_normal(prob.H.shape) + 1j * rng.standard_normal(prob.H.shape))
    prob = ml.WidebandProblem(H, prob.pos, FC, DF)
    x = flat(th + np.array([0.004, -0.003, 0.01]), mf + 0.01, mt - 0.02)
    ev = prob.evaluate(*unflat(x))
    steps = np.tile([1e-7, 1e-7, 1e-6, 1e-7, 1e-7], 2)
    fd = central_differences(
        lambda y: prob.evaluate(*unflat(y), derivatives=False)["cost"], x, steps
    )
    np.testing.assert_allclose(-2 * ev["g"], fd, rtol=2e-4, atol=1e-4 * np.abs(fd).max())


def test_gauss_newton_matrix_is_the_hessian_at_a_noiseless_optimum(toy):
    prob, truth, c = toy
    x = flat(*truth)
    ev = prob.evaluate(*truth)
    np.testing.assert_allclose(ev["c"], c, rtol=1e-10)
    assert ev["cost"] < 1e-12 * prob.h2
    steps = np.tile([1e-6, 1e-6, 1e-5, 1e-6, 1e-6], 2)
    hess = central_differences(lambda y: -2 * prob.evaluate(*unflat(y))["g"], x, steps)
    np.testing.assert_allclose(2 * ev["A"], hess, rtol=1e-4, atol=1e-5 * np.abs(hess).max())


@pytest.fixture(scope="module")
def route_epoch():
    """The 28 GHz example, 4 x 4 elements, one near epoch: paths, array, truth in the fit's
    parameters, the design's error model with the term."""
    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    ep = len(setup.trajectory.t) - 3
    ue, vel = setup.trajectory.position[ep], setup.trajectory.velocity[ep]
    arr = propagation.select_array(setup.arrays("4x4"), ue)
    paths = propagation.trace_paths(setup.tunnel, arr, ue, vel, fc=setup.fc, kinds=setup.kinds)
    truth = ml_truth(paths, arr, setup.config)
    return setup, arr, paths, truth


def test_the_model_is_the_channel_s_synthesis(route_epoch):
    """The wideband atoms at the true parameters and gains are the channel's tensor with the
    term (16 tones, 2 symbols)."""
    setup, arr, paths, truth = route_epoch
    cfg = setup.config
    H = channel_tensor(paths, cfg, n_tones=16, n_symbols=2, spatial_wideband=True)
    prob = ml.WidebandProblem(H, arr.local, cfg.fc, cfg.tone_spacing)
    c = np.sqrt(cfg.tx_power) * np.array([p.gain for p in paths])
    np.testing.assert_allclose(prob.model(*truth, c), H, rtol=1e-9, atol=1e-9 * np.abs(H).max())


def test_ml_truth_points_at_the_wave_origins_and_refuses_bad_input_by_name(route_epoch):
    """``(u_x, u_y, u_z) / w`` (``u_z > 0``: the origins face the array) is each path's VUE in
    the array's frame, ``mu_f`` / ``mu_t`` the phase steps of its length and Doppler; the test
    above checks the same values against the channel's synthesis."""
    setup, arr, paths, (th, mf, mt) = route_epoch
    cfg = setup.config
    uz = np.sqrt(1 - th[:, 0] ** 2 - th[:, 1] ** 2)
    origin = np.column_stack([th[:, :2], uz]) / th[:, 2:]
    np.testing.assert_allclose(arr.to_world(origin), [p.source for p in paths], atol=1e-9)
    tau = np.array([p.length for p in paths]) / C
    np.testing.assert_allclose(np.exp(1j * mf), np.exp(-2j * np.pi * cfg.tone_spacing * tau))
    dop = np.array([p.doppler for p in paths])
    np.testing.assert_allclose(np.exp(1j * mt), np.exp(2j * np.pi * cfg.symbol_period * dop))
    with pytest.raises(ValueError, match=r"^paths"):
        ml_truth([], arr, cfg)
    with pytest.raises(TypeError, match=r"^paths\[1\]"):
        ml_truth([paths[0], "los"], arr, cfg)
    with pytest.raises(TypeError, match=r"^paths"):
        ml_truth(paths[0], arr, cfg)
    with pytest.raises(TypeError, match=r"^array"):
        ml_truth(paths, arr.local, cfg)
    with pytest.raises(TypeError, match=r"^srs"):
        ml_truth(paths, arr, cfg.fc)


def test_the_wideband_fit_is_unbiased_where_eq1_s_is_not(route_epoch):
    """A noiseless wideband tensor (792 tones, 380 MHz): eq. 1's fit is off by many standard
    deviations (the design's bias), the wideband model's fit at the truth."""
    setup, arr, paths, truth = route_epoch
    cfg = setup.config
    H = channel_tensor(paths, cfg, spatial_wideband=True)
    sd = {}
    for wb in (False, True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            est = ml.ml_paths(
                H,
                len(paths),
                arr,
                cfg,
                start=truth,
                n_reseed=0,
                search="basic",
                noise_power=cfg.noise_power,
                wideband=wb,
            )
        d = np.sort([p.length for p in paths])
        sd[wb] = np.abs(np.sort(est.d) - d)
    crlb = path_error_model(setup, "4x4", DesignImpairments(), epochs=[len(setup.trajectory.t) - 3])
    d_sd = np.sqrt(np.diagonal(crlb.crlb[0])[3::4][crlb.exists[0]])
    assert np.max(sd[False] / np.min(d_sd)) > 10  # eq. 1: the delay to about the array's centre
    assert np.max(sd[True]) < 1e-3 * np.min(d_sd)


def test_bad_input_is_refused_by_name(toy):
    prob, truth, _ = toy
    with pytest.raises(ValueError, match=r"^tone_spacing"):
        ml.WidebandProblem(prob.H, prob.pos, FC, -1.0)
    with pytest.raises(TypeError, match=r"^wideband"):
        ml.ml_paths(prob.H, 2, prob.pos, SRS, start=truth, wideband="yes")
