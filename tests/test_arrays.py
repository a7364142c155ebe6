import numpy as np
import pytest

from tunnelkit import arrays
from tunnelkit.constants import wavelength


def test_ura_layout_reference_corner_and_spacing():
    p = arrays.ura(3, 4, 0.5)
    assert p.shape == (12, 3)
    np.testing.assert_array_equal(p[0], [0, 0, 0])
    np.testing.assert_array_equal(p[:, 2], 0)
    np.testing.assert_allclose(p[1] - p[0], [0.5, 0, 0])  # along a row
    np.testing.assert_allclose(p[4] - p[0], [0, 0.5, 0])  # next row
    assert arrays.ula(5, 1.0).shape == (5, 3)


def test_rotation_is_right_handed_with_boresight_as_local_z():
    R = arrays.rotation(0.0, np.radians(-30))
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)
    np.testing.assert_allclose(R[:, 2], [np.cos(np.radians(30)), 0, -0.5], atol=1e-12)
    np.testing.assert_allclose(R[:, 0], [0, 1, 0], atol=1e-12)  # local x horizontal, to the left
    np.testing.assert_allclose(arrays.rotation(np.pi, 0)[:, 2], [-1, 0, 0], atol=1e-12)


def test_make_array_half_wavelength_and_frames_round_trip():
    a = arrays.make_array(4, 4, fc=5.9e9, azimuth=0.3, elevation=-0.2, origin=[1, 2, 3])
    lam = wavelength(5.9e9)
    assert a.M == 16
    np.testing.assert_allclose(np.linalg.norm(a.world[1] - a.world[0]), lam / 2)
    q = np.random.default_rng(0).normal(size=(5, 3))
    np.testing.assert_allclose(a.to_local(a.to_world(q)), q, atol=1e-12)
    np.testing.assert_allclose(a.world[0], [1, 2, 3])
    assert a.in_front(a.origin + 2 * a.boresight) and not a.in_front(a.origin - a.boresight)


@pytest.mark.parametrize(
    ("pos", "m", "msg"),
    [
        (np.array([[0, 0, 0], [1, 0, 0.1], [0, 1, 0]]), None, "xy-plane"),
        (np.array([[0.1, 0, 0], [1, 0, 0], [0, 1, 0]]), None, "origin"),
        (np.array([[0, 0, 0], [1, 0, 0]]), 3, "M = 3"),
        (np.array([[0, 0, 0], [0, 0, 0]]), None, "coincide"),
        (np.zeros((3, 2)), None, "shape"),
    ],
)
def test_bad_element_positions_name_the_parameter(pos, m, msg):
    with pytest.raises(ValueError, match=f"element_positions.*{msg}"):
        arrays.check_element_positions("element_positions", pos, m)


def test_bad_array_arguments():
    with pytest.raises(ValueError, match="n_rows"):
        arrays.ura(0, 3, 0.5)
    with pytest.raises(ValueError, match="elevation"):
        arrays.rotation(0.0, 2.0)
