import numpy as np
import pytest
from javelin_geometric import toy_reflectors

from tunnelkit.crlb import numeric_jacobian
from tunnelkit.tracking.javelin import JavelinConfig, JavelinState
from tunnelkit.tracking.javelin.motion import motion_increment, predict


def _state_with_wall_vues(pu):
    st = JavelinState.initial(pu, 1.0)
    for pl in toy_reflectors():
        st.append(pl.mirror(np.asarray(pu))[1:], np.eye(2))
    return st


def test_ue_moves_by_speed_and_heading():
    st = JavelinState.initial([-30.0, 1.0, 1.0], 1.0)
    x, P = predict(st, 10.0, np.radians(30), 0.1, JavelinConfig())
    np.testing.assert_allclose(
        x, [-30.0 + np.cos(np.radians(30)), 1.0 + np.sin(np.radians(30)), 1.0]
    )
    assert np.all(np.linalg.eigvalsh(P - st.P) >= -1e-15)  # Q is PSD


@pytest.mark.parametrize("vue_motion", ["random_walk", "mirror"])
def test_G_is_the_derivative_of_the_increment(vue_motion):
    st = _state_with_wall_vues([-30.0, 1.0, 1.0])

    def inc(u):
        return motion_increment(st, u[0], u[1], 0.1, vue_motion)[0]

    _, G = motion_increment(st, 8.0, 0.2, 0.1, vue_motion)
    np.testing.assert_allclose(G, numeric_jacobian(inc, np.array([8.0, 0.2])), atol=1e-8)


def test_mirror_motion_is_exact_for_planar_reflectors():
    pu0 = np.array([-30.0, 1.0, 1.0])
    st = _state_with_wall_vues(pu0)
    speed, heading, dt = 10.0, np.radians(20), 0.1
    x, _ = predict(st, speed, heading, dt, JavelinConfig(), vue_motion="mirror")
    pu1 = pu0 + dt * speed * np.array([np.cos(heading), np.sin(heading), 0.0])
    truth = np.concatenate([pu1] + [pl.mirror(pu1)[1:] for pl in toy_reflectors()])
    np.testing.assert_allclose(x, truth, atol=1e-12)
    # the paper's random walk leaves the VUEs where they were
    x_rw, _ = predict(st, speed, heading, dt, JavelinConfig())
    np.testing.assert_allclose(x_rw[3:], st.x[3:])


def test_negative_dt_rejected():
    st = JavelinState.initial([-30.0, 1.0, 1.0], 1.0)
    with pytest.raises(ValueError, match=r"^dt"):
        predict(st, 1.0, 0.0, -0.1, JavelinConfig())
