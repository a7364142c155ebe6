"""The residual test of the ML stage (fit_ok), the re-initialisation on the residual,
the bounds at the SNR used, the feasible set to end-fire, caps and physically possible paths."""

import warnings
from dataclasses import replace

import numpy as np
import pytest

from tunnelkit import arrays, channel, evaluation, extraction, signal_route
from tunnelkit.constants import C
from tunnelkit.extraction import ml
from tunnelkit.extraction.ml import residual

FC = 5.9e9
LAM = C / FC
SMALL = channel.SRSConfig(n_rb=20, comb=4, n_symbols=6)  # 60 tones x 6 symbols


def _scene(seed, n_paths=3, **kw):
    return evaluation.random_scene(np.random.default_rng(seed), n_paths, config=SMALL, **kw)


def _truth(sc):
    r = np.linalg.norm(sc.sources, axis=1)
    return np.column_stack([sc.sources[:, :2] / r[:, None], 1 / r]), sc.mu_f, sc.mu_t


def test_peak_threshold_is_the_quantile_of_the_largest_of_k_exponentials():
    """Closed form against brute force: the largest of K unit exponentials exceeds the threshold
    with the stated probability."""
    n, pfa = 50, 0.1
    t = residual.peak_threshold(n, pfa)
    K = int(residual.OVERSAMPLING_CELLS * n)
    rng = np.random.default_rng(0)
    mx = rng.exponential(size=(20000, K)).max(axis=1)
    assert abs(np.mean(mx > t) - pfa) < 0.012
    assert residual.peak_threshold(10**6, 0.01) > residual.peak_threshold(10**3, 0.01)
    with pytest.raises(ValueError, match="false_alarm"):
        residual.peak_threshold(100, 1.0)
    with pytest.raises(ValueError, match="n_samples"):
        residual.peak_threshold(0)


def test_residual_peak_of_one_atom_is_its_energy_over_the_noise_and_finds_it():
    """A far-field atom on the grid of the test: the peak is |c|^2 N / sigma^2 (exact), at its
    direction, delay and Doppler."""
    pos = arrays.ura(4, 4, LAM / 2)
    nf, nt = 32, 6
    u = np.array([0.3, -0.2])
    mf, mt = 2 * np.pi * 5 / (2 * nf), -2 * np.pi * 2 / (2 * nt)
    a = np.exp(-1j * 2 * np.pi / LAM * (pos[:, :2] @ u))
    X = np.einsum("m,s,k->msk", a, np.exp(1j * np.arange(nf) * mf), np.exp(1j * np.arange(nt) * mt))
    c, sigma2 = 0.7 - 0.2j, 0.05
    peak, loc, x = residual.residual_peak(c * X, pos, FC, sigma2)
    # the grid point nearest to u (the scan grid's step is 1/30); brute-force inner product there
    ug, A = extraction.numerics.scan_grid(pos, FC)
    g = int(np.argmin(np.linalg.norm(ug - u, axis=1)))
    brute = abs(np.vdot(A[:, g], (c * X).reshape(16, -1) @ np.conj(X[0].ravel()))) ** 2
    assert peak == pytest.approx(brute / (X.size * sigma2), rel=1e-5)
    assert peak == pytest.approx(abs(c) ** 2 * X.size / sigma2, rel=0.05)
    np.testing.assert_allclose(loc[:2], ug[g])
    assert loc[2] == pytest.approx(mf) and loc[3] == pytest.approx(mt)
    assert x.shape == (16,)


def test_residual_peak_of_noise_stays_below_the_threshold_at_the_stated_rate():
    """Calibration of OVERSAMPLING_CELLS: noise alone exceeds the threshold at no more than the
    stated false-alarm rate (binomial allowance for 300 draws)."""
    rng = np.random.default_rng(3)
    pos = arrays.ura(4, 4, LAM / 2)
    shape = (16, 32, 6)
    thr = residual.peak_threshold(int(np.prod(shape)), 0.05)
    peaks = [
        residual.residual_peak(channel.add_noise(np.zeros(shape), 1.0, rng), pos, FC, 1.0)[0]
        for _ in range(300)
    ]
    assert np.mean(np.array(peaks) > thr) <= 0.05 + 2.5 * np.sqrt(0.05 * 0.95 / 300)
    assert np.median(peaks) > 5.0  # not a test that cannot fail: the statistic is not tiny


def test_residual_peak_refuses_bad_input_by_name():
    pos = arrays.ura(4, 4, LAM / 2)
    R = np.zeros((16, 8, 4), complex)
    with pytest.raises(ValueError, match="R"):
        residual.residual_peak(R.real, pos, FC, 1.0)
    with pytest.raises(ValueError, match="element_positions"):
        residual.residual_peak(R, pos[:4], FC, 1.0)
    with pytest.raises(ValueError, match="noise_power"):
        residual.residual_peak(R, pos, FC, 0.0)
    with pytest.raises(ValueError, match="n_cells"):
        residual.residual_peak(R, pos, FC, 1.0, n_cells=0)


def test_a_wrong_basin_is_flagged_and_the_search_leaves_it():
    """Started with one source counted twice and another missing, the local fit stays there:
    the residual test flags it (fit_ok False) even with no re-seeding; the default search
    re-initialises on the residual's peak, finds the missing source and passes the test."""
    sc = _scene(71, n_paths=3, snr_db=(0.0, 5.0))
    H = sc.tensor(np.random.default_rng(8))
    pos, srs = sc.element_positions, sc.config
    th, mf, mt = _truth(sc)
    th_bad, mf_bad, mt_bad = th.copy(), mf.copy(), mt.copy()
    th_bad[2], mf_bad[2], mt_bad[2] = th[1] + [0.004, 0.0, 0.0], mf[1], mt[1]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ml.MLConvergenceWarning)
        local = ml.fit_ml(H, (th_bad, mf_bad, mt_bad), pos, srs, n_reseed=0)
    assert not local.fit_ok and local.peak > local.peak_max
    fit = ml.fit_ml(H, (th_bad, mf_bad, mt_bad), pos, srs, n_reseed=3, search="residual")
    assert fit.fit_ok and fit.peak <= fit.peak_max and fit.rho <= fit.rho_max
    est = ml.estimates_from_fit(fit, pos, srs, SMALL.n_tones, SMALL.n_symbols, 0.0)
    assert est.fit_ok is True
    err = evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, sc.crlb())
    assert np.all(np.abs(err) < 5.0), err


def test_a_right_fit_passes_and_a_missed_path_is_flagged():
    sc = _scene(11, n_paths=3, snr_db=(0.0, 10.0))
    H = sc.tensor(np.random.default_rng(5))
    est = extraction.extract_paths(H, 3, sc.element_positions, sc.config)
    assert est.fit_ok is True and est.fit.peak < est.fit.peak_max
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ml.MLConvergenceWarning)
        two = extraction.extract_paths(H, 2, sc.element_positions, sc.config)
    assert two.fit_ok is False and two.fit.peak > 10 * two.fit.peak_max
    assert (
        extraction.extract_paths(H, 3, sc.element_positions, sc.config, refine="joint").fit_ok
        is None
    )


def test_a_path_near_end_fire_is_inside_the_feasible_set():
    """A source at u_z = 0.011 (|u| = 0.99994, outside the former |u| <= 0.999): found at the
    bound, not pinned to the edge of the feasible set."""
    rng = np.random.default_rng(2)
    sc = _scene(5, n_paths=2, snr_db=(5.0, 10.0))
    src = sc.sources.copy()
    uz = 0.011
    src[1] = 5.0 * np.array([np.sqrt(1 - uz**2), 0.0, uz])
    sc = replace(sc, sources=src)
    est = extraction.extract_paths(sc.tensor(rng), 2, sc.element_positions, sc.config)
    assert est.fit_ok
    err = evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, sc.crlb())
    assert np.all(np.abs(err) < 5.0), err
    assert ml.model.U_MAX > np.sqrt(1 - uz**2)


def test_path_crlb_takes_the_snr_actually_used():
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    arr, paths = route.paths(10)
    b0 = extraction.path_crlb(paths, arr, route.config)
    b = extraction.path_crlb(paths, arr, route.config, snr_offset_db=-20.0)
    for key in ("d", "v", "direction", "kappa"):
        np.testing.assert_allclose(b[key], 10.0 * b0[key], rtol=1e-6)
    with pytest.raises(ValueError, match="snr_offset_db"):
        extraction.path_crlb(paths, arr, route.config, snr_offset_db=np.nan)
    # the same SNR as the synthesis: the noise power of a snapshot at that offset
    snap = channel.synthesize(paths, route.config, np.random.default_rng(0), snr_offset_db=-20.0)
    assert snap.noise_power == pytest.approx(route.config.noise_power * 100.0)


def test_iteration_caps_and_search_are_checked_by_name():
    sc = _scene(31, n_paths=2)
    H = sc.tensor(np.random.default_rng(0))
    pos, srs = sc.element_positions, sc.config
    with pytest.raises(ValueError, match="max_iter"):
        ml.ml_paths(H, 2, pos, srs, max_iter=10**7)
    with pytest.raises(ValueError, match="n_reseed"):
        ml.ml_paths(H, 2, pos, srs, n_reseed=10**7)
    with pytest.raises(ValueError, match="max_iter"):
        ml.fit_ml(H, _truth(sc), pos, srs, max_iter=10**7)
    with pytest.raises(ValueError, match="polish"):
        extraction.extract_paths(H, 2, pos, srs, refine="joint", polish=10**7)
    with pytest.raises(ValueError, match="n_iter_max"):
        extraction.extract_paths(H, 2, pos, srs, refine="joint", n_iter_max=10**7)
    with pytest.raises(ValueError, match="search"):
        extraction.extract_paths(H, 2, pos, srs, search="fast")
    with pytest.raises(ValueError, match="search"):
        extraction.extract_paths(H, 2, pos, srs, refine="joint", search="basic")
    with pytest.raises(ValueError, match="search"):
        ml.fit_ml(H, _truth(sc), pos, srs, search="x")
    # radios outside the physical ranges never reach the extraction: refused where they enter
    with pytest.raises(ValueError, match=r"^fc: expected 1e\+08 to 3e\+11 Hz"):
        channel.SRSConfig(scs=1e300, bandwidth=1e305, fc=1e306)  # T0 = 1e-300 s
    with pytest.raises(ValueError, match=r"^fc: expected 1e\+08 to 3e\+11 Hz"):
        channel.SRSConfig(scs=1e11, bandwidth=1.5e12, fc=9e11, n_rb=1, comb=1)


def test_a_physically_impossible_path_is_never_valid():
    sc = _scene(21, n_paths=2, snr_db=(5.0, 10.0))
    est = extraction.extract_paths(
        sc.tensor(np.random.default_rng(1)), 2, sc.element_positions, sc.config
    )
    ok = ml.physical(est, sc.config)
    assert ok.all()
    # marked valid, a path faster than light or from behind the array is refused outright
    with pytest.raises(ValueError, match=r"^valid: path 1 is marked valid but is not physical"):
        replace(est, v=est.v + np.array([0.0, 2 * C]))
    fast = replace(est, v=est.v + np.array([0.0, 2 * C]), valid=np.array([True, False]))
    np.testing.assert_array_equal(ml.physical(fast, sc.config), [True, False])
    np.testing.assert_array_equal(fast.physical(), [True, False])
    behind = est.direction.copy()
    behind[0, 2] = -behind[0, 2]
    with pytest.raises(ValueError, match=r"^valid: path 0 "):
        replace(est, direction=behind)
    np.testing.assert_array_equal(
        ml.physical(replace(est, direction=behind, valid=np.array([False, True])), sc.config),
        [False, True],
    )
    close = replace(est, kappa=np.array([0.1, est.kappa[1]]))
    assert not ml.physical(close, sc.config)[0]
    with pytest.raises(TypeError, match="srs"):
        ml.physical(est, 5.9e9)


def test_the_drive_adapter_drops_a_flagged_epoch():
    from tunnelkit import simulation

    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ep = route.epoch(10, np.random.default_rng(0))
    assert ep.estimates.fit_ok is True
    pm, why = simulation.path_measurements(ep, route)
    assert pm is not None and why is None
    flagged = replace(ep, estimates=replace(ep.estimates, fit_ok=False))
    pm, why = simulation.path_measurements(flagged, route)
    assert pm is None and why == simulation.drives.FLAGGED


def test_mie_threshold_is_where_a_noise_cell_beats_the_path_half_the_time():
    """Brute force: K unit exponentials (noise cells) against the path's cell |sqrt(eta) + n|^2
    (n ~ CN(0, 1)) at eta = the threshold: the path loses about half the time."""
    from tunnelkit import efficiency

    K = 300
    eta = 10 ** (efficiency.mie_threshold_db(K) / 10)
    assert eta == pytest.approx(np.log(2 * K))
    rng = np.random.default_rng(0)
    n = (rng.standard_normal(4000) + 1j * rng.standard_normal(4000)) / np.sqrt(2)
    path = np.abs(np.sqrt(eta) + n) ** 2
    noise = rng.exponential(size=(4000, K)).max(axis=1)
    assert 0.2 < np.mean(noise > path) < 0.6
    with pytest.raises(ValueError, match="n_cells"):
        efficiency.mie_threshold_db(0)


def test_bound_errors_assign_clustered_paths_by_the_bound():
    sc = _scene(9, n_paths=2, snr_db=(5.0, 10.0))
    est = extraction.extract_paths(
        sc.tensor(np.random.default_rng(4)), 2, sc.element_positions, sc.config
    )
    b = sc.crlb()
    e = evaluation.bound_errors(est, sc.d, sc.v, sc.sources, b)
    assert e.shape == (2, 4) and np.all(np.abs(e) < 5.0)
    # the truth moved by exactly 2 sigma in d: the error column reads -2 more
    e2 = evaluation.bound_errors(est, sc.d + 2 * b["d"], sc.v, sc.sources, b)
    np.testing.assert_allclose(e2[:, 0], e[:, 0] - 2.0, atol=1e-9)
    none = replace(est, significance=np.zeros(2))
    assert np.all(np.isinf(evaluation.bound_errors(none, sc.d, sc.v, sc.sources, b)))


def test_threshold_study_finds_the_bound_above_and_flags_below():
    from tunnelkit import efficiency

    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    cfg = replace(route.config, n_rb=10, comb=4)
    los = signal_route.SignalRoute(
        route.tunnel, route.arrays, route.trajectory, cfg, kinds=("los",)
    )
    arr, paths = los.paths(12)
    N = arr.M * cfg.n_tones * cfg.n_symbols
    eta0 = 10 * np.log10(abs(paths[0].gain) ** 2 * cfg.tx_power * N / cfg.noise_power)
    th = efficiency.mie_threshold_db(N)
    rows = efficiency.threshold_study(los, [12], [th + 20 - eta0, th - 8 - eta0], 3, seed=1)
    hi, lo = rows
    assert hi["integrated SNR [dB]"] == pytest.approx(th + 20)
    assert hi["beyond 6 sigma"] == 0.0 and hi["RMS/CRLB direction"] < 3.0 and hi["flagged"] == 0
    assert lo["beyond 6 sigma"] == 1.0 and lo["flagged"] == 1.0
    with pytest.raises(ValueError, match="snr_offsets_db"):
        efficiency.threshold_study(los, [12], [np.nan], 1, seed=1)
    with pytest.raises(ValueError, match="n_snapshots"):
        efficiency.threshold_study(los, [12], [0.0], 0, seed=1)


def test_a_merged_pair_at_long_range_is_split_toward_the_residual_peak():
    """At 103 m on the straight drive the LoS and the ceiling image are a quarter beamwidth and
    centimetres apart. On these two noise draws the search used to end with the two fitted as
    one and the road image counted twice (residual peak ~1,250 noise powers, flagged): the
    residual's peak lies beyond the merged path on the side of the missing one, and the split
    along that line reaches the basin of the truth (the cost of the fit started at the truth)
    with every parameter within 5 sigma of its bound."""
    from tunnelkit import scenarios

    sc = scenarios.with_values(
        scenarios.load_scenario("italiano2026-straight"),
        {"tunnel.length": 300.0, "trajectory.x_start": 122.0, "trajectory.x_end": 0.5},
    )
    route = signal_route.SignalRoute.from_scenario(sc)
    arr, paths = route.paths(14)
    assert len(paths) == 3 and 100.0 < np.linalg.norm(paths[0].source - arr.origin) < 105.0
    cfg = route.config
    src = np.stack([arr.to_local(p.source) for p in paths])
    r = np.linalg.norm(src, axis=1)
    th = np.column_stack([src[:, :2] / r[:, None], 1 / r])
    assert np.linalg.norm(th[0, :2] - th[1, :2]) < 0.06  # a quarter of the 10 x 10 beamwidth
    bound = extraction.path_crlb(paths, arr, cfg)
    for seed in (2, 7):
        snap = route.snapshot(paths, arr, np.random.default_rng(seed))
        d = np.array([p.length for p in paths]) + C * snap.clock_bias
        v = np.array([p.velocity for p in paths])
        mf = -2 * np.pi * cfg.tone_spacing * d / C
        mt = 2 * np.pi * cfg.fc * cfg.symbol_period * v / C
        est = extraction.extract_paths(snap.H, 3, arr, cfg)
        at_truth = ml.fit_problem(ml.Problem(snap.H, arr.local, cfg.fc), (th, mf, mt), n_reseed=0)
        assert est.fit_ok
        assert est.fit.cost <= at_truth.cost + at_truth.noise_power
        err = evaluation.bound_errors(est, d, v, src, bound)
        assert np.all(np.abs(err) < 5.0), err


def test_calibrated_threshold_holds_its_false_alarm_rate_on_noise_only_residuals():
    """The GLRT of one path more at a stated false-alarm rate, calibrated by simulation
    (``residual.calibrated_threshold``): fresh noise-only tensors (a generator the calibration
    never saw) exceed it at the stated rate, within the binomial 99 % interval of 400 draws."""
    pos = arrays.ura(4, 4, LAM / 2)
    shape = (16, 32, 6)
    pfa = 0.1
    thr = residual.calibrated_threshold(pos, FC, shape, pfa)
    rng = np.random.default_rng(12345)
    n = 400
    peaks = np.array(
        [
            residual.residual_peak(channel.add_noise(np.zeros(shape), 1.0, rng), pos, FC, 1.0)[0]
            for _ in range(n)
        ]
    )
    half = 2.58 * np.sqrt(pfa * (1 - pfa) / n)
    assert abs(np.mean(peaks > thr) - pfa) < half
    assert residual.calibrated_threshold(pos, FC, shape, 0.01) > thr
    with pytest.raises(ValueError, match="false_alarm"):
        residual.calibrated_threshold(pos, FC, shape, 0.5)
    with pytest.raises(TypeError, match="rng"):
        residual.peak_null(pos, FC, shape, 0)
    with pytest.raises(ValueError, match="shape"):
        residual.peak_null(pos, FC, (16, 32), np.random.default_rng(0))
    with pytest.raises(ValueError, match="n_draws"):
        residual.peak_null(pos, FC, shape, np.random.default_rng(0), n_draws=1)


def test_pair_separation_is_the_mahalanobis_distance_of_the_difference_and_flags_a_pair():
    """Brute force: the distance of each pair from the inverse Fisher information computed from
    a finite-difference Jacobian of the model tensor; two sources closer than their bound can
    resolve are flagged ``unresolved pair``, the same sources far apart are not."""
    sc = _scene(41, n_paths=2, snr_db=(5.0, 10.0))
    H = sc.tensor(np.random.default_rng(3))
    pos, srs = sc.element_positions, sc.config
    prob = ml.Problem(H, pos, srs.fc)
    th, mf, mt = _truth(sc)
    sigma2 = 0.7
    sep = ml.pair_separation(prob, th, mf, mt, sigma2)
    # finite-difference Jacobian of the residual r(theta) = P_perp h over the 10 parameters
    x0 = np.column_stack([th, mf, mt]).ravel()

    def resid(x):
        x = x.reshape(2, 5)
        ev = prob.evaluate(x[:, :3], x[:, 3], x[:, 4], derivatives=False)
        return (H - prob.model(x[:, :3], x[:, 3], x[:, 4], ev["c"])).ravel()

    h = 1e-7
    J = np.stack([(resid(x0 + h * e) - resid(x0 - h * e)) / (2 * h) for e in np.eye(10)], 1)
    cov = np.linalg.inv(2 * np.real(J.conj().T @ J) / sigma2)
    D = x0[:5] - x0[5:]
    S = cov[:5, :5] + cov[5:, 5:] - cov[:5, 5:] - cov[5:, :5]
    assert sep == pytest.approx(np.sqrt(D @ np.linalg.solve(S, D)), rel=1e-3)
    assert ml.pair_separation(prob, th[:1], mf[:1], mt[:1], sigma2) == np.inf
    # the second source moved onto the first (a fortieth of a beamwidth, same delay/Doppler)
    src = sc.sources.copy()
    r0 = np.linalg.norm(src[0])
    u = src[0, :2] / r0 + [0.005, 0.0]
    src[1] = r0 * np.append(u, np.sqrt(1 - u @ u))
    close = replace(sc, sources=src, d=np.array([sc.d[0], sc.d[0]]), v=np.array([sc.v[0]] * 2))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(close.tensor(np.random.default_rng(3)), 2, pos, srs)
        far = extraction.extract_paths(H, 2, pos, srs)
    assert est.fit_ok is False and "unresolved pair" in est.fit.reason
    assert est.fit.separation < ml.fitting.RESOLVE_Z
    assert far.fit_ok is True and far.fit.reason == "" and far.fit.separation > 50.0
    assert far.fit.detected.all()
    with pytest.raises(TypeError, match="prob"):
        ml.pair_separation(H, th, mf, mt, sigma2)
    with pytest.raises(ValueError, match="noise_power"):
        ml.pair_separation(prob, th, mf, mt, 0.0)


def test_ml_order_adds_paths_while_the_residual_holds_one():
    """The GLRT per added path: three sources well above the noise give three paths; the same
    scene without its weakest source gives two; noise alone stops at the first path (not
    detected)."""
    sc = _scene(11, n_paths=3, snr_db=(0.0, 10.0))
    pos, srs = sc.element_positions, sc.config
    est = ml.ml_order(sc.tensor(np.random.default_rng(5)), pos, srs, max_paths=5)
    assert len(est) == 3 and est.fit_ok
    weak = int(np.argmin(np.abs(sc.alpha)))
    keep = np.arange(3) != weak
    two = replace(sc, sources=sc.sources[keep], d=sc.d[keep], v=sc.v[keep], alpha=sc.alpha[keep])
    assert len(ml.ml_order(two.tensor(np.random.default_rng(5)), pos, srs, max_paths=5)) == 2
    shape = sc.tensor().shape
    noise = channel.add_noise(np.zeros(shape), srs.noise_power, np.random.default_rng(2))
    one = ml.ml_order(noise, pos, srs, max_paths=3)
    assert len(one) == 1 and not one.fit.detected.any()
    with pytest.raises(ValueError, match="max_paths"):
        ml.ml_order(noise, pos, srs, max_paths=0)
    with pytest.raises(TypeError, match="n_paths"):
        ml.ml_order(noise, pos, srs, n_paths=2)


def test_separations_per_path_against_a_finite_difference_fisher_information_and_resolvable():
    """Brute force: each path's smallest Mahalanobis distance to another from the inverse Fisher
    information of a finite-difference Jacobian (three paths, 15 parameters); ``resolvable``
    drops a path whose gain is scaled to the noise and a path moved onto another; the
    estimates carry the fit's per-path ``resolution`` sorted like their delays."""
    sc = _scene(43, n_paths=3, snr_db=(5.0, 10.0))
    H = sc.tensor(np.random.default_rng(4))
    pos, srs = sc.element_positions, sc.config
    prob = ml.Problem(H, pos, srs.fc)
    th, mf, mt = _truth(sc)
    sigma2 = prob.noise_floor(3)
    z = ml.separations(prob, th, mf, mt, sigma2)
    x0 = np.column_stack([th, mf, mt]).ravel()

    def resid(x):
        x = x.reshape(3, 5)
        ev = prob.evaluate(x[:, :3], x[:, 3], x[:, 4], derivatives=False)
        return (H - prob.model(x[:, :3], x[:, 3], x[:, 4], ev["c"])).ravel()

    h = 1e-7
    J = np.stack([(resid(x0 + h * e) - resid(x0 - h * e)) / (2 * h) for e in np.eye(15)], 1)
    cov = np.linalg.inv(2 * np.real(J.conj().T @ J) / sigma2)
    want = np.full(3, np.inf)
    for i in range(3):
        for j in range(3):
            if i != j:
                a, b = slice(5 * i, 5 * i + 5), slice(5 * j, 5 * j + 5)
                D = x0[a] - x0[b]
                S = cov[a, a] + cov[b, b] - cov[a, b] - cov[b, a]
                want[i] = min(want[i], np.sqrt(D @ np.linalg.solve(S, D)))
    np.testing.assert_allclose(z, want, rtol=1e-3)
    assert ml.pair_separation(prob, th, mf, mt, sigma2) == pytest.approx(want.min(), rel=1e-3)
    sig = ml.resolution.significance(prob.evaluate(th, mf, mt), sigma2)
    assert ml.resolvable(prob, th, mf, mt, sigma2, detect=20.0).all() and sig.min() > 20.0
    # a detection threshold above the weakest path's log-likelihood ratio: that path only
    weak = ml.resolvable(prob, th, mf, mt, sigma2, detect=float(np.sort(sig)[1]) - 1e-9)
    assert list(weak) == list(sig >= np.sort(sig)[1] - 1e-9) and weak.sum() == 2
    th2, mf2, mt2 = th.copy(), mf.copy(), mt.copy()
    th2[1, :2] = th[0, :2] + [0.002, 0.0]
    th2[1, 2], mf2[1], mt2[1] = th[0, 2], mf[0], mt[0]
    near = ml.resolvable(prob, th2, mf2, mt2, sigma2, detect=1e-9)
    assert not near[0] and not near[1] and near[2]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(H, 3, pos, srs)
    o = np.argsort(-est.fit.mu_f)  # the estimates are sorted by d = -c mu_f / (2 pi Df)
    np.testing.assert_array_equal(est.resolution, est.fit.resolution[o])
    assert est.resolution.min() == est.fit.separation
    with pytest.raises(ValueError, match="detect"):
        ml.resolvable(prob, th, mf, mt, sigma2, detect=0.0)
    with pytest.raises(TypeError, match="prob"):
        ml.separations(H, th, mf, mt, sigma2)


def test_split_weak_recovers_a_merged_pair_from_a_path_below_the_noise():
    """Two sources 0.03 apart in direction cosine (a seventh of a beamwidth) fitted as one
    strong path plus a path on nothing (below the noise): the split move drops the weak path, splits the strong one and
    finds both sources (cost down by more than the detection threshold); a fit with every path
    above the noise is left alone."""
    sc = _scene(47, n_paths=2, snr_db=(20.0, 25.0))
    src = sc.sources.copy()
    r0 = np.linalg.norm(src[0])
    u = src[0, :2] / r0 + [0.03, 0.0]
    src[1] = r0 * np.append(u, np.sqrt(1 - u @ u))
    pair = replace(sc, sources=src, d=np.array([sc.d[0], sc.d[0] + 0.05]), v=sc.v[[0, 0]])
    H = pair.tensor(np.random.default_rng(5))
    prob = ml.Problem(H, pair.element_positions, pair.config.fc)
    th, mf, mt = _truth(pair)
    sigma2 = prob.noise_floor(2)
    # the pair merged into one path at its centre, the other path far from both
    th0 = np.vstack([np.append(th[:, :2].mean(0), th[0, 2]), [-0.5, -0.5, 0.1]])
    start = (th0, np.array([mf.mean(), -2.0]), np.array([mt.mean(), -0.5]))
    best = ml.fitting._lm(prob, *start, sigma2, 60)
    assert ml.resolution.significance(best[3], sigma2).min() < ml.fitting.MIN_SIGNIFICANCE
    gain = 30.0 * sigma2
    out, n_it, kept = ml.fitting._split_weak(prob, best, sigma2, 60, gain)
    assert kept and n_it > 0 and out[3]["cost"] < best[3]["cost"] - gain
    err = np.abs(np.sort(out[0][:, 0]) - np.sort(th[:, 0]))
    assert err.max() < 0.003
    again, n2, kept2 = ml.fitting._split_weak(prob, out, sigma2, 60, gain)
    assert not kept2 and n2 == 0 and again is out


def test_split_weak_recovers_a_merged_pair_from_a_path_counted_twice():
    """The same pair merged into one path while a third source is fitted twice (two atoms 0.004
    apart in direction cosine, both far above the noise, 0.2 standard deviations of their
    difference apart: unresolved). The move drops the weaker of the unresolved pair, splits the
    merged path and reaches the likelihood of the fit started at the truth, every source within
    0.003 in direction cosine and the pair resolved; the fit it returns is left alone."""
    sc = _scene(47, n_paths=3, snr_db=(20.0, 25.0))
    src = sc.sources.copy()
    r0 = np.linalg.norm(src[0])
    u = src[0, :2] / r0 + [0.03, 0.0]
    src[1] = r0 * np.append(u, np.sqrt(1 - u @ u))
    d, v = sc.d.copy(), sc.v.copy()
    d[1], v[1] = d[0] + 0.05, v[0]
    pair = replace(sc, sources=src, d=d, v=v)
    prob = ml.Problem(pair.tensor(np.random.default_rng(5)), pair.element_positions, pair.config.fc)
    th, mf, mt = _truth(pair)
    sigma2 = prob.noise_floor(3)
    dx = np.array([0.002, 0.0, 0.0])
    th0 = np.vstack([np.append(th[:2, :2].mean(0), th[0, 2]), th[2] - dx, th[2] + dx])
    mf0, mt0 = np.array([mf[:2].mean(), mf[2], mf[2]]), np.array([mt[:2].mean(), mt[2], mt[2]])
    best = (th0, mf0, mt0, prob.evaluate(th0, mf0, mt0))
    assert ml.resolution.significance(best[3], sigma2).min() > 10 * ml.fitting.MIN_SIGNIFICANCE
    assert ml.separations(prob, th0, mf0, mt0, sigma2).min() < 1.0
    out, n_it, kept = ml.fitting._split_weak(prob, best, sigma2, 60, 30.0 * sigma2)
    at_truth = ml.fitting._lm(prob, th, mf, mt, sigma2, 60)
    assert kept and n_it > 0
    assert out[3]["cost"] == pytest.approx(at_truth[3]["cost"], rel=1e-9)
    for row in th[:, :2]:
        assert np.min(np.linalg.norm(out[0][:, :2] - row, axis=1)) < 0.003
    assert ml.separations(prob, *out[:3], sigma2).min() > ml.RESOLVE_Z
    again, n2, kept2 = ml.fitting._split_weak(prob, out, sigma2, 60, 30.0 * sigma2)
    assert not kept2 and n2 == 0 and again is out
