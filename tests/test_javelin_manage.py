import numpy as np
import pytest
from javelin_geometric import geometric_paths, toy_reflectors

from tunnelkit.tracking.javelin import FixedBirth, JavelinConfig, JavelinState, PathMeasurements
from tunnelkit.tracking.javelin.lostest import los_test
from tunnelkit.tracking.javelin.manage import intersection, manage_tracks, static_doppler

BS = np.array([0.0, 0.0, 4.8])
PU = np.array([-25.0, 1.3, 1.0])
VU = np.array([9.0, 1.0, 0.0])


def _truth():
    return geometric_paths(PU, VU, toy_reflectors(), np.random.default_rng(0), bs=BS, shuffle=False)


def test_los_test_eq60_61():
    assert los_test([30.0, 25.0, 40.0], [10.0, 24.0, 20.0], 0.2) == 1
    assert los_test([30.0, 31.0], [10.0, 20.0], 0.2) is None  # best ratio 1.55 fails eq. 61
    assert los_test([30.0, 25.0], [10.0, 24.0], 0.2, candidates=[0]) is None
    assert los_test([np.nan], [10.0], 0.2) is None


def test_intersection_recovers_the_true_vue():
    meas, truth = _truth()
    for j in range(len(meas)):
        yz = intersection(meas.phi[j], meas.psi[j], PU[0], BS)
        np.testing.assert_allclose(yz, truth["vue"][j, 1:], atol=1e-9)
    assert intersection(np.pi / 2, 0.0, -10.0) is None  # ray parallel to x = x_u
    assert intersection(0.0, 0.0, -10.0) is None  # ray pointing away


def test_static_doppler_matches_the_geometric_source():
    meas, truth = _truth()
    for j in range(len(meas)):
        assert static_doppler(PU, truth["vue"][j], VU, BS) == pytest.approx(meas.v[j], abs=1e-12)


def _state_with_vues(n):
    st = JavelinState.initial(PU, 1.0)
    for k in range(n):
        st.append([5.0 + k, 1.0], np.eye(2))
    return st


@pytest.mark.parametrize(("zeta", "survivors"), [(0, [2]), (1, [2]), (2, [1, 2, 3])])
def test_deaths_after_zeta_misses(zeta, survivors):
    st = _state_with_vues(3)
    meas = PathMeasurements.from_arrays([0.1], [0.0], kappa=[np.nan], d=[np.nan])
    cfg = JavelinConfig(max_misses=zeta, base_station=tuple(BS))
    res = manage_tracks(st, meas, [(2, 0)], cfg)
    assert st.ids == survivors
    assert res.pairs == [(survivors.index(2) + 1, 0)]
    assert sorted(res.dead) == sorted(set([1, 2, 3]) - set(survivors))


def test_births_los_and_dynamic_paths():
    meas, truth = _truth()
    # a fifth path from a moving reflector: wall geometry but a Doppler 5 m/s off
    m = PathMeasurements.from_arrays(
        np.append(meas.phi, meas.phi[1]),
        np.append(meas.psi, meas.psi[1]),
        np.append(meas.kappa, meas.kappa[1]),
        np.append(meas.d, meas.d[1]),
        np.append(meas.v, meas.v[1] + 5.0),
    )
    st = JavelinState.initial(PU, 1.0)
    cfg = JavelinConfig(base_station=tuple(BS))
    res = manage_tracks(st, m, [], cfg, v_u=VU)
    assert res.los and res.los_path == 0  # the LoS passes eq. 61 exactly (d = kappa)
    assert len(res.born) == 5 and res.dynamic == [res.born[-1]]
    assert st.transient == [False] * 4 + [True]
    np.testing.assert_allclose(st.x[3:11].reshape(4, 2), truth["vue"][1:, 1:], atol=1e-9)
    np.testing.assert_allclose(st.P[3:5, 3:5], 100.0 * np.eye(2))
    assert (0, 0) in res.pairs and len(res.pairs) == 6
    # without update_with_births the newborns wait for the next epoch
    st2 = JavelinState.initial(PU, 1.0)
    res2 = manage_tracks(st2, m, [], cfg, v_u=VU, initiator=FixedBirth(update_at_birth=False))
    assert res2.pairs == [(0, 0)]
