"""The Huber-weighted update (tunnelkit.studies.robust_update) against a brute-force minimum."""

import numpy as np
import pytest
from scipy.optimize import minimize

from tunnelkit.studies.robust_update import HUBER_K, HuberUpdater, huber_weights
from tunnelkit.tracking.javelin.update import StackedMeasurement, joseph_update


def _spd(rng, n, scale=1.0):
    a = rng.normal(size=(n, n))
    return scale * (a @ a.T + n * np.eye(n))


def _huber_objective(dx, y, H, Pinv, Rinv_half, k):
    e = Rinv_half @ (y - H @ dx)
    a = np.abs(e)
    rho = np.where(a <= k, 0.5 * e**2, k * a - 0.5 * k**2)
    return 0.5 * dx @ Pinv @ dx + rho.sum()


def _root(R):
    lam, V = np.linalg.eigh(R)
    return (V * np.sqrt(lam)) @ V.T


@pytest.mark.parametrize("seed", [3, 11, 2027])
def test_the_update_is_the_minimum_of_the_huber_objective(seed):
    rng = np.random.default_rng(seed)
    D, K = 3, 5
    P, R = _spd(rng, D), _spd(rng, K, 0.2)  # correlated rows
    H = rng.normal(size=(K, D))
    y = rng.normal(size=K)
    y[1] += 40.0  # one gross error
    w = huber_weights(y, H, P, R, HUBER_K)
    assert np.all((w > 0) & (w <= 1)) and w.min() < 0.5
    args = (y, H, np.linalg.inv(P), np.linalg.inv(_root(R)), HUBER_K)
    best = minimize(_huber_objective, np.zeros(D), args=args, method="BFGS", tol=1e-12)
    m = StackedMeasurement(y, np.zeros(K), H, R, np.zeros(K, bool), [("a", 0, 0)] * K, None)
    x, P_new, nis = HuberUpdater().update(np.zeros(D), P, m)
    np.testing.assert_allclose(x, best.x, atol=1e-5)
    assert _huber_objective(x, *args) <= best.fun + 1e-9
    # the told R's normalised innovation, not the reweighted one: the gross error shows
    assert nis == pytest.approx(joseph_update(np.zeros(D), P, m)[2])
    assert np.all(np.linalg.eigvalsh(P_new) > 0)
    # the rows' order does not matter (the symmetric square root whitens)
    order = rng.permutation(K)
    mo = StackedMeasurement(
        y[order], np.zeros(K), H[order], R[np.ix_(order, order)], np.zeros(K, bool),
        [("a", 0, 0)] * K, None,
    )  # fmt: skip
    np.testing.assert_allclose(HuberUpdater().update(np.zeros(D), P, mo)[0], x, atol=1e-9)


def test_an_azimuth_across_the_half_turn_is_wrapped():
    # measured -179 deg, predicted 179 deg: the innovation is 2 deg, not -358 deg
    z, h = np.radians([-179.0]), np.radians([179.0])
    m = StackedMeasurement(z, h, np.ones((1, 1)), np.radians([[1.0]]) ** 2, np.array([True]),
                           [("phi", 0, 0)], None)  # fmt: skip
    x, _, _ = HuberUpdater().update(np.zeros(1), np.radians([[1.0]]) ** 2, m)
    assert 0 < np.degrees(x[0]) <= 1.0 + 1e-9  # within k: the Kalman half of 2 deg


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
    for bad in (0.0, float("nan"), True, "1"):
        with pytest.raises(ValueError, match=r"^k:"):
            HuberUpdater(bad)
    with pytest.raises(ValueError, match=r"^R:"):
        huber_weights(np.ones(2), np.eye(2), np.eye(2), np.diag([1.0, -1.0]))
    with pytest.raises(ValueError, match=r"^H:"):
        huber_weights(np.ones(2), np.eye(3), np.eye(2), np.eye(2))
    m = StackedMeasurement(
        np.ones(1), np.zeros(1), np.ones((1, 1)), np.ones((1, 1)), np.zeros(1, bool),
        [("a", 0, 0)], None,
    )  # fmt: skip
    with pytest.raises(ValueError, match=r"^C:"):
        HuberUpdater().update(np.zeros(1), np.eye(1), m, C=np.zeros((1, 4)))
