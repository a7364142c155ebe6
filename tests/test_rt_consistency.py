"""The geometry-consistency test of one snapshot's paths (tunnelkit.consistency)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import binom

from tunnelkit.consistency import consistent_paths, geometry_consistency, tunnel_planes
from tunnelkit.signal_route import SignalRoute


@pytest.fixture(scope="module")
def scene():
    route = SignalRoute.from_scenario("italiano2026-straight")
    arr, paths = route.paths(10)
    return route, arr, paths


def _exact(paths, beta):
    u = np.array([p.direction for p in paths])
    d = np.array([p.length for p in paths]) + beta
    return u, d


def test_planes_are_the_distinct_surface_planes(scene):
    route = scene[0]
    planes = tunnel_planes(route.tunnel)
    coeffs = {
        tuple(np.round(np.append(f.plane.normal, f.plane.offset), 6)) for f in route.tunnel.surfaces
    }
    assert len(planes) == len(coeffs)
    for f in route.tunnel.surfaces:  # every surface's plane is among them
        c = np.append(f.plane.normal, f.plane.offset)
        assert min(np.abs(np.append(p.normal, p.offset) - c).max() for p in planes) < 1e-9


def test_exact_paths_recover_the_ue_the_clock_bias_and_the_planes(scene):
    route, arr, paths = scene
    beta = 3.7
    u, d = _exact(paths, beta)
    planes = tunnel_planes(route.tunnel)
    res = geometry_consistency(u, d, arr.origin, planes, 1e-6, 1e-6, 1e-5,
                               inside=route.tunnel.contains)  # fmt: skip
    ue = paths[0].ue
    assert np.linalg.norm(res["ue"] - ue) < 1e-6
    assert abs(res["beta"] - beta) < 1e-6
    assert res["consistent"] and res["keep"].all() and res["r2"].max() < 1e-3
    for p, j in zip(paths, res["plane"], strict=True):  # brute force: the plane mirroring the UE
        want = (
            -1
            if p.kind == "los"
            else int(np.argmin([np.linalg.norm(pl.mirror(ue) - p.source) for pl in planes]))
        )
        assert j == want


def test_false_alarm_rate_on_gaussian_errors(scene):
    """Paths drawn about the exact geometry with the stated sigmas: the snapshot test's
    false-alarm rate is its pfa (binomial 99.9 % interval over the draws)."""
    route, arr, paths = scene
    u0, d0 = _exact(paths, 0.0)
    planes = tunnel_planes(route.tunnel)
    rng = np.random.default_rng(3)
    sa, sd, pfa, n = 2e-4, 2e-3, 0.1, 150
    flags = 0
    for _ in range(n):
        az = np.arctan2(u0[:, 1], u0[:, 0]) + sa * rng.standard_normal(len(paths))
        el = np.arcsin(u0[:, 2]) + sa * rng.standard_normal(len(paths))
        u = np.c_[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)]
        d = d0 + sd * rng.standard_normal(len(paths))
        res = geometry_consistency(u, d, arr.origin, planes, sa, sa, sd, pfa=pfa,
                                   inside=route.tunnel.contains)  # fmt: skip
        flags += not res["consistent"]
    lo, hi = binom.ppf([0.0005, 0.9995], n, pfa)
    assert lo <= flags <= hi


def test_an_inconsistent_path_is_flagged_and_dropped(scene):
    route, arr, paths = scene
    u, d = _exact(paths, 1.0)
    d[2] += 0.5  # 50 cm on one reflection, 500 of its sigmas
    res = geometry_consistency(u, d, arr.origin, tunnel_planes(route.tunnel), 1e-4, 1e-4, 1e-3,
                               inside=route.tunnel.contains)  # fmt: skip
    assert not res["consistent"]
    assert not res["keep"][2] and np.delete(res["keep"], 2).all()
    assert np.linalg.norm(res["ue"] - paths[0].ue) < 1e-3


def test_a_floor_absorbs_a_model_error_within_it(scene):
    route, arr, paths = scene
    u, d = _exact(paths, 1.0)
    d[2] += 0.05
    res = geometry_consistency(u, d, arr.origin, tunnel_planes(route.tunnel), 1e-4, 1e-4, 1e-3,
                               floor_range=0.1, inside=route.tunnel.contains)  # fmt: skip
    assert res["consistent"] and res["keep"].all()


def test_route_measurements_and_one_path(scene):
    route = scene[0]
    ep = route.epoch(10, np.random.default_rng(0), refine="joint")
    res = consistent_paths(ep.measurements, route.tunnel, sigma_phi=1e-3, sigma_psi=1e-3,
                           sigma_d=0.05)  # fmt: skip
    assert res["keep"].shape == (len(ep.measurements),)
    with pytest.raises(ValueError, match="sigma_phi"):
        consistent_paths(ep.measurements, route.tunnel)
    one = geometry_consistency(np.array([[1.0, 0, 0]]), [5.0], np.zeros(3),
                               tunnel_planes(route.tunnel), 1e-3, 1e-3, 0.01)  # fmt: skip
    assert one["consistent"] and one["dof"] == 0 and one["keep"].all()


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"direction": np.ones((2, 2))}, "direction"),
        ({"d": [1.0]}, "d"),
        ({"sigma_d": -1.0}, "sigma_d"),
        ({"sigma_phi": 0.0}, "sigma_phi"),
        ({"pfa": 1.5}, "pfa"),
        ({"floor_angle": -1.0}, "floor_angle"),
        ({"planes": []}, "planes"),
        ({"n_los": 0}, "n_los"),
        ({"inside": 3}, "inside"),
        ({"origin": [0, 0]}, "origin"),
    ],
)
def test_bad_input_names_the_parameter(scene, kw, match):
    route, arr, paths = scene
    u, d = _exact(paths, 0.0)
    args = {"direction": u, "d": d, "origin": arr.origin, "planes": tunnel_planes(route.tunnel),
            "sigma_phi": 1e-3, "sigma_psi": 1e-3, "sigma_d": 0.01}  # fmt: skip
    args.update(kw)
    with pytest.raises((ValueError, TypeError), match=match):
        geometry_consistency(**args)


def test_bound_sigmas_match_the_reported_covariance(scene):
    """Where the fit passes its own test, the bound at the estimate is the route's reported one."""

    from tunnelkit.path_consistency import bound_sigmas, epoch_consistency

    route = scene[0].with_options(report_covariance=True)
    ep = route.epoch(10, np.random.default_rng(5), refine="ml")
    m = ep.measurements
    assert m.cov is not None
    sig = bound_sigmas(ep.estimates, ep.array, route.config)
    np.testing.assert_allclose(sig[:, 0], np.sqrt(m.cov[:, 0, 0]), rtol=1e-9)
    np.testing.assert_allclose(sig[:, 1], np.sqrt(m.cov[:, 1, 1]), rtol=1e-9)
    np.testing.assert_allclose(sig[:, 2], m.sigma_d, rtol=1e-9)
    res = epoch_consistency(ep, route, pfa=1e-3)
    assert res["r2"].shape == (len(m),) and np.linalg.norm(res["ue"] - ep.ue) < 0.05
    floors = epoch_consistency(ep, route, bound=False, floor_angle=1e-3, floor_range=0.05)
    assert floors["consistent"]
    with pytest.raises(ValueError, match="floor"):
        epoch_consistency(ep, route, bound=False)
    with pytest.raises(TypeError, match="ep"):
        epoch_consistency(m, route)
    with pytest.raises(TypeError, match="est"):
        bound_sigmas(m, ep.array, route.config)
    np.testing.assert_array_equal(bound_sigmas(ep.estimates, ep.array, route.config, m.source), sig)
    for bad in ([0, 0], [-1], [99], [[0]], [0.5]):
        with pytest.raises(ValueError, match="keep"):
            bound_sigmas(ep.estimates, ep.array, route.config, bad)
    with pytest.raises(TypeError, match="bound"):
        epoch_consistency(ep, route, bound="yes")


def test_joint_fisher_against_finite_differences():
    """The joint Fisher information of two paths against 2/N0 Re(J^H J) with J the central
    finite differences of the eq.-1 tensor (small array, few tones), cross terms included."""
    from tunnelkit.path_consistency import joint_fisher

    rng = np.random.default_rng(2)
    pos = np.c_[rng.uniform(-0.02, 0.02, (4, 2)), np.zeros(4)]
    pos[0] = 0.0
    fc, nf, nt, n0 = 3.5e9, 6, 3, 0.3
    alpha = np.array([1.0 + 0.5j, -0.4 + 0.8j])
    src = np.array([[0.3, 0.2, 4.0], [-0.5, 0.4, 6.0]])
    mu_f, mu_t = np.array([-0.7, -1.1]), np.array([0.05, -0.02])
    k0 = 2 * np.pi * fc / 299792458.0

    def tensor(theta):
        H = np.zeros((4, nf, nt), complex)
        for j in range(2):
            q = theta[7 * j : 7 * j + 7]
            r = np.linalg.norm(q[4:][None] - pos, axis=1)
            a = np.exp(1j * k0 * (r - r[0]))
            f = np.exp(1j * np.arange(nf) * q[2])
            t = np.exp(1j * np.arange(nt) * q[3])
            H += (q[0] + 1j * q[1]) * a[:, None, None] * f[None, :, None] * t[None, None, :]
        return H.ravel()

    theta = np.concatenate([[alpha[j].real, alpha[j].imag, mu_f[j], mu_t[j], *src[j]]
                            for j in range(2)])  # fmt: skip
    J = np.zeros((4 * nf * nt, 14), complex)
    for i in range(14):
        h = 1e-6 * max(1.0, abs(theta[i]))
        e = np.zeros(14)
        e[i] = h
        J[:, i] = (tensor(theta + e) - tensor(theta - e)) / (2 * h)
    want = 2.0 / n0 * (J.conj().T @ J).real
    got = joint_fisher(alpha, src, pos, mu_f, mu_t, nf, nt, n0, fc)
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-6 * np.abs(want).max())
    assert np.abs(got[:7, 7:]).max() > 1e-3 * np.abs(got).max()  # the paths do interact
    with pytest.raises(ValueError, match="sources"):
        joint_fisher(alpha, src[:1], pos, mu_f, mu_t, nf, nt, n0, fc)
    with pytest.raises(ValueError, match="noise_power"):
        joint_fisher(alpha, src, pos, mu_f, mu_t, nf, nt, -1.0, fc)


def test_joint_bound_blocks_are_the_per_path_bound(scene):
    """The joint covariance's diagonal is bound_sigmas squared; its off-diagonal correlations
    are there (the statistic needs them)."""
    from tunnelkit.path_consistency import bound_sigmas, joint_bound

    route = scene[0]
    ep = route.epoch(10, np.random.default_rng(5), refine="ml")
    m = ep.measurements
    cov = joint_bound(ep.estimates, ep.array, route.config, m.source)
    sig = bound_sigmas(ep.estimates, ep.array, route.config, m.source)
    np.testing.assert_allclose(np.sqrt(np.diag(cov)).reshape(-1, 3), sig, rtol=1e-8)
    corr = cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    assert np.abs(corr - np.eye(len(cov))).max() > 0.3
    assert joint_bound(ep.estimates, ep.array, route.config, np.zeros(0, int)).shape == (0, 0)
    with pytest.raises(ValueError, match="keep"):
        joint_bound(ep.estimates, ep.array, route.config, [0, 0])


def test_gls_statistic_with_a_diagonal_cov_is_the_plain_one(scene):
    """cov = diag(sigma^2): the generalised least-squares statistic equals the per-component one;
    a correlated cov whitens correlated errors (false-alarm rate at pfa over the draws)."""
    route, arr, paths = scene
    u0, d0 = _exact(paths, 0.0)
    K = len(paths)
    planes = tunnel_planes(route.tunnel)
    sa, sd = 2e-4, 2e-3
    rng = np.random.default_rng(4)
    sig = np.tile([sa, sa, sd], K)

    def draw(cov):
        e = np.linalg.cholesky(cov) @ rng.standard_normal(3 * K)
        e = e.reshape(K, 3)
        az = np.arctan2(u0[:, 1], u0[:, 0]) + e[:, 0]
        el = np.arcsin(u0[:, 2]) + e[:, 1]
        return np.c_[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], d0 + e[:, 2]

    u, d = draw(np.diag(sig**2))
    kw = {"inside": route.tunnel.contains}
    a = geometry_consistency(u, d, arr.origin, planes, sa, sa, sd, **kw)
    b = geometry_consistency(u, d, arr.origin, planes, sa, sa, sd, cov=np.diag(sig**2), **kw)
    assert b["statistic"] == pytest.approx(a["statistic"], rel=1e-6)
    np.testing.assert_allclose(b["r2"], a["r2"], rtol=1e-6)
    # strongly correlated errors (0.8 between every pair of paths' ranges and within each path's
    # angles): with the joint cov the rate is pfa
    corr = np.eye(3 * K)
    idx = np.arange(K) * 3
    corr[np.ix_(idx + 2, idx + 2)] = 0.8 + 0.2 * np.eye(K)
    corr[idx, idx + 1] = corr[idx + 1, idx] = 0.8
    cov = corr * np.outer(sig, sig)
    n, pfa, flags = 150, 0.1, 0
    for _ in range(n):
        u, d = draw(cov)
        res = geometry_consistency(u, d, arr.origin, planes, sa, sa, sd, pfa=pfa, cov=cov, **kw)
        flags += not res["consistent"]
    lo, hi = binom.ppf([0.0005, 0.9995], n, pfa)
    assert lo <= flags <= hi
    with pytest.raises(ValueError, match="cov"):
        geometry_consistency(u, d, arr.origin, planes, sa, sa, sd, cov=np.eye(3))
    with pytest.raises(ValueError, match="cov"):
        geometry_consistency(u, d, arr.origin, planes, sa, sa, sd, cov=-np.eye(3 * K))


def test_rate_interval_is_the_exact_binomial_interval():
    """At each end the binomial tail equals (1 - level) / 2 (brute force: scipy's binomial)."""
    from tunnelkit.path_consistency import rate_interval

    for k, n in ((0, 50), (3, 50), (20, 500), (50, 50)):
        lo, hi = rate_interval(k, n, 0.95)
        assert 0 <= lo <= k / n <= hi <= 1
        if k > 0:
            assert binom.sf(k - 1, n, lo) == pytest.approx(0.025, rel=1e-6)
        if k < n:
            assert binom.cdf(k, n, hi) == pytest.approx(0.025, rel=1e-6)
    with pytest.raises(ValueError, match="k"):
        rate_interval(5, 4)
    with pytest.raises(ValueError, match="level"):
        rate_interval(1, 4, 1.5)
