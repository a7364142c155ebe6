"""The joint maximum-likelihood stage (tunnelkit.extraction.ml): derivatives, fixed points, efficiency."""

import warnings

import numpy as np
import pytest
from fd_helpers import central_differences, flat, unflat

from tunnelkit import arrays, channel, evaluation, extraction, signal_route
from tunnelkit.constants import C
from tunnelkit.extraction import ml
from tunnelkit.extraction.numerics import spatial_phase

FC = 5.9e9
LAM = C / FC
K0 = 2 * np.pi / LAM
SMALL = channel.SRSConfig(n_rb=20, comb=4, n_symbols=6)  # 60 tones x 6 symbols


def _scene(seed, n_paths=3, **kw):
    return evaluation.random_scene(np.random.default_rng(seed), n_paths, config=SMALL, **kw)


def _truth(sc):
    r = np.linalg.norm(sc.sources, axis=1)
    return np.column_stack([sc.sources[:, :2] / r[:, None], 1 / r]), sc.mu_f, sc.mu_t


def _args(sc):
    """The radio arguments ``(array, srs)`` of a scene."""
    return sc.element_positions, sc.config


# --- derivatives against central differences -------------------------------------------------


def test_spatial_phase_is_the_exact_spherical_phase():
    pos = arrays.ura(10, 10, LAM / 2)
    th = np.array([[0.3, -0.2, 1 / 4.0], [-0.5, 0.1, 1 / 30.0], [0.2, 0.6, 0.0]])
    psi = spatial_phase(th, pos, K0)[0]
    for j in range(2):
        uz = np.sqrt(1 - th[j, 0] ** 2 - th[j, 1] ** 2)
        q = np.array([th[j, 0], th[j, 1], uz]) / th[j, 2]
        exact = K0 * (np.linalg.norm(q - pos, axis=1) - np.linalg.norm(q))
        np.testing.assert_allclose(psi[:, j], exact, atol=1e-9)
    np.testing.assert_allclose(psi[:, 2], -K0 * pos[:, :2] @ th[2, :2], atol=1e-12)  # far field


@pytest.mark.parametrize("w", [1 / 3.0, 1 / 40.0, 0.0])
def test_spatial_phase_derivatives_match_central_differences(w):
    pos = arrays.ura(10, 10, LAM / 2)
    th = np.array([[0.31, -0.27, w]])
    _, dx, dy, dw = spatial_phase(th, pos, K0)
    for i, ana in enumerate((dx, dy, dw)):
        h = np.zeros((1, 3))
        h[0, i] = 1e-6
        fd = (spatial_phase(th + h, pos, K0)[0] - spatial_phase(th - h, pos, K0)[0]) / 2e-6
        np.testing.assert_allclose(ana, fd, rtol=1e-6, atol=1e-7 * np.abs(fd).max())


def test_varpro_gradient_matches_central_differences_of_the_projected_cost():
    """``Re <D_i, r>`` (Kaufman) is minus half the exact gradient of ``||P_perp h||^2``."""
    sc = _scene(11)
    H = sc.tensor(np.random.default_rng(1))
    prob = ml.Problem(H, sc.element_positions, FC)
    th, mf, mt = _truth(sc)
    th = th + np.array([0.01, -0.008, 0.02])  # away from the optimum: a gradient to see
    x = flat(th, mf + 0.01, mt - 0.02)
    ev = prob.evaluate(*unflat(x))
    steps = np.tile([1e-7, 1e-7, 1e-6, 1e-7, 1e-7], 3)
    fd = central_differences(
        lambda y: prob.evaluate(*unflat(y), derivatives=False)["cost"], x, steps
    )
    np.testing.assert_allclose(-2 * ev["g"], fd, rtol=2e-4, atol=1e-4 * np.abs(fd).max())


def test_gauss_newton_matrix_is_the_hessian_at_a_noiseless_optimum():
    """With ``r = 0`` the Golub-Pereyra and Kaufman Jacobians coincide: ``2 Re J^H J`` is the
    Hessian of the projected cost (central differences of the analytic gradient)."""
    sc = _scene(12, n_paths=2)
    H = sc.tensor()
    prob = ml.Problem(H, sc.element_positions, FC)
    x = flat(*_truth(sc))
    A = prob.evaluate(*unflat(x))["A"]
    steps = np.tile([1e-6, 1e-6, 1e-5, 1e-6, 1e-6], 2)
    hess = central_differences(lambda y: -2 * prob.evaluate(*unflat(y))["g"], x, steps)
    np.testing.assert_allclose(2 * A, hess, rtol=1e-4, atol=1e-5 * np.abs(hess).max())


def test_structured_bound_matches_a_finite_difference_fim_in_the_ml_parametrisation():
    """``source_crlb`` (direction, kappa, d, v) against the FIM of eq. 1 built by central
    differences in ``(Re c, Im c, u_x, u_y, w, mu_f, mu_t)`` per path, mapped by the delta
    method (kappa = 1/w, direction angle from ``(u_x, u_y)``)."""
    sc = _scene(13, n_paths=2)
    cfg = sc.config
    th0, mf0, mt0 = _truth(sc)
    s, k = np.arange(cfg.n_tones), np.arange(cfg.n_symbols)

    def model(x):
        x = x.reshape(-1, 7)
        a = np.exp(1j * spatial_phase(x[:, 2:5], sc.element_positions, K0)[0])
        f = np.exp(1j * s[:, None] * x[:, 5][None])
        t = np.exp(1j * k[:, None] * x[:, 6][None])
        return np.einsum("ml,sl,kl->msk", a * (x[:, 0] + 1j * x[:, 1]), f, t).ravel()

    x0 = np.column_stack([sc.alpha.real, sc.alpha.imag, th0, mf0, mt0]).ravel()
    steps = np.tile([1e-6 * np.abs(sc.alpha).max()] * 2 + [1e-7, 1e-7, 1e-6, 1e-7, 1e-7], 2)
    J = np.stack([(model(x0 + e) - model(x0 - e)) / (2 * e.max()) for e in np.diag(steps)], axis=1)
    fim = 2 / cfg.noise_power * np.real(J.conj().T @ J)
    dsc = 1 / np.sqrt(np.diag(fim))
    cov = dsc[:, None] * np.linalg.inv(dsc[:, None] * fim * dsc[None]) * dsc[None]
    b = sc.crlb()
    for j in range(2):
        i = 7 * j
        ux, uy, w = th0[j]
        uz = np.sqrt(1 - ux**2 - uy**2)
        Jd = np.array([[1, 0], [0, 1], [-ux / uz, -uy / uz]])  # d(u_x, u_y, u_z)/d(u_x, u_y)
        sd_dir = np.sqrt(np.trace(Jd @ cov[i + 2 : i + 4, i + 2 : i + 4] @ Jd.T))
        np.testing.assert_allclose(b["direction"][j], sd_dir, rtol=1e-3)
        np.testing.assert_allclose(b["kappa"][j], np.sqrt(cov[i + 4, i + 4]) / w**2, rtol=1e-3)
        sd_d = C / (2 * np.pi * cfg.tone_spacing) * np.sqrt(cov[i + 5, i + 5])
        sd_v = C / (2 * np.pi * cfg.fc * cfg.symbol_period) * np.sqrt(cov[i + 6, i + 6])
        np.testing.assert_allclose(b["d"][j], sd_d, rtol=1e-3)
        np.testing.assert_allclose(b["v"][j], sd_v, rtol=1e-3)
    free = sc.crlb(spatial="free")
    assert np.all(free["d"] >= b["d"] * (1 - 1e-9)) and np.all(free["v"] >= b["v"] * (1 - 1e-9))


# --- fixed points and efficiency -----------------------------------------------------------


def _normalized(est, sc):
    return evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, sc.crlb())


def test_started_at_the_truth_a_noiseless_fit_stays_there():
    sc = _scene(21)
    H = sc.tensor()
    pos, srs = _args(sc)
    est = ml.ml_paths(H, 3, pos, srs, start=_truth(sc), noise_power=sc.config.noise_power)
    err = _normalized(est, sc)
    assert np.all(np.abs(err) < 1e-3), err
    np.testing.assert_allclose(np.sort(np.abs(est.alpha)), np.sort(np.abs(sc.alpha)), rtol=1e-6)


def test_started_at_the_truth_a_noisy_fit_moves_by_the_bound_only():
    sc = _scene(22)
    H = sc.tensor(np.random.default_rng(5))
    pos, srs = _args(sc)
    est = ml.ml_paths(H, 3, pos, srs, start=_truth(sc))
    err = _normalized(est, sc)
    assert np.all(np.abs(err) < 4.0), err
    assert abs(est.fit.rho - 1) < 0.05 and est.fit.rho <= est.fit.rho_max


def test_default_route_is_efficient_on_random_near_field_scenes():
    """20 seeded snapshots of 2-3 source scenes 2-8 m from a 10 x 10 URA, default extraction
    (CPD, coherent split, ML): RMS(error / CRLB) < 2.5 for every parameter, none missed."""
    errs = []
    for seed in range(20):
        rng = np.random.default_rng(1000 + seed)
        sc = evaluation.random_scene(rng, 2 + seed % 2, config=SMALL)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            est = extraction.extract_paths(sc.tensor(rng), len(sc.d), *_args(sc))
        errs.append(_normalized(est, sc))
    e = np.concatenate(errs)
    assert np.all(np.isfinite(e)), "a path was missed"
    rms = np.sqrt(np.mean(e**2, axis=0))
    assert np.all(rms < 2.5), rms


@pytest.fixture(scope="module")
def javelin_epoch():
    """Straight drive, x = 38 m (epoch 5): LoS, ceiling, road and two RRMs within 0.8 m and
    0.35 m/s of each other; the LoS/ceiling pair shares one delay-Doppler bin."""
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ep = route.epoch(5, np.random.default_rng(1))
    return route, ep


def test_javelin_epoch_resolves_los_and_ceiling_at_the_bound(javelin_epoch):
    route, ep = javelin_epoch
    assert ep.estimates.fit is not None  # the default route is the ML one
    src = np.stack([ep.array.to_local(p.source) for p in ep.paths])
    d_true = np.array([p.length for p in ep.paths]) + C * ep.snapshot.clock_bias
    v_true = np.array([p.velocity for p in ep.paths])
    bound = extraction.path_crlb(ep.paths, ep.array, route.config)
    err = evaluation.normalized_errors(ep.estimates, d_true, v_true, src, bound)
    kinds = [p.surface_kind for p in ep.paths]
    assert {"los", "ceiling"} <= set(kinds)
    assert np.all(np.abs(err) < 5.0), dict(zip(kinds, err.round(2).tolist()))
    # the bound itself at 38 m: direction to thousandths of a degree, kappa to decimetres
    assert np.all(np.degrees(bound["direction"]) < 0.01) and np.all(bound["kappa"] < 0.5)
    assert ep.estimates.fit.rho <= ep.estimates.fit.rho_max
    assert len(ep.measurements) == len(ep.paths) and np.all(np.isfinite(ep.measurements.kappa))


# --- bad input -----------------------------------------------------------------------------


def test_bad_input_is_refused_by_name():
    sc = _scene(31, n_paths=2)
    H = sc.tensor(np.random.default_rng(0))
    pos, srs = _args(sc)
    th, mf, mt = _truth(sc)
    with pytest.raises(ValueError, match="start"):
        ml.ml_paths(H, 2, pos, srs, start=(th + np.array([0.9, 0.9, 0]), mf, mt))  # |u| > 1
    with pytest.raises(ValueError, match="start"):
        ml.ml_paths(H, 2, pos, srs, start=(th * [1, 1, -1], mf, mt))  # behind the array
    with pytest.raises(ValueError, match="start"):
        ml.ml_paths(H, 2, pos, srs, start=(th[:1], mf[:1], mt[:1]))
    bad = H.copy()
    bad[3, 4, 1] = np.nan
    with pytest.raises(ValueError, match="H"):
        extraction.extract_paths(bad, 2, pos, srs)
    dup = pos.copy()
    dup[5] = dup[6]
    with pytest.raises(ValueError, match="array"):
        extraction.extract_paths(H, 2, dup, srs)
    with pytest.raises(TypeError, match="srs"):
        ml.ml_paths(H, 2, pos, srs.fc)
    with pytest.raises(TypeError, match="srs"):
        ml.fit_ml(H, (th, mf, mt), pos, srs.fc)
    with pytest.raises(ValueError, match="array"):
        ml.fit_ml(H, (th, mf, mt), pos[:10], srs)
    with pytest.raises(ValueError, match="n_paths"):
        extraction.extract_paths(H, 500, pos, srs)
    with pytest.raises(ValueError, match="n_paths"):
        ml.ml_paths(H[:4, :6, :6], 4, pos[:4], srs)  # as many paths as antennas
    with pytest.raises(ValueError, match="noise_power"):
        extraction.extract_paths(H, 2, pos, srs, noise_power=-1.0)
    with pytest.raises(ValueError, match="noise_power"):
        extraction.extract_paths(H, 2, pos, srs, refine="joint", noise_power=1.0)


def test_pure_noise_warns_and_marks_every_path_invalid():
    rng = np.random.default_rng(7)
    pos = arrays.ura(10, 10, LAM / 2)
    H = channel.add_noise(np.zeros((100, SMALL.n_tones, SMALL.n_symbols)), 1.0, rng)
    with pytest.warns(ml.MLDetectionWarning, match="0 of n_paths = 3"):
        est = extraction.extract_paths(H, 3, pos, SMALL)
    assert not np.any(est.valid) and np.all(np.isfinite(est.d))
    assert abs(est.fit.noise_power - 1.0) < 0.05
    assert len(signal_route.measurements_from_estimates(est, _array())) == 0


def test_too_many_paths_for_the_scene_are_flagged_not_invented():
    sc = _scene(41, n_paths=2, snr_db=(0.0, 5.0))
    H = sc.tensor(np.random.default_rng(3))
    with pytest.warns(ml.MLDetectionWarning, match="2 of n_paths = 4"):
        est = extraction.extract_paths(H, 4, *_args(sc))
    assert est.valid.sum() == 2
    err = evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, sc.crlb())
    assert np.all(np.abs(err) < 5.0), err


def test_a_failed_fit_keeps_its_start_and_warns(monkeypatch):
    sc = _scene(51, n_paths=2)
    H = sc.tensor(np.random.default_rng(2))
    pos, srs = _args(sc)
    start = _truth(sc)

    def worse(prob, theta, mu_f, mu_t, sigma2, max_iter):  # a stage that only makes it worse
        th = theta.copy()
        th[:, 0] = -th[:, 0]
        ev = prob.evaluate(th, mu_f, mu_t)
        return th, mu_f, mu_t, ev, 1, False

    monkeypatch.setattr(ml.fitting, "_lm", worse)
    with pytest.warns(ml.MLConvergenceWarning):
        fit = ml.fit_ml(H, start, pos, srs, n_reseed=0)
    np.testing.assert_allclose(fit.theta, start[0])
    assert np.all(np.isfinite(fit.alpha))


def _array():
    return signal_route.SignalRoute.from_scenario("italiano2026-straight").arrays[0]


def test_too_few_paths_fail_the_basin_test_and_warn():
    """Three strong sources fitted with n_paths = 2: the residual keeps the third one."""
    sc = _scene(61, n_paths=3, snr_db=(0.0, 5.0))
    H = sc.tensor(np.random.default_rng(4))
    with pytest.warns(ml.MLConvergenceWarning, match="noise floor"):
        est = extraction.extract_paths(H, 2, *_args(sc))
    assert est.fit.rho > est.fit.rho_max and np.all(np.isfinite(est.d))


def test_reseeding_recovers_a_path_counted_twice():
    """Started with one source counted twice and another missing, the local fit stays in that
    basin (residual far above the noise floor); the re-seeding finds the missing source."""
    sc = _scene(71, n_paths=3, snr_db=(0.0, 5.0))
    H = sc.tensor(np.random.default_rng(8))
    pos, srs = _args(sc)
    th, mf, mt = _truth(sc)
    th_bad, mf_bad, mt_bad = th.copy(), mf.copy(), mt.copy()
    th_bad[2], mf_bad[2], mt_bad[2] = th[1] + [0.004, 0.0, 0.0], mf[1], mt[1]
    with pytest.warns(ml.MLConvergenceWarning, match="noise floor"):
        local = ml.fit_ml(H, (th_bad, mf_bad, mt_bad), pos, srs, n_reseed=0)
    assert local.rho > local.rho_max
    fit = ml.fit_ml(H, (th_bad, mf_bad, mt_bad), pos, srs)
    assert fit.rho <= fit.rho_max and fit.n_reseed >= 1
    est = ml.estimates_from_fit(fit, pos, srs, SMALL.n_tones, SMALL.n_symbols, 0.0)
    err = evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, sc.crlb())
    assert np.all(np.abs(err) < 5.0), err
