"""The Huber-weighted update (tunnelkit.studies.robust_update) against a brute-force minimum."""

import numpy as np
import pytest
from scipy.optimize import minimize

from tunnelkit.studies.robust_update import HUBER_K, HuberUpdater, huber_weights
from tunnelkit.tracking.javelin.update import StackedMeasurement, joseph_update


def _spd(rng, n, scale=1.0):
    a = rng.normal(size=(n, n))
    return scale * (a @ a.T + n * np.eye(n))


def _huber_objective(dx, y, H, Pinv, Linv, k):
    e = Linv @ (y - H @ dx)
    a = np.abs(e)
    rho = np.where(a <= k, 0.5 * e**2, k * a - 0.5 * k**2)
    return 0.5 * dx @ Pinv @ dx + rho.sum()


@pytest.mark.parametrize("seed", [3, 11, 2027])
def test_weights_give_the_minimum_of_the_huber_objective(seed):
    rng = np.random.default_rng(seed)
    D, K = 3, 5
    P, R = _spd(rng, D), _spd(rng, K, 0.2)
    H = rng.normal(size=(K, D))
    y = rng.normal(size=K)
    y[1] += 40.0  # one gross error
    w = huber_weights(y, H, P, R, HUBER_K)
    assert w[1] < 0.2 and np.all((w > 0) & (w <= 1))
    L = np.linalg.cholesky(R)
    Rw = (L / np.sqrt(w)) @ (L / np.sqrt(w)).T
    dx = P @ H.T @ np.linalg.solve(H @ P @ H.T + Rw, y)
    args = (y, H, np.linalg.inv(P), np.linalg.inv(L), HUBER_K)
    best = minimize(_huber_objective, np.zeros(D), args=args, method="BFGS", tol=1e-12)
    np.testing.assert_allclose(dx, best.x, atol=1e-5)
    assert _huber_objective(dx, *args) <= best.fun + 1e-9


def test_small_innovations_give_the_kalman_update():
    rng = np.random.default_rng(5)
    P, R = _spd(rng, 2), np.diag([0.5, 0.7])
    H = rng.normal(size=(2, 2))
    y = 0.01 * rng.normal(size=2)
    assert np.all(huber_weights(y, H, P, R) == 1.0)
    m = StackedMeasurement(y, np.zeros(2), H, R, np.zeros(2, bool), [("a", 0, 0)] * 2, None)
    x0 = np.zeros(2)
    for a, b in zip(HuberUpdater().update(x0, P, m), joseph_update(x0, P, m), strict=True):
        np.testing.assert_allclose(a, b)
    for a, b in zip(HuberUpdater(np.inf).update(x0, P, m), joseph_update(x0, P, m), strict=True):
        np.testing.assert_allclose(a, b)


def test_a_gross_error_moves_the_state_a_bounded_amount():
    P, sigma = 4.0, 0.5
    for y in (1e2, 1e4):  # one scalar row: dx -> P k / sigma, not the Kalman K y
        m = StackedMeasurement(
            np.array([y]), np.zeros(1), np.ones((1, 1)), np.array([[sigma**2]]),
            np.zeros(1, bool), [("a", 0, 0)], None,
        )  # fmt: skip
        x, _, _ = HuberUpdater().update(np.zeros(1), np.array([[P]]), m)
        assert x[0] == pytest.approx(P * HUBER_K / sigma, rel=1e-6)


def test_bad_input_is_refused_by_name():
    with pytest.raises(ValueError, match="k"):
        HuberUpdater(0.0)
    with pytest.raises(ValueError, match="k"):
        HuberUpdater(float("nan"))
    with pytest.raises(ValueError, match="R"):
        huber_weights(np.ones(2), np.eye(2), np.eye(2), np.diag([1.0, -1.0]))
    with pytest.raises(ValueError, match="H"):
        huber_weights(np.ones(2), np.eye(3), np.eye(2), np.eye(2))
    m = StackedMeasurement(
        np.ones(1), np.zeros(1), np.ones((1, 1)), np.ones((1, 1)), np.zeros(1, bool),
        [("a", 0, 0)], None,
    )  # fmt: skip
    with pytest.raises(ValueError, match="C"):
        HuberUpdater().update(np.zeros(1), np.eye(1), m, C=np.zeros((1, 4)))
