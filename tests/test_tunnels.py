"""User tunnel shapes: facets, cross-section measures, specular points, the signal route."""

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import arrays, propagation, reflection, signal_route, tunnels
from tunnelkit import scenarios as S
from tunnelkit.constants import C

W, H, L = 8.0, 6.0, 200.0


def _shapes():
    return {
        "rectangular": tunnels.make_tunnel("rectangular", width=W, height=H, length=L),
        "horseshoe": tunnels.make_tunnel("horseshoe", width=W, height=H, length=L, n_facets=12),
        "horseshoe-flat": tunnels.make_tunnel(
            "horseshoe", width=W, height=H, length=L, wall_height=4.5, n_facets=9
        ),
        "semicircular": tunnels.make_tunnel("semicircular", width=10.0, height=5.0, length=L),
    }


@pytest.mark.parametrize("name", list(_shapes()))
def test_facet_normals_point_inside(name):
    tun = _shapes()[name]
    centre = np.array([0.0, 0.0, tun.height / 2])
    assert tun.contains(centre)
    for f in tun.facets:
        assert np.linalg.norm(f.normal) == pytest.approx(1.0, abs=1e-12)
        # the normal points from the facet towards the inside ...
        assert f.normal @ (centre - f.center) > 0, f.name
        # ... a step along it from the facet centre stays inside, a step against it leaves
        assert tun.contains(f.center + 1e-3 * f.normal), f.name
        assert not tun.contains(f.center - 1e-3 * f.normal), f.name
        assert f.plane.signed_distance(f.corners()) == pytest.approx(np.zeros(4), abs=1e-9)
    kinds = [f.kind for f in tun.facets]
    assert kinds.count("road") == 1 and "wall" in kinds and "ceiling" in kinds


def test_rectangular_surfaces_are_where_they_should_be():
    tun = _shapes()["rectangular"]
    by = {f.name: f for f in tun.facets}
    assert set(by) == {"wall left", "ceiling", "wall right", "road"}
    np.testing.assert_allclose(by["wall left"].normal, [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(by["wall right"].normal, [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(by["ceiling"].normal, [0, 0, -1], atol=1e-12)
    assert by["ceiling"].kind == "ceiling" and by["wall left"].kind == "wall"
    assert by["wall left"].plane.signed_distance([0.0, W / 2, 1.0]) == pytest.approx(0.0)
    assert tun.x_range == (-L / 2, L / 2)


def _polygon_area(a, b, n):
    """Area of the half-ellipse polygon with vertices at angles i pi / n (sum of n triangles)."""
    return n / 2 * a * b * np.sin(np.pi / n)


@pytest.mark.parametrize("n", [2, 3, 12, 31])
def test_cross_section_area_and_perimeter_closed_forms(n):
    rect = tunnels.rectangular_tunnel(width=W, height=H, length=L)
    assert tunnels.cross_section_area(rect) == pytest.approx(W * H, rel=1e-12)
    assert tunnels.cross_section_perimeter(rect) == pytest.approx(2 * (W + H), rel=1e-12)
    r = 5.0  # semicircle: chord 2 r sin(pi / 2n) per facet
    semi = tunnels.make_tunnel("semicircular", width=2 * r, height=r, length=L, n_facets=n)
    assert tunnels.cross_section_area(semi) == pytest.approx(_polygon_area(r, r, n), rel=1e-12)
    chord = 2 * r * np.sin(np.pi / (2 * n))
    assert tunnels.cross_section_perimeter(semi) == pytest.approx(2 * r + n * chord, rel=1e-12)
    # horseshoe with a semicircular roof (default wall_height = H - W/2 = 2 m)
    hw, a = H - W / 2, W / 2
    hs = tunnels.horseshoe_tunnel(width=W, height=H, length=L, n_facets=n)
    assert tunnels.cross_section_area(hs) == pytest.approx(
        W * hw + _polygon_area(a, a, n), rel=1e-12
    )
    assert tunnels.cross_section_perimeter(hs) == pytest.approx(
        W + 2 * hw + n * 2 * a * np.sin(np.pi / (2 * n)), rel=1e-12
    )
    # an elliptic roof: wall_height 4.5 m, semi-axes 4 m and 1.5 m
    he = tunnels.horseshoe_tunnel(width=W, height=H, length=L, wall_height=4.5, n_facets=n)
    assert tunnels.cross_section_area(he) == pytest.approx(
        W * 4.5 + _polygon_area(a, 1.5, n), rel=1e-12
    )


def test_faceted_sections_converge_to_the_smooth_shapes():
    semi = tunnels.make_tunnel("semicircular", width=10.0, height=5.0, length=L, n_facets=360)
    assert tunnels.cross_section_area(semi) == pytest.approx(np.pi * 25 / 2, rel=1e-4)
    assert tunnels.cross_section_perimeter(semi) == pytest.approx(10 + np.pi * 5, rel=1e-5)
    he = tunnels.horseshoe_tunnel(width=W, height=H, length=L, wall_height=4.5, n_facets=360)
    assert tunnels.cross_section_area(he) == pytest.approx(W * 4.5 + np.pi * 4 * 1.5 / 2, rel=1e-4)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        (dict(width=8.0, height=3.0), "wall_height: the default"),
        (dict(width=8.0, height=6.0, wall_height=6.0), "wall_height: must be < height"),
        (dict(width=8.0, height=6.0, n_facets=1), "n_facets"),
        (dict(width=8.0, height=6.0, n_facets=10**6), "n_facets: at most 360"),
        (dict(width=-8.0, height=6.0), "width"),
    ],
)
def test_horseshoe_bad_input(kw, match):
    with pytest.raises(ValueError, match=match):
        tunnels.horseshoe_tunnel(length=L, **kw)
    with pytest.raises(ValueError, match="shape: expected one of"):
        tunnels.make_tunnel("oval", width=1.0, height=1.0, length=1.0)


@pytest.mark.parametrize("name", list(_shapes()))
@pytest.mark.parametrize("ue", [[40.0, -2.0, 1.5], [12.0, 2.5, 1.0], [-30.0, 0.5, 2.0]])
def test_specular_points_lie_on_the_right_surfaces(name, ue):
    tun = _shapes()[name]
    a0 = np.array([0.0, 0.3, tun.height - 0.4])
    arr = arrays.make_array(2, 2, fc=28e9, azimuth=0.0, elevation=np.radians(-20), origin=a0)
    ue = np.asarray(ue)
    paths = propagation.trace_paths(tun, arr, ue, fc=28e9, front_only=False)
    traced = {p.surface for p in paths if p.kind == "reflection"}
    # brute force: a surface reflects iff the mirror-image specular point lies on its rectangle
    expected = set()
    for f in tun.facets:
        pt = reflection.specular_point(a0, ue, f.plane)
        if f.contains(pt, tol=1e-9):
            expected.add(f.name)
    assert traced == expected and "road" in expected and len(expected) >= 2
    by = {f.name: f for f in tun.facets}
    for p in paths[1:]:
        f = by[p.surface]
        assert p.surface_kind == f.kind
        assert f.plane.signed_distance(p.point) == pytest.approx(0.0, abs=1e-9)
        # law of reflection: equal angles to the normal, and the unfolded length
        cos_in = (ue - p.point) @ f.normal / np.linalg.norm(ue - p.point)
        cos_out = (a0 - p.point) @ f.normal / np.linalg.norm(a0 - p.point)
        assert cos_in == pytest.approx(cos_out, abs=1e-9)
        assert p.length == pytest.approx(
            np.linalg.norm(ue - p.point) + np.linalg.norm(a0 - p.point), rel=1e-12
        )
        if name == "rectangular":
            want = {"ceiling": (2, H), "wall left": (1, W / 2), "wall right": (1, -W / 2)}
            want["road"] = (2, 0.0)
            axis, value = want[p.surface]
            assert p.point[axis] == pytest.approx(value, abs=1e-9)


def test_example_preset_is_the_issue_question():
    sc = tk.load_scenario("example-rectangular-28ghz")
    assert sc.family == "user" and sc.paper == ""
    tun = sc.tunnel()
    assert (tun.width, tun.height) == (8.0, 6.0)
    assert sc.get("radio.fc") == 28e9 and sc.get("radio.bandwidth") == 400e6
    assert H - sc.base_station()[2] == pytest.approx(0.2)
    arrs = sc.arrays()
    lam = C / 28e9
    for a in arrs:
        assert a.M == 64 and np.degrees(a.elevation) == pytest.approx(-20.0)
        d = np.linalg.norm(a.local[1] - a.local[0])
        assert d == pytest.approx(lam / 2, rel=1e-12)
    assert {p.name for p in tun.plates} == {"RRM left", "RRM right"}


def test_spacing_in_metres_or_wavelengths():
    sc = tk.load_scenario("example-rectangular-28ghz")
    s1 = S.with_values(sc, {"base_station.arrays[*].spacing_m": 0.004})
    s2 = S.with_values(sc, {"base_station.arrays[0].spacing_wavelengths": 1.0})
    assert np.linalg.norm(s1.arrays()[1].local[1]) == pytest.approx(0.004)
    a0, a1 = s2.arrays()
    assert np.linalg.norm(a0.local[1]) == pytest.approx(C / 28e9)
    assert np.linalg.norm(a1.local[1]) == pytest.approx(C / 28e9 / 2)


# a weak path of a 4 x 4 array may stay below the noise: the ML route says so, and that is physics
@pytest.mark.filterwarnings("ignore::tunnelkit.extraction.ml.MLDetectionWarning")
@pytest.mark.parametrize("shape", ["rectangular", "horseshoe", "semicircular"])
def test_user_scenario_runs_the_signal_route(shape):
    sc = S.with_values(
        tk.load_scenario("example-rectangular-28ghz"),
        {
            "tunnel.kind": shape,
            "base_station.arrays[*].shape": [4, 4],
            "radio.n_symbols": 4,
            "radio.comb": 8,
        },
    )
    route = signal_route.SignalRoute.from_scenario(sc)
    ep = route.epoch(5, np.random.default_rng(1))
    assert ep.paths[0].kind == "los" and len(ep.paths) >= 3
    kinds = {p.surface_kind for p in ep.paths}
    assert {"los", "road", "ceiling"} <= kinds
    m = ep.measurements
    assert np.all(np.isfinite(m.d))
    # the LoS path is recovered: its delay (with the clock bias) within 10 cm
    los = np.flatnonzero(ep.truth_index == 0)
    assert los.size == 1
    want = ep.paths[0].length + C * ep.snapshot.clock_bias
    assert m.d[los[0]] == pytest.approx(want, abs=0.1)


def test_slalom_trajectory_of_a_user_tunnel():
    sc = S.with_values(
        tk.load_scenario("example-rectangular-28ghz"),
        {"trajectory.kind": "slalom", "trajectory.amplitude": 1.0, "trajectory.wavelength": 20.0},
    )
    tr = sc.trajectory()
    y = tr.position[:, 1]
    assert y.max() == pytest.approx(-1.0, abs=0.02) and y.min() == pytest.approx(-3.0, abs=0.02)
    np.testing.assert_allclose(tr.velocity[:, 0], -13.89)
    # slalom amplitude that hits the wall is refused, naming the trajectory
    with pytest.raises(S.ScenarioError, match="trajectory: leaves the tunnel"):
        S.with_values(sc, {"trajectory.amplitude": 2.5})
