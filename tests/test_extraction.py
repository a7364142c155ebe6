import warnings

import numpy as np
import pytest

from tunnelkit import arrays, channel, extraction, signal_route
from tunnelkit import propagation as P
from tunnelkit.constants import C

FC = 5.9e9
CFG = channel.SRSConfig()


@pytest.fixture(scope="module")
def route():
    return signal_route.SignalRoute.from_scenario("italiano2026-straight")


def _extract(H, L, arr, **kw):
    """The paper's route (eq. 13-24) unless ``refine`` says otherwise (the ML route: test_ml.py)."""
    kw.setdefault("refine", "joint")
    return extraction.extract_paths(H, L, arr, CFG, **kw)


def _angle_deg(u, v):
    return np.degrees(np.arccos(np.clip(np.sum(u * v, axis=-1), -1, 1)))


def test_noiseless_scenario_epoch_is_recovered_exactly(route):
    arr, paths = route.paths(20)
    H = channel.channel_tensor(paths, CFG)
    est = _extract(H, len(paths), arr)
    o = np.argsort([p.length for p in paths])
    np.testing.assert_allclose(est.d, [paths[i].length for i in o], atol=1e-6)
    np.testing.assert_allclose(est.v, [paths[i].velocity for i in o], atol=1e-5)
    truth = np.stack([paths[i].direction_local for i in o])
    assert np.max(_angle_deg(est.direction, truth)) < 0.05
    # exact physics: the wavefront is centred on the VUE, so kappa is the VUE distance
    np.testing.assert_allclose(est.kappa, [paths[i].length for i in o], rtol=2e-3)
    assert np.all(est.near_field) and np.all(est.valid) and est.rel_error < 1e-6


def test_srnf_channel_gives_reflection_point_distance(route):
    arr, paths = route.paths(20)
    H = channel.channel_tensor(paths, CFG, model="srnf")
    est = _extract(H, len(paths), arr)
    o = np.argsort([p.length for p in paths])
    np.testing.assert_allclose(est.kappa, [paths[i].kappa_srnf for i in o], rtol=2e-3)  # eq. 51


def test_psi_follows_eq19_polar_angle_not_eq22():
    pos = arrays.ura(8, 8, 0.0254)
    src = np.array([1.5, -2.0, 9.0])  # local frame, in front of the array
    delta = np.linalg.norm(pos - src, axis=1) - np.linalg.norm(src)
    x = extraction.solve_near_field(delta[:, None], pos)[0]
    kappa = np.linalg.norm(src)
    np.testing.assert_allclose(x, [src[0], src[1], kappa], rtol=1e-9)
    ang = extraction.angles_from_solution(x[None], np.zeros((1, 2)))
    u = src / kappa
    assert ang["psi_nf"][0] == pytest.approx(np.arccos(u[2]), abs=1e-9)  # eq. 19: from the normal
    eq22 = np.arccos(np.hypot(x[0], x[1]) / x[2])
    assert eq22 == pytest.approx(np.pi / 2 - np.arccos(u[2]), abs=1e-9)  # eq. 22 is the complement
    np.testing.assert_allclose(ang["dir_nf"][0], u, atol=1e-9)
    # far field: delta_m = -u . p_m, LS gives (u_x, u_y)
    uf = extraction.solve_far_field(-(pos @ u)[:, None], pos)[0]
    np.testing.assert_allclose(uf, u[:2], atol=1e-12)


def test_unwrapping_on_a_grid_and_on_a_scattered_array():
    rng = np.random.default_rng(2)
    pos = arrays.ura(6, 7, 0.5)
    true = pos @ np.array([2.6, -1.9, 0]) + 0.05 * np.sum(
        pos**2, axis=1
    )  # ramps of ~pi per element
    un = extraction.unwrap_spatial(np.exp(1j * true)[:, None], pos)[:, 0]
    np.testing.assert_allclose(un, true - true[0], atol=1e-9)
    scattered = np.column_stack(
        [np.cumsum(rng.uniform(0.3, 0.5, 12)), rng.uniform(0, 0.4, 12), np.zeros(12)]
    )
    scattered -= scattered[0]
    t2 = scattered @ np.array([3.0, 1.0, 0])
    un2 = extraction.unwrap_spatial(np.exp(1j * t2)[:, None], scattered)[:, 0]
    np.testing.assert_allclose(un2, t2 - t2[0], atol=1e-9)


def test_kruskal_bounds_and_ranks():
    assert extraction.max_identifiable_rank((100, 410, 12)) == 110
    assert extraction.max_identifiable_rank((2, 2, 2)) == 2
    with pytest.raises(ValueError, match=r"n_paths.*Kruskal"):
        extraction.check_rank((4, 4, 2), 5)
    v = np.exp(1j * np.outer(np.arange(8), [0.1, 0.7, 1.9]))
    assert extraction.kruskal_rank(v) == 3
    assert extraction.kruskal_rank(np.column_stack([v[:, 0], v[:, 0], v[:, 1]])) == 1


def test_crlb_matches_finite_difference_fim():
    rng = np.random.default_rng(4)
    pos = arrays.ura(2, 2, 0.025)
    L, nf, nt, n0 = 2, 6, 4, 0.3
    alpha = rng.normal(size=L) + 1j * rng.normal(size=L)
    src = np.array([[0.3, 0.2, 1.5], [-0.4, 0.1, 2.0]])
    mu_f, mu_t = np.array([0.3, -0.8]), np.array([0.05, 0.4])
    k0 = 2 * np.pi * FC / C

    def model(theta):
        out = np.zeros((4, nf, nt), complex)
        for j_ in range(L):
            a_l = theta[7 * j_] + 1j * theta[7 * j_ + 1]
            s = theta[7 * j_ + 4 : 7 * j_ + 7]
            r = np.linalg.norm(pos - s, axis=1)
            out += a_l * np.einsum(
                "m,s,k->msk",
                np.exp(1j * k0 * (r - r[0])),
                np.exp(1j * np.arange(nf) * theta[7 * j_ + 2]),
                np.exp(1j * np.arange(nt) * theta[7 * j_ + 3]),
            )
        return out.ravel()

    theta = np.concatenate(
        [[alpha[j_].real, alpha[j_].imag, mu_f[j_], mu_t[j_], *src[j_]] for j_ in range(L)]
    )
    J = np.stack(
        [(model(theta + h) - model(theta - h)) / (2e-6) for h in 1e-6 * np.eye(theta.size)], axis=1
    )
    cov = np.linalg.inv(2 / n0 * np.real(J.conj().T @ J))
    cr = extraction.crlb_paths(alpha, src, pos, mu_f, mu_t, FC, nf, nt, n0)
    np.testing.assert_allclose(cr["mu_f"], np.sqrt(cov[[2, 9], [2, 9]]), rtol=1e-5)
    np.testing.assert_allclose(cr["mu_t"], np.sqrt(cov[[3, 10], [3, 10]]), rtol=1e-5)
    np.testing.assert_allclose(cr["source_cov"][1], cov[11:14, 11:14], rtol=1e-4)


def test_los_rmse_within_twice_the_crlb(route):
    """Seeded snapshots at the paper's SNR and size, L known (LoS + road, no ceiling)."""
    route_kinds = signal_route.SignalRoute(
        route.tunnel, route.arrays, route.trajectory, route.config, kinds=("los", "road")
    )
    arr, paths = route_kinds.paths(10)
    nf = CFG.n_tones
    H0 = channel.channel_tensor(paths, CFG, n_tones=nf)
    d0, v0 = paths[0].length, paths[0].velocity
    err = []
    for seed in range(25):
        H = channel.add_noise(H0, CFG.noise_power, np.random.default_rng(seed))
        est = _extract(H, len(paths), arr)
        i = int(np.argmin(_angle_deg(est.direction, paths[0].direction_local)))
        err.append((est.d[i] - d0, est.v[i] - v0))
    rmse = np.sqrt(np.mean(np.square(err), axis=0))
    alpha = np.sqrt(CFG.tx_power) * np.array([p.gain for p in paths])
    src = np.stack([arr.to_local(p.source) for p in paths])
    mu_f = -2 * np.pi * CFG.tone_spacing * np.array([p.length for p in paths]) / C
    mu_t = 2 * np.pi * CFG.symbol_period * np.array([p.doppler for p in paths])
    cr = extraction.crlb_paths(
        alpha, src, arr.local, mu_f, mu_t, FC, nf, CFG.n_symbols, CFG.noise_power, spatial="free"
    )
    sd = C / (2 * np.pi * CFG.tone_spacing) * cr["mu_f"][0]
    sv = C / (2 * np.pi * FC * CFG.symbol_period) * cr["mu_t"][0]
    assert rmse[0] < 2 * sd, (rmse, sd)
    assert rmse[1] < 2 * sv, (rmse, sv)


def test_bad_input_names_the_parameter(route):
    arr, paths = route.paths(20)
    H = channel.channel_tensor(paths, CFG, n_tones=16)
    bad = H.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match=r"H.*NaN"):
        extraction.extract_paths(bad, 2, arr, CFG)
    with pytest.raises(ValueError, match=r"H.*3-D"):
        extraction.extract_paths(H[:, :, 0], 2, arr, CFG)
    with pytest.raises(ValueError, match="n_paths"):
        extraction.extract_paths(H, 0, arr, CFG)
    with pytest.raises(ValueError, match=r"n_paths.*Kruskal"):
        extraction.extract_paths(H[:3, :3, :2], 4, arr.local[:3], CFG)
    with pytest.raises(ValueError, match=r"array.*M = 100"):
        extraction.extract_paths(H, 2, arr.local[:50], CFG)
    with pytest.raises(ValueError, match=r"array.*M = 100"):  # an ArrayGeometry of another size
        small = arrays.make_array(4, 4, fc=FC, azimuth=0.0, elevation=0.0, origin=[0, 0, 2.5])
        extraction.extract_paths(H, 2, small, CFG)
    tilted = arr.local.copy()
    tilted[5, 2] = 0.01
    with pytest.raises(ValueError, match=r"array.*plane"):
        extraction.extract_paths(H, 2, tilted, CFG)
    with pytest.raises(ValueError, match=r"array.*shape"):
        extraction.extract_paths(H, 2, arr.local[:, :2], CFG)
    with pytest.raises(TypeError, match="array"):
        extraction.extract_paths(H, 2, "ura", CFG)
    with pytest.raises(TypeError, match="array"):
        extraction.extract_paths(H, 2, None, CFG)
    with pytest.raises(TypeError, match="srs"):
        extraction.extract_paths(H, 2, arr, {"fc": FC})
    with pytest.raises(TypeError, match="srs"):
        extraction.extract_paths(H, 2, arr, FC)  # the old positional radio arguments
    with pytest.raises(TypeError, match="srs"):
        extraction.extract_paths(H, 2, arr, None, refine="joint")
    with pytest.raises(ValueError, match="refine"):
        extraction.extract_paths(H, 2, arr, CFG, refine="maybe")


def _same_estimates(a, b):
    """Two :class:`PathEstimates` equal to the last bit (fit and factors included)."""
    assert len(a) == len(b)
    for key in ("alpha", "d", "v", "direction", "kappa", "near_field", "phi", "psi", "valid"):
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    for key in ("kappa_nf", "delta", "mu_f", "mu_t"):
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    for fa, fb in zip(a.factors, b.factors):
        np.testing.assert_array_equal(fa, fb)
    assert (a.rel_error, a.n_iter, a.converged) == (b.rel_error, b.n_iter, b.converged)
    assert (a.fit is None) == (b.fit is None)
    if a.fit is not None:
        np.testing.assert_array_equal(a.fit.theta, b.fit.theta)
        np.testing.assert_array_equal(a.significance, b.significance)
        assert (a.fit.cost, a.fit.rho, a.fit.n_iter) == (b.fit.cost, b.fit.rho, b.fit.n_iter)


@pytest.fixture(scope="module")
def small_tensor(route):
    """A noisy 100 x 32 x 12 tensor of a straight-drive epoch (five paths)."""
    arr, paths = route.paths(20)
    H0 = channel.channel_tensor(paths, CFG, n_tones=32)
    return channel.add_noise(H0, CFG.noise_power, np.random.default_rng(3)), arr, len(paths)


@pytest.mark.parametrize("refine", ["joint", "column", "none"])
def test_one_call_form_equals_the_paper_stage(small_tensor, refine):
    """``extract_paths(H, L, array, srs)`` is the paper's stage called directly, whether the
    array comes as an ArrayGeometry or as its local positions."""
    H, arr, L = small_tensor
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(H, L, arr, CFG, refine=refine)
        stage = extraction.paper_route(H, L, arr.local, CFG, refine=refine)
    _same_estimates(est, stage)


def test_one_call_form_equals_the_coherent_and_ml_stages(small_tensor):
    from tunnelkit.extraction import coherent, ml

    H, arr, L = small_tensor
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(H, L, arr, CFG, refine="coherent")
        joint = extraction.paper_route(H, L, arr, CFG, refine="joint")
        _same_estimates(est, coherent.resolve_coherent(H, joint, arr.local, CFG, L))
        est = extraction.extract_paths(H, L, arr.local, CFG)
        _same_estimates(est, ml.ml_paths(H, L, arr, CFG))
        noise = extraction.extract_paths(H, L, arr, CFG, noise_power=CFG.noise_power)
        _same_estimates(noise, ml.ml_paths(H, L, arr, CFG, noise_power=CFG.noise_power))


def test_stage_entry_points_name_array_and_srs(small_tensor):
    from tunnelkit.extraction import coherent, ml

    H, arr, L = small_tensor
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.paper_route(H, L, arr, CFG, refine="none")
    calls = {
        "paper_route": lambda a, s: extraction.paper_route(H, L, a, s),
        "resolve_coherent": lambda a, s: coherent.resolve_coherent(H, est, a, s),
        "ml_paths": lambda a, s: ml.ml_paths(H, L, a, s),
        "fit_ml": lambda a, s: ml.fit_ml(H, ml.start_from_estimates(est), a, s),
        "estimate_crlb": lambda a, s: extraction.estimate_crlb(est, a, s),
    }
    for call in calls.values():
        with pytest.raises(TypeError, match="srs"):
            call(arr, CFG.fc)
        with pytest.raises(ValueError, match=r"array.*M = 100"):
            call(arr.local[:50], CFG)
        with pytest.raises(TypeError, match="array"):
            call("ura", CFG)
    with pytest.raises(ValueError, match="refine"):
        extraction.paper_route(H, L, arr, CFG, refine="ml")
    with pytest.raises(TypeError, match="array"):
        extraction.path_crlb([], arr.local, CFG)
    with pytest.raises(TypeError, match="srs"):
        extraction.path_crlb([], arr, "srs")


def test_non_convergence_warns_with_the_final_error():
    rng = np.random.default_rng(0)
    H = rng.normal(size=(4, 5, 3)) + 1j * rng.normal(size=(4, 5, 3))
    with pytest.warns(extraction.CPDConvergenceWarning, match="final relative error"):
        extraction.cpd(H, 3, method="plain", n_iter_max=2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = extraction.cpd(H[:, :, :1].repeat(3, axis=2), 1, method="plain")
    assert res.converged


def test_far_field_path_reports_nan_kappa():
    arr = arrays.make_array(4, 4, fc=FC, azimuth=0.0, elevation=0.0, origin=[0, 0, 2.5])
    tun = P.semicircular_tunnel(length=4000.0)
    paths = P.trace_paths(tun, arr, [1500.0, 1.0, 2.3], fc=FC, kinds=("los",))
    H = channel.add_noise(
        channel.channel_tensor(paths, CFG, n_tones=64),
        CFG.noise_power * 1e-6,
        np.random.default_rng(1),
    )
    est = _extract(H, 1, arr)
    assert _angle_deg(est.direction[0], paths[0].direction_local) < 0.5
    assert not est.near_field[0] or est.kappa[0] > 200  # curvature unresolvable at 1.5 km
    assert np.isnan(est.kappa[0]) == (not est.near_field[0])


@pytest.mark.parametrize("shape", [(1, 8), (8, 1)])
def test_linear_array_along_either_local_axis_keeps_the_curvature(shape):
    """A ULA along local y (an ``n x 1`` URA) is as linear as one along x: TLS must not degrade."""
    pos = arrays.ura(*shape, 0.0254)
    e = pos[-1, :2] / np.linalg.norm(pos[-1, :2])
    src = np.array([1.5, -2.0, 9.0])
    delta = np.linalg.norm(pos - src, axis=1) - np.linalg.norm(src)
    x = extraction.solve_near_field(delta[:, None], pos)[0]
    np.testing.assert_allclose(x, [*((src[:2] @ e) * e), np.linalg.norm(src)], rtol=1e-9, atol=1e-9)
    u = src / np.linalg.norm(src)
    uf = extraction.solve_far_field(-(pos @ u)[:, None], pos)[0]
    np.testing.assert_allclose(uf, (u[:2] @ e) * e, atol=1e-12)
    # through the whole route: the LoS stays near-field with kappa = distance
    arr = arrays.make_array(
        *shape, fc=FC, azimuth=0.0, elevation=np.radians(-30), origin=[0, 0, 4.8]
    )
    paths = P.trace_paths(P.semicircular_tunnel(), arr, [18.0, -2.5, 1.5], fc=FC, kinds=("los",))
    est = _extract(channel.channel_tensor(paths, CFG, n_tones=64, n_symbols=4), 1, arr)
    assert est.near_field[0]
    assert est.kappa[0] == pytest.approx(paths[0].length, rel=1e-6)
    assert est.direction[0, :2] @ e == pytest.approx(paths[0].direction_local[:2] @ e, abs=1e-6)


@pytest.mark.parametrize("fc", [3.5e9, 5.9e9, 28e9])
def test_half_wavelength_ura_is_recognised_as_a_grid(fc):
    """Rounding positions to the tolerance first made the step drift along a long axis."""
    pos = arrays.ura(32, 24, C / fc / 2)
    r, c, nr, nc = extraction.numerics.grid_index(pos)
    assert (nr, nc) == (32, 24)
    np.testing.assert_array_equal(r * 24 + c, np.arange(pos.shape[0]))
    assert len(extraction.decomposition._shift_pairs(pos)) == 2


def test_refine_joint_reaches_a_stationary_point_of_the_projected_cost():
    """Brute-force twin of the Kaufman Jacobian: central differences of the variable-projection
    cost ``min_A ||H - A W^T||^2`` vanish at the returned roots, and the cost went down."""
    rng = np.random.default_rng(1)
    M, nf, nt, L = 6, 40, 8, 3
    A = rng.normal(size=(M, L)) + 1j * rng.normal(size=(M, L))
    muf, mut = np.array([0.3, 0.35, -1.0]), np.array([0.1, -0.2, 0.15])
    s, k = np.arange(nf)[:, None], np.arange(nt)[:, None]
    H = np.einsum("ml,sl,kl->msk", A, np.exp(1j * s * muf), np.exp(1j * k * mut))
    H = H + 0.3 * (rng.normal(size=H.shape) + 1j * rng.normal(size=H.shape))
    X = H.reshape(M, nf * nt)

    def cost(mu):
        W = np.einsum("sl,kl->skl", np.exp(1j * s * mu[:L]), np.exp(1j * k * mu[L:]))
        W = W.reshape(nf * nt, L)
        Ahat = np.linalg.lstsq(W, X.T, rcond=None)[0].T
        return np.linalg.norm(X - Ahat @ W.T) ** 2

    start = np.concatenate([muf + 0.01, mut - 0.01])
    mf, mt, _ = extraction.refine_joint(H, start[:L], start[L:], n_steps=20)
    mu = np.concatenate([mf, mt])
    h = 1e-6
    grad = np.array([(cost(mu + e) - cost(mu - e)) / (2 * h) for e in h * np.eye(2 * L)])
    g0 = np.array([(cost(start + e) - cost(start - e)) / (2 * h) for e in h * np.eye(2 * L)])
    assert cost(mu) < cost(start)
    assert np.max(np.abs(grad)) < 1e-5 * np.max(np.abs(g0))


def test_free_spatial_crlb_matches_finite_difference_fim():
    """``spatial="free"``: unknowns Re/Im alpha, mu_f, mu_t and every a_m (m >= 1, a_0 = 1)."""
    rng = np.random.default_rng(5)
    M, L, nf, nt, n0 = 4, 2, 6, 4, 0.3
    pos = arrays.ura(2, 2, 0.025)
    alpha = rng.normal(size=L) + 1j * rng.normal(size=L)
    src = np.array([[0.3, 0.2, 1.5], [-0.4, 0.1, 2.0]])
    mu_f, mu_t = np.array([0.3, -0.8]), np.array([0.05, 0.4])
    k0 = 2 * np.pi * FC / C
    r = np.linalg.norm(pos[:, None, :] - src[None], axis=-1)
    a = np.exp(1j * k0 * (r - r[0]))
    n_per = 4 + 2 * (M - 1)

    def model(theta):
        out = np.zeros((M, nf, nt), complex)
        for j_ in range(L):
            t = theta[n_per * j_ : n_per * (j_ + 1)]
            am = np.concatenate([[1.0], t[4 : 4 + M - 1] + 1j * t[4 + M - 1 :]])
            out += (t[0] + 1j * t[1]) * np.einsum(
                "m,s,k->msk",
                am,
                np.exp(1j * np.arange(nf) * t[2]),
                np.exp(1j * np.arange(nt) * t[3]),
            )
        return out.ravel()

    theta = np.concatenate(
        [
            [alpha[j_].real, alpha[j_].imag, mu_f[j_], mu_t[j_], *a[1:, j_].real, *a[1:, j_].imag]
            for j_ in range(L)
        ]
    )
    h = 1e-6
    J = np.stack(
        [(model(theta + e) - model(theta - e)) / (2 * h) for e in h * np.eye(theta.size)], 1
    )
    cov = np.linalg.inv(2 / n0 * np.real(J.conj().T @ J))
    cr = extraction.crlb_paths(alpha, src, pos, mu_f, mu_t, FC, nf, nt, n0, spatial="free")
    idx = np.arange(L) * n_per
    np.testing.assert_allclose(cr["mu_f"], np.sqrt(cov[idx + 2, idx + 2]), rtol=1e-5)
    np.testing.assert_allclose(cr["mu_t"], np.sqrt(cov[idx + 3, idx + 3]), rtol=1e-5)
