import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tunnelkit import reflection, tunnel2d
from tunnelkit.geometry import Plane, line
from tunnelkit.tunnel2d import Tunnel2D

coord = st.floats(-100, 100, allow_nan=False)


def test_virtual_stations_match_jiang_eq3(jiang):
    # eq. 3-4 written out for A = 3, B = -3 and the BS at the origin: x_v = -2AC/(A^2+B^2)
    A, B = 3.0, -3.0
    expect = [
        [-2 * A * C / (A * A + B * B), -2 * B * C / (A * A + B * B)] for C in (40.0, -23.6396)
    ]
    np.testing.assert_allclose(jiang["vs"], expect, atol=1e-12)
    assert jiang["tunnel"].width == pytest.approx(15.0, abs=1e-5)


def test_tunnel_frame_and_walls(jiang):
    t = jiang["tunnel"]
    np.testing.assert_allclose(t.axis, [np.sqrt(0.5), np.sqrt(0.5)])
    np.testing.assert_allclose(t.wall_distances(jiang["start"]), [6.0, 9.0], atol=1e-4)
    q = np.array([[12.0, 3.0], [-40.0, 14.0]])
    np.testing.assert_allclose(t.to_tunnel_frame(t.from_tunnel_frame(q)), q, atol=1e-12)
    assert t.contains(jiang["bs"]) and not t.contains([0.0, 30.0])


@settings(max_examples=200, deadline=None)
@given(coord, coord, st.floats(-5, 5), st.floats(-5, 5), coord)
def test_mirror_is_an_involution_and_keeps_distance(px, py, a, b, c):
    if abs(a) + abs(b) < 1e-3:
        return
    ln = line(a, b, c)
    p = np.array([px, py])
    m = ln.mirror(p)
    np.testing.assert_allclose(ln.mirror(m), p, atol=1e-9)
    assert ln.signed_distance(m) == pytest.approx(-ln.signed_distance(p), abs=1e-9)


@settings(max_examples=200, deadline=None)
@given(st.floats(0.5, 14.5), st.floats(0.5, 14.5), st.floats(-80, 80))
def test_specular_path_length_equals_virtual_station_distance(c_bs, c_v, along):
    t = Tunnel2D.from_lines((3, -3, 40), (3, -3, -23.6396))
    bs = t.from_tunnel_frame(np.array([0.0, c_bs]))
    veh = t.from_tunnel_frame(np.array([along, c_v]))
    for w in t.walls:
        r = w.project(reflection.specular_point(bs, veh, w))  # lies on the wall
        assert abs(w.signed_distance(r)) < 1e-9
        folded = np.linalg.norm(r - bs) + np.linalg.norm(veh - r)
        assert folded == pytest.approx(np.linalg.norm(veh - w.mirror(bs)), rel=1e-12)
        # equal angles: incoming and outgoing make the same angle with the normal
        n = w.normal
        u_in, u_out = (r - bs) / np.linalg.norm(r - bs), (veh - r) / np.linalg.norm(veh - r)
        assert abs(u_in @ n) == pytest.approx(abs(u_out @ n), abs=1e-9)


def test_reflector_point_eq45_on_bisector_and_on_bs_vue_line():
    rng = np.random.default_rng(3)
    pu = rng.uniform(-5, 5, (50, 3)) + np.array([20.0, 0.0, 1.0])
    wall = Plane(np.array([0.0, 1.0, 0.2]), -5.0)
    pv = wall.mirror(pu)
    pr = reflection.reflector_point(pu, pv)
    assert np.all(np.abs(wall.signed_distance(pr)) < 1e-9)  # on the wall (the UE-VUE bisector)
    cross = np.cross(pr, pv)  # collinear with the origin (BS) and the VUE
    assert np.abs(cross).max() < 1e-9
    # eq. 45 literally: p_r = (n.p_u + n.p_v) / (2 n.p_v) p_v
    n = (pv - pu) / np.linalg.norm(pv - pu, axis=-1, keepdims=True)
    lit = (np.sum(n * pu, -1) + np.sum(n * pv, -1)) / (2 * np.sum(n * pv, -1))
    np.testing.assert_allclose(pr, lit[:, None] * pv, atol=1e-10)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: line(0, 0, 1), "A, B: degenerate"),
        (lambda: Plane(np.array([0.0, 0.0, 0.0]), 1.0), "normal: degenerate"),
        (lambda: line(1, np.nan, 0), "B: must be finite"),
        (lambda: Tunnel2D.from_lines((1, 0, 0), (0, 1, 0)), "parallel"),
        (lambda: Tunnel2D.from_lines((1, 0, 0), (2, 0, 0)), "zero width"),
        (lambda: reflection.specular_point([0, 1], [0, -1], line(0, 1, 0)), "same side"),
        (lambda: reflection.specular_point([0, 0], [0, 1], line(0, 1, 0)), "source: lies on"),
        (lambda: reflection.reflector_point([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]), "coincides"),
        (lambda: line(1, 0, 0).mirror([1.0, 2.0, 3.0]), "p: expected points with 2"),
        (lambda: tunnel2d.virtual_stations([0, 0], []), "walls: need"),
    ],
)
def test_bad_geometry_input_names_the_parameter(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


def test_require_inside(jiang):
    t = jiang["tunnel"]
    t.require_inside("vehicle", jiang["start"])
    with pytest.raises(ValueError, match="vehicle: point"):
        t.require_inside("vehicle", [[10.0, 14.0], [0.0, 30.0]])
