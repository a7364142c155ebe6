import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import propagation as P
from tunnelkit.arrays import make_array
from tunnelkit.constants import C

FC = 5.9e9


@pytest.fixture(scope="module")
def scene():
    sc = tk.load_scenario("italiano2026-straight")
    tun = sc.tunnel()
    arrs = P.scenario_arrays(sc)
    return {"sc": sc, "tunnel": tun, "arrays": arrs, "traj": sc.trajectory(tun)}


def _paths(scene, ue, vel=(0.0, 0.0, 0.0), **kw):
    arr = P.select_array(scene["arrays"], ue)
    return arr, P.trace_paths(kw.pop("tunnel", scene["tunnel"]), arr, ue, vel, fc=FC, **kw)


def test_scenario_geometry(scene):
    tun, arrs = scene["tunnel"], scene["arrays"]
    assert tun.x_range == (-50.0, 50.0) and len(tun.facets) == 13 and len(tun.plates) == 4
    assert (
        tun.contains([0, 0, 4.8])
        and not tun.contains([0, 4.9, 4.0])
        and not tun.contains([60, 0, 1])
    )
    assert {a.name for a in arrs} == {"-x", "+x"} and all(a.M == 100 for a in arrs)
    np.testing.assert_allclose(arrs[1].boresight, [np.cos(np.radians(30)), 0, -0.5], atol=1e-12)
    assert np.all(tun.contains(scene["traj"].position))
    assert {p.kind for p in tun.plates} == {"rrm"} and all(
        p.material == "metal" for p in tun.plates
    )


def test_los_lengths_are_exact_distances_to_every_antenna(scene):
    ue = np.array([20.0, -2.5, 1.5])
    arr, paths = _paths(scene, ue)
    los = paths[0]
    assert los.kind == "los"
    assert los.length == pytest.approx(np.linalg.norm(ue - arr.origin), abs=1e-12)
    np.testing.assert_allclose(los.lengths, np.linalg.norm(arr.world - ue, axis=1), atol=1e-12)
    np.testing.assert_allclose(los.direction, (ue - arr.origin) / los.length, atol=1e-12)
    dz = ue[2] - arr.origin[2]  # the reference antenna's height comes from the preset's mount
    assert los.elevation == pytest.approx(np.arctan2(dz, np.hypot(20, 2.5)), abs=1e-12)  # eq. 47


def test_reflections_obey_the_image_method(scene):
    ue = np.array([25.0, -2.5, 1.5])
    arr, paths = _paths(scene, ue)
    refl = [p for p in paths if p.kind == "reflection"]
    assert {p.surface_kind for p in refl} >= {"road", "rrm"}
    surfaces = {s.name: s for s in scene["tunnel"].surfaces}
    for p in refl:
        s = surfaces[p.surface]
        assert abs(float(s.plane.signed_distance(p.point))) < 1e-9  # on the plane
        assert s.contains(p.point)  # inside the finite facet
        unfolded = np.linalg.norm(ue - p.point) + np.linalg.norm(p.point - arr.origin)
        assert p.length == pytest.approx(unfolded, abs=1e-9)  # |VUE - BS| = |UE-P| + |P-BS|
        # equal angles of incidence and reflection
        a, b = ue - p.point, arr.origin - p.point
        n = s.normal
        assert a @ n / np.linalg.norm(a) == pytest.approx(b @ n / np.linalg.norm(b), abs=1e-9)
        # reciprocity: mirror the array instead of the UE, same length
        assert p.length == pytest.approx(np.linalg.norm(s.plane.mirror(arr.origin) - ue), abs=1e-9)
        np.testing.assert_allclose(
            p.lengths, np.linalg.norm(arr.world - p.source, axis=1), atol=1e-9
        )
        assert p.lengths_srnf[0] == pytest.approx(p.length, abs=1e-9)
        assert p.kappa_srnf == pytest.approx(
            np.linalg.norm(p.point - arr.origin), abs=1e-12
        )  # eq. 51


def test_plate_reflection_vanishes_when_the_specular_point_falls_off(scene):
    ue = np.array([25.0, -2.5, 1.5])
    _, paths = _paths(scene, ue)
    assert "RRM bottom right" in {p.surface for p in paths}
    moved = P.road_marking(
        x_range=[35.0, 45.0], y=-4.6, z=0.3, width=0.3, inclination_deg=55, name="RRM bottom right"
    )
    others = tuple(p for p in scene["tunnel"].plates if p.name != "RRM bottom right")
    tun = P.semicircular_tunnel(plates=(*others, moved))
    _, paths2 = _paths(scene, ue, tunnel=tun)
    assert "RRM bottom right" not in {p.surface for p in paths2}
    assert len(paths2) == len(paths) - 1


def test_truck_blocks_los(scene):
    ue = np.array([30.0, -2.5, 1.5])
    _, clear = _paths(scene, ue)
    truck = P.truck_box(20.0, -2.5, height=4.0)
    _, blocked = _paths(scene, ue, tunnel=scene["tunnel"].with_blockers(truck))
    assert clear[0].kind == "los" and all(p.kind != "los" for p in blocked)
    assert truck.blocks(ue, [0, 0, 4.8]) and not truck.blocks([30, 2.5, 1.5], [40, 2.5, 1.5])


def test_doppler_sign_and_finite_difference(scene):
    ue, vel = np.array([30.0, -2.5, 1.5]), np.array([-14.0, 0.3, 0.0])
    _arr, paths = _paths(scene, ue, vel)
    dt = 1e-4
    _, later = _paths(scene, ue + vel * dt, vel)
    by_name = {p.surface: p for p in later}
    for p in paths:
        rate = (by_name[p.surface].length - p.length) / dt
        assert p.range_rate == pytest.approx(rate, abs=1e-3)
        assert p.velocity == pytest.approx(-rate, abs=1e-3)
        assert p.doppler == pytest.approx(FC * p.velocity / C)
    assert paths[0].velocity > 0  # approaching: positive Doppler


def test_concrete_is_a_partial_reflector():
    g = P.fresnel_te(P.concrete_permittivity(FC), np.array([1.0, 0.5, 1e-3]))
    assert (
        np.all(np.abs(g) < 1) and abs(g[-1]) > 0.99 and abs(g[0]) == pytest.approx(0.39, abs=0.02)
    )


def test_bad_input(scene):
    arr = scene["arrays"][1]
    with pytest.raises(ValueError, match=r"ue.*outside"):
        P.trace_paths(scene["tunnel"], arr, [0, 6.0, 1.0], fc=FC)
    with pytest.raises(ValueError, match="width"):
        P.road_marking(x_range=[1, 2], y=3, z=1, width=0, inclination_deg=90)
    with pytest.raises(ValueError, match="zero area"):
        P.Facet([0, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 1], name="plate")
    with pytest.raises(ValueError, match="sticks out"):
        P.semicircular_tunnel(
            plates=(P.road_marking(x_range=[1, 2], y=4.99, z=3, width=1, inclination_deg=90),)
        )
    with pytest.raises(TypeError, match="array"):
        P.trace_paths(scene["tunnel"], "array", [10, 0, 1], fc=FC)
    with pytest.raises(ValueError, match="model"):
        P.trace_paths(scene["tunnel"], arr, [10, 0, 1], fc=FC)[0].delta("plane")


def test_back_lobe_dropped_and_small_array():
    tun = P.semicircular_tunnel()
    arr = make_array(2, 2, fc=FC, azimuth=0.0, elevation=0.0, origin=[0, 0, 4.8])
    assert P.trace_paths(tun, arr, [-20, 0, 1.5], fc=FC) == []
    assert len(P.trace_paths(tun, arr, [-20, 0, 1.5], fc=FC, front_only=False)) >= 2


def test_figures_build(scene):
    from tunnelkit.plots import tunnel3d_figure, wave_origins_figure

    arr, paths = _paths(scene, np.array([25.0, -2.5, 1.5]))
    fig = tunnel3d_figure(scene["tunnel"], [arr], paths, [25.0, -2.5, 1.5], x_range=(0, 30))
    lines = [t for t in fig.data if t.type == "scatter3d" and t.mode == "lines"]
    assert len(lines) == len(paths)
    np.testing.assert_allclose([lines[0].x[0], lines[0].y[0], lines[0].z[0]], [25.0, -2.5, 1.5])
    wo = wave_origins_figure({"a": np.array([[1.0, 2.0, 3.0], [np.nan] * 3])})
    assert len(wo.data[0].x) == 1
