"""Posterior CRLB (Tichavsky 1998) against the Kalman filter, the snapshot CRLB and Monte Carlo."""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from tunnelkit import crlb
from tunnelkit.tracking import pcrlb
from tunnelkit.tracking import virtual_station as vs
from tunnelkit.tracking.cv import cv_process_noise, cv_transition, simulate_cv


def test_linear_gaussian_bound_equals_kalman_covariance():
    """For linear h the PCRLB recursion is the information form of the Kalman filter."""
    F, Q = cv_transition(0.1), cv_process_noise(0.1, 0.3)
    H = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [1.0, -1.0, 0, 0]])
    R = np.diag([0.5, 0.8, 0.3])
    P0 = np.diag([2.0, 3.0, 1.0, 0.5])
    T = 25
    B = pcrlb.pcrlb(F, Q, P0, np.broadcast_to(H.T @ np.linalg.solve(R, H), (T, 4, 4)))
    kf = KalmanFilter(dim_x=4, dim_z=3)
    kf.F, kf.Q, kf.H, kf.R, kf.P = F, Q, H, R, P0.copy()
    for k in range(T):
        if k:
            kf.predict()
        kf.update(np.zeros(3))
        assert np.allclose(B[k], kf.P, rtol=1e-8, atol=1e-12)


def test_measurement_information_is_the_snapshot_fim():
    m = vs.model_from_scenario("jiang2023-straight", level=1)
    x = np.array([[[40.0, 45.0, 10.0, 10.0]]])
    info = pcrlb.measurement_information(m.jacobian(x), m.R)[0]
    assert np.allclose(
        info[:2, :2], crlb.fim_toa_doa(x[0, 0, :2], m.stations, m.sigma_theta, m.sigma_d)
    )
    assert np.allclose(info[2:], 0.0) and np.allclose(info[:, 2:], 0.0)


def test_huge_process_noise_gives_back_the_snapshot_crlb():
    m = vs.model_from_scenario("jiang2023-straight", level=2, q=1e9)
    truth = np.array([[30.0, 35.0, 10.0, 10.0]] * 3)
    b = pcrlb.vs_pcrlb(m, truth, np.eye(4) * 1e9)
    assert np.allclose(
        b, crlb.crlb_rmse(truth[0, :2], m.stations, m.sigma_theta, m.sigma_d), rtol=1e-3
    )


def test_bound_shrinks_with_noise_and_filter_respects_it():
    """EKF on trajectories drawn from the model (so the bound applies): MSE >= 0.85 PCRLB."""
    exp = vs.experiment("jiang2023-straight", level=2)
    rng = np.random.default_rng(8)
    X = simulate_cv(exp.truth[0], exp.model.period, exp.model.q, 30, rng, size=150)
    b = pcrlb.vs_pcrlb(exp.model, X, exp.P0)
    lo = pcrlb.vs_pcrlb(
        exp.model.with_noise(exp.model.sigma_theta / 2, exp.model.sigma_d / 2), X, exp.P0
    )
    assert np.all(lo < b)
    Z = np.stack([exp.model.simulate(X[r, :, :2], rng) for r in range(150)])
    x0 = vs.initial_states(exp.truth[0], exp.P0, rng, size=150)
    x0 = x0 - exp.truth[0] + X[:, 0]
    est = vs.VsEKF.run(exp.model, Z, x0, exp.P0)
    mse = np.mean(np.sum((est[..., :2] - X[..., :2]) ** 2, -1), axis=0)
    assert np.all(mse[5:] > 0.75 * b[5:] ** 2)  # sampling sd of a 150-run MSE is ~12 %
    assert 0.85 < np.mean(mse) / np.mean(b**2) < 1.25


def test_noise_free_truth_is_the_batch_information_about_the_start():
    """Q = 0: J_k = F^-kT [P0^-1 + sum_j F^jT I_j F^j] F^-k (brute force), the limit of Q -> 0."""
    F = cv_transition(0.1)
    rng = np.random.default_rng(3)
    T = 12
    A = rng.standard_normal((T, 3, 4))
    info = A.transpose(0, 2, 1) @ A
    P0 = np.diag([2.0, 3.0, 1.0, 0.5])
    B = pcrlb.pcrlb(F, np.zeros((4, 4)), P0, info)
    J0 = np.linalg.inv(P0)
    for k in range(T):
        Fk = [np.linalg.matrix_power(F, j) for j in range(k + 1)]
        Jx0 = J0 + sum(Fk[j].T @ info[j] @ Fk[j] for j in range(k + 1))
        Fik = np.linalg.inv(Fk[k])
        assert np.allclose(B[k], np.linalg.inv(Fik.T @ Jx0 @ Fik), rtol=1e-8, atol=1e-12)

    def gap(q):  # relative to each epoch's largest entry
        near = pcrlb.pcrlb(F, cv_process_noise(0.1, q), P0, info)
        return np.max(np.abs(near - B) / np.abs(B).max(axis=(1, 2), keepdims=True))

    # the limit q -> 0, approached linearly in q (below 1e-6 the inverse of Q costs digits)
    assert 8 < gap(1e-4) / gap(1e-5) < 12 and gap(1e-6) < 2e-5
    assert np.all(
        np.diagonal(pcrlb.pcrlb(F, cv_process_noise(0.1, 0.1), P0, info)[1:], 0, 1, 2)
        > np.diagonal(B[1:], 0, 1, 2)
    )


def test_noise_free_bound_holds_for_filters_on_a_fixed_drive():
    """The presets' drive is one straight path without process noise and random prior means: the
    Q = 0 bound lies under the filters' RMSE (the model's q = 0.1 bound does not, see notebook 05)."""
    exp = vs.experiment("jiang2023-straight", level=2)
    rng = np.random.default_rng(20261205)
    Z, x0 = exp.simulate(40, rng)
    est = vs.VsEKF.run(exp.model, Z, x0, exp.P0)
    mse = np.mean(np.sum((est[..., :2] - exp.truth[:, :2]) ** 2, -1))
    free = pcrlb.vs_pcrlb(exp.model, exp.truth, exp.P0, process_noise=False)
    noisy = pcrlb.vs_pcrlb(exp.model, exp.truth, exp.P0)
    assert np.all(free[1:] < noisy[1:])
    assert np.sqrt(mse / np.mean(free**2)) > 1.0
    with pytest.raises(TypeError, match="process_noise"):
        pcrlb.vs_pcrlb(exp.model, exp.truth, exp.P0, process_noise="no")


def test_bad_input():
    F, Q = cv_transition(0.1), cv_process_noise(0.1, 0.3)
    with pytest.raises(ValueError, match="Q"):
        pcrlb.pcrlb(F, -Q, np.eye(4), np.zeros((3, 4, 4)))
    with pytest.raises(ValueError, match=r"F: .*invertible"):
        pcrlb.pcrlb(np.zeros((4, 4)), np.zeros((4, 4)), np.eye(4), np.zeros((3, 4, 4)))
    with pytest.raises(ValueError, match="info"):
        pcrlb.pcrlb(F, Q, np.eye(4), np.zeros((3, 2, 2)))
    with pytest.raises(ValueError, match="states"):
        pcrlb.vs_pcrlb(vs.model_from_scenario("jiang2023-straight"), np.zeros((3, 2)), np.eye(4))
