"""The geometry-consistency test of one snapshot's paths (rt.consistency)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import binom

from tunnelkit.rt.consistency import consistent_paths, geometry_consistency, tunnel_planes
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
    from dataclasses import replace

    from tunnelkit.path_consistency import bound_sigmas, epoch_consistency

    route = replace(scene[0], report_covariance=True)
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
    np.testing.assert_array_equal(bound_sigmas(ep.estimates, ep.array, route.config, m.index), sig)
    for bad in ([0, 0], [-1], [99], [[0]], [0.5]):
        with pytest.raises(ValueError, match="keep"):
            bound_sigmas(ep.estimates, ep.array, route.config, bad)
    with pytest.raises(TypeError, match="bound"):
        epoch_consistency(ep, route, bound="yes")
