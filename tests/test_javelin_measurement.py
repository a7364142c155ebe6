import numpy as np
import pytest
from javelin_geometric import geometric_paths, toy_reflectors

from tunnelkit.crlb import numeric_jacobian
from tunnelkit.reflection import reflector_point
from tunnelkit.tracking.javelin import (
    JavelinWarning,
    PathMeasurements,
    measurement_model,
    track_model,
)

BS = np.array([0.0, 0.0, 4.8])


def _random_states(rng, n):
    for _ in range(n):
        nv = rng.integers(0, 5)
        x = np.concatenate(
            [
                [rng.uniform(-48, -5), rng.uniform(-3, 3), rng.uniform(0.5, 2)],
                rng.uniform(-12, 12, 2 * nv),
            ]
        )
        yield x


@pytest.mark.parametrize("kappa_model", ["reflector", "vue"])
def test_jacobian_matches_finite_differences(kappa_model):
    rng = np.random.default_rng(1)
    for x in _random_states(rng, 20):
        h, H = measurement_model(x, BS, kappa_model)
        Hn = numeric_jacobian(lambda s: measurement_model(s, BS, kappa_model)[0], x, step=1e-6)
        np.testing.assert_allclose(H, Hn, atol=1e-6, rtol=1e-6)
        assert h.size == 4 * (1 + (x.size - 3) // 2) - 1


def test_kappa_is_eq45_reflector_distance():
    rng = np.random.default_rng(2)
    for x in _random_states(rng, 10):
        pred, _ = track_model(x, BS)
        pu = x[:3]
        for k, yz in enumerate(x[3:].reshape(-1, 2)):
            pv = np.array([pu[0], *yz])
            pr = reflector_point(pu, pv, BS)
            assert pred[k + 1, 2] == pytest.approx(np.linalg.norm(pr - BS), rel=1e-10)
            assert pred[k + 1, 3] == pytest.approx(np.linalg.norm(pv - BS), rel=1e-12)
        assert pred[0, 2] == pytest.approx(np.linalg.norm(pu - BS))


def test_geometric_source_is_the_model_at_the_true_state():
    rng = np.random.default_rng(3)
    pu = np.array([-30.0, 1.2, 1.0])
    meas, truth = geometric_paths(pu, [10.0, 0, 0], toy_reflectors(), rng, bs=BS, shuffle=False)
    vue = truth["vue"]
    x = np.concatenate([pu, vue[1:, 1:].ravel()])
    pred, _ = track_model(x, BS)
    np.testing.assert_allclose(pred[:, 0], meas.phi, atol=1e-12)
    np.testing.assert_allclose(pred[:, 1], meas.psi, atol=1e-12)
    np.testing.assert_allclose(pred[:, 2], meas.kappa, atol=1e-9)
    np.testing.assert_allclose(pred[:, 3], meas.d, atol=1e-12)
    # vertical walls: their VUE keeps z_u, the mirror of y in y = +-4.5
    np.testing.assert_allclose(vue[1], [-30.0, 9.0 - 1.2, 1.0], atol=1e-12)


def test_algorithm1_sanitisation():
    with pytest.warns(JavelinWarning, match="NaN angle"):
        m = PathMeasurements.from_arrays(
            [0.1, np.nan, 0.2, 0.3],
            [0, 0, 0, 0],
            kappa=[5.0, 5.0, -1.0, 7.0],
            d=[6.0, 6.0, 7.0, -2.0],
        )
    np.testing.assert_array_equal(m.source, [0, 2])  # NaN angle and d < 0 discarded
    assert np.isnan(m.kappa[1])  # kappa < 0 -> far field
    assert len(PathMeasurements.empty()) == 0
    with pytest.raises(ValueError, match=r"^psi"):
        PathMeasurements.from_arrays([0.1, 0.2], [0.0])


def test_bad_state_rejected():
    with pytest.raises(ValueError, match=r"^x"):
        track_model(np.zeros(4))
    with pytest.raises(ValueError, match=r"^x"):
        track_model(np.array([0.0, 0.0, 1.0]))  # on the base station's axis


def test_derived_fields_follow_the_stored_ones():
    """The container's derived fields: ``near_field`` where a curvature is given, ``delta_d``
    (eq. 52) re-referenced to the first row of a subset, ``z`` (eq. 54), unit ``direction``
    from the angles, ``wave_origins`` from ``origin`` (kept by ``subset`` and ``sanitised``,
    needed by ``wave_origins``, three finite coordinates)."""
    pm = PathMeasurements(
        [0.1, -0.2, 0.3], [0.05, 0.0, -0.1], [12.0, np.nan, 30.0], [10.0, 13.5, 20.0],
        [1.0, -2.0, 0.5], origin=[1.0, 2.0, 3.0],
    )  # fmt: skip
    np.testing.assert_array_equal(pm.near_field, [True, False, True])
    np.testing.assert_array_equal(pm.delta_d, [0.0, 3.5, 10.0])
    np.testing.assert_array_equal(pm.z, np.r_[pm.phi, pm.psi, pm.kappa, 3.5, 10.0])
    u = pm.direction
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(np.arctan2(u[:, 1], u[:, 0]), pm.phi, atol=1e-15)
    np.testing.assert_allclose(np.arcsin(u[:, 2]), pm.psi, atol=1e-15)
    w = pm.wave_origins
    np.testing.assert_allclose(w[0], [1.0, 2.0, 3.0] + 12.0 * u[0], atol=1e-12)
    assert np.isnan(w[1]).all()
    tail = pm.subset(np.array([1, 2]))
    np.testing.assert_array_equal(tail.delta_d, [0.0, 6.5])
    np.testing.assert_array_equal(tail.origin, pm.origin)
    np.testing.assert_array_equal(tail.source, [1, 2])
    np.testing.assert_array_equal(pm.sanitised(0.0)[0].origin, pm.origin)
    bare = PathMeasurements.from_arrays([0.1], [0.0], [5.0], [5.0], [0.0])
    assert bare.origin is None
    with pytest.raises(ValueError, match=r"^origin"):
        _ = bare.wave_origins
    with pytest.raises(ValueError, match=r"^origin"):
        PathMeasurements([0.1], [0.0], [5.0], [5.0], [0.0], origin=[0.0, 1.0])
    with pytest.raises(ValueError, match=r"^origin"):
        PathMeasurements([0.1], [0.0], [5.0], [5.0], [0.0], origin=[0.0, np.nan, 1.0])
