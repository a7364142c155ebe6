import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from tunnelkit.tracking.javelin import FixedNoise, JavelinConfig, PathMeasurements, track_model
from tunnelkit.tracking.javelin.update import StackedMeasurement, joseph_update, stack_measurement


def test_joseph_form_equals_filterpy_on_a_linear_problem():
    rng = np.random.default_rng(0)
    D, K = 5, 3
    A = rng.standard_normal((D, D))
    P = A @ A.T + np.eye(D)
    H = rng.standard_normal((K, D))
    R = np.diag([0.5, 1.0, 2.0])
    x = rng.standard_normal(D)
    z = rng.standard_normal(K)
    m = StackedMeasurement(z, H @ x, H, R, np.zeros(K, bool), [], None)
    x1, P1, nis = joseph_update(x, P, m)
    kf = KalmanFilter(dim_x=D, dim_z=K)
    kf.x, kf.P, kf.H, kf.R = x.copy(), P.copy(), H, R
    kf.update(z)
    np.testing.assert_allclose(x1, kf.x, atol=1e-12)
    np.testing.assert_allclose(P1, kf.P, atol=1e-10)
    y = z - H @ x
    assert nis == pytest.approx(y @ np.linalg.solve(H @ P @ H.T + R, y))
    np.testing.assert_array_equal(P1, P1.T)


def test_stack_uses_los_as_tdoa_reference_and_correlated_blocks():
    x = np.array([-20.0, 1.0, 1.0, 8.0, 1.0, -10.0, 1.0])
    pred, J = track_model(x, (0, 0, 4.8))
    bias = 7.0
    meas = PathMeasurements.from_arrays(
        pred[:, 0], pred[:, 1], kappa=[pred[0, 2], np.nan, pred[2, 2]], d=pred[:, 3] + bias
    )
    cfg = JavelinConfig()
    corr = FixedNoise(correlated_delta_d=True)
    m = stack_measurement(pred, J, meas, [(0, 0), (1, 1), (2, 2)], cfg, los_path=0, noise=corr)
    assert m.reference == (0, 0)
    assert [lab[0] for lab in m.labels].count("kappa") == 2
    dd = [k for k, lab in enumerate(m.labels) if lab[0] == "delta_d"]
    np.testing.assert_allclose(m.residual(), 0.0, atol=1e-9)  # clock bias cancels in the TDoA
    s2 = cfg.sigma_delta_d**2
    np.testing.assert_allclose(m.R[np.ix_(dd, dd)], [[s2, s2 / 2], [s2 / 2, s2]])
    # without LoS the shortest associated path is the reference
    m2 = stack_measurement(pred, J, meas, [(1, 1), (2, 2)], cfg)
    assert m2.reference == (int(np.argmin(pred[1:, 3])) + 1, int(np.argmin(pred[1:, 3])) + 1)
