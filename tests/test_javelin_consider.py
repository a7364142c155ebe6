"""The bias-aware JAVELIN update (Schmidt-Kalman consider filter) against brute-force batch
solutions on a linear toy with a constant bias, and its plumbing through the tracker."""

import numpy as np
import pytest

from tunnelkit.tracking.javelin import ConsiderNoise, PathMeasurements, ReportedNoise
from tunnelkit.tracking.javelin.config import JavelinConfig
from tunnelkit.tracking.javelin.consider import bias_factors, consider_update, schmidt_update
from tunnelkit.tracking.javelin.update import stack_measurement

NX, NB, STEPS = 2, 2, 8


def _toy(seed=0):
    rng = np.random.default_rng(seed)
    H = rng.standard_normal((STEPS, 3, NX))
    B = rng.standard_normal((STEPS, 3, NB))
    A = rng.standard_normal((STEPS, 3, 3))
    R = A @ np.swapaxes(A, 1, 2) + 0.5 * np.eye(3)
    P0 = np.diag([4.0, 2.0])
    Pb = np.array([[1.5, 0.3], [0.3, 0.8]])
    return H, B, R, P0, Pb


def _filter(H, B, R, P0, Pb, z, n_est, gains=None):
    """Sequential updates of [x; b] (prior mean 0) through schmidt_update."""
    x = np.zeros(NX + NB)
    P = np.zeros((NX + NB, NX + NB))
    P[:NX, :NX], P[NX:, NX:] = P0, Pb
    for k in range(STEPS):
        Ha = np.hstack([H[k], B[k]])
        y = z[k] - Ha @ x
        g = None if gains is None else gains[k]
        x, P, _, _ = schmidt_update(x, P, Ha, R[k], y, n_est=n_est, gain=g)
    return x, P


def test_augmented_kf_equals_batch_weighted_least_squares():
    H, B, R, P0, Pb = _toy()
    z = np.random.default_rng(1).standard_normal((STEPS, 3))
    x, P = _filter(H, B, R, P0, Pb, z, NX + NB)
    # batch: prior N(0, blockdiag(P0, Pb)) on [x; b], every row weighted by R^-1
    info = np.zeros((NX + NB, NX + NB))
    info[:NX, :NX], info[NX:, NX:] = np.linalg.inv(P0), np.linalg.inv(Pb)
    rhs = np.zeros(NX + NB)
    for k in range(STEPS):
        Ha = np.hstack([H[k], B[k]])
        W = np.linalg.inv(R[k])
        info += Ha.T @ W @ Ha
        rhs += Ha.T @ W @ z[k]
    np.testing.assert_allclose(x, np.linalg.solve(info, rhs), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(P, np.linalg.inv(info), rtol=1e-9, atol=1e-12)


def _linear_map(H, B, R, P0, Pb, n_est, gains=None):
    """The filter's estimate of x is linear in (x0 error, b, v_1..v_N): its maps, by running it
    on unit inputs (the gains do not depend on the data)."""
    base = np.zeros((STEPS, 3))

    def est(z):
        return _filter(H, B, R, P0, Pb, z, n_est, gains)[0][:NX]

    # the prior mean is 0, the truth x and b: z_k = H x + B b + v_k; error = est - x
    Mx = np.column_stack([est(np.einsum("kij,j->ki", H, e)) for e in np.eye(NX)]) - np.eye(NX)
    Mb = np.column_stack([est(np.einsum("kij,j->ki", B, e)) for e in np.eye(NB)])
    Mv = []
    for k in range(STEPS):
        cols = []
        for e in np.eye(3):
            z = base.copy()
            z[k] = e
            cols.append(est(z))
        Mv.append(np.column_stack(cols))
    cov = Mx @ P0 @ Mx.T + Mb @ Pb @ Mb.T + sum(M @ R[k] @ M.T for k, M in enumerate(Mv))
    return cov, -Mb @ Pb  # P's cross block: cov(x - estimate, b)


def test_consider_filter_covariance_is_the_true_covariance_of_its_estimate():
    H, B, R, P0, Pb = _toy(2)
    _, P = _filter(H, B, R, P0, Pb, np.zeros((STEPS, 3)), NX)
    cov, cross = _linear_map(H, B, R, P0, Pb, NX)
    np.testing.assert_allclose(P[:NX, :NX], cov, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(P[:NX, NX:], cross, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(P[NX:, NX:], Pb, rtol=0, atol=1e-12)  # never estimated


def test_consider_filter_ignoring_the_bias_matches_the_batch_estimate_that_ignores_it():
    """With the gains of a Kalman filter that does not know the bias, the Joseph covariance is
    the brute-force covariance of the batch weighted least squares that ignores the bias."""
    H, B, R, P0, Pb = _toy(3)
    gains, Pn = [], P0.copy()
    for k in range(STEPS):
        S = H[k] @ Pn @ H[k].T + R[k]
        K = Pn @ H[k].T @ np.linalg.inv(S)
        gains.append(K)
        Pn = (np.eye(NX) - K @ H[k]) @ Pn
    _, P = _filter(H, B, R, P0, Pb, np.zeros((STEPS, 3)), NX, gains)
    info = np.linalg.inv(P0) + sum(H[k].T @ np.linalg.inv(R[k]) @ H[k] for k in range(STEPS))
    A = np.linalg.inv(info)
    G = sum(H[k].T @ np.linalg.inv(R[k]) @ B[k] for k in range(STEPS))
    brute = A + A @ G @ Pb @ G.T @ A
    np.testing.assert_allclose(P[:NX, :NX], brute, rtol=1e-9, atol=1e-12)
    # and it is worse than the consider filter's own gains
    _, Ps = _filter(H, B, R, P0, Pb, np.zeros((STEPS, 3)), NX)
    assert np.trace(Ps[:NX, :NX]) < np.trace(P[:NX, :NX])


def test_schmidt_gain_is_the_best_gain_that_leaves_the_bias_alone():
    H, B, R, P0, Pb = _toy(4)
    Pa = np.zeros((NX + NB, NX + NB))
    Pa[:NX, :NX], Pa[NX:, NX:] = P0, Pb
    Pa[:NX, NX:] = 0.4 * np.array([[1.0, 0.2], [-0.3, 0.5]])
    Pa[NX:, :NX] = Pa[:NX, NX:].T
    Ha = np.hstack([H[0], B[0]])
    _, P, K, _ = schmidt_update(np.zeros(4), Pa, Ha, R[0], np.zeros(3), n_est=NX)
    rng = np.random.default_rng(5)
    for _ in range(20):
        dK = 1e-3 * rng.standard_normal(K.shape)
        _, Pp, _, _ = schmidt_update(np.zeros(4), Pa, Ha, R[0], np.zeros(3), n_est=NX, gain=K + dK)
        assert np.trace(Pp[:NX, :NX]) > np.trace(P[:NX, :NX])


def _meas(bias_scale):
    phi, psi = np.array([0.1, 0.3]), np.array([-0.05, 0.2])
    cov = np.stack([np.diag([1e-6, 2e-6, 4.0])] * 2)
    sd = np.array([0.01, 0.02])
    b = np.zeros((2, 4, 4))
    b[:, :3, :3] = bias_scale * cov
    b[:, 3, 3] = bias_scale * sd**2
    return PathMeasurements.from_arrays(
        phi, psi, [10.0, 12.0], [10.0, 12.0], None, cov=cov, sigma_d=sd, bias_cov=b
    )


def test_stacked_consider_rows_split_the_reported_covariance():
    """R (white) + B B^T is the reported covariance row by row: the TDoA row carries both
    paths' delay biases with opposite signs."""
    meas = _meas(0.25)
    cfg = JavelinConfig()
    pred = np.zeros((2, 4))
    J = np.zeros((2, 4, 5))
    C = np.zeros((5, 8))
    m = stack_measurement(pred, J, meas, [(0, 0), (1, 1)], cfg, 0, ConsiderNoise(), C)
    full = stack_measurement(pred, J, meas, [(0, 0), (1, 1)], cfg, 0, ReportedNoise())
    np.testing.assert_allclose(m.R + m.B @ m.B.T, full.R, rtol=1e-9, atol=1e-15)
    assert m.B[-1, 3] == pytest.approx(-0.5 * 0.01) and m.B[-1, 7] == pytest.approx(0.5 * 0.02)
    np.testing.assert_allclose(
        bias_factors(meas.bias_cov) @ np.swapaxes(bias_factors(meas.bias_cov), 1, 2),
        meas.bias_cov,
        rtol=1e-6,
        atol=1e-18,
    )


def test_bias_factors_block_by_block():
    """Every block factorised on its own terms, whatever its neighbours: full blocks, blocks
    with some components that do not repeat (their rows and columns stay zero), zero blocks and
    a singular one; the same factor as the block alone, lower-triangular, L L^T = the block."""
    rng = np.random.default_rng(3)
    A = rng.standard_normal((6, 4, 4)) * np.array([1e-4, 1.0, 3.0, 1e-2, 1.0, 0.5])[:, None, None]
    b = A @ np.swapaxes(A, 1, 2)
    b[1] = 0.0  # nothing repeats
    b[2][[0, 2], :] = b[2][:, [0, 2]] = 0.0  # psi and d repeat only
    v = rng.standard_normal(4)
    b[4] = np.outer(v, v)  # rank one: the ridge keeps it factorisable
    L = bias_factors(b)
    for k in range(len(b)):
        np.testing.assert_array_equal(L[k], bias_factors(b[k : k + 1])[0])
        assert np.all(np.triu(L[k], 1) == 0)
        np.testing.assert_allclose(L[k] @ L[k].T, b[k], rtol=1e-5, atol=1e-12 * np.abs(b[k]).max())
    assert np.all(L[1] == 0) and np.all(L[2][[0, 2]] == 0) and np.all(L[2][:, [0, 2]] == 0)
    assert bias_factors(np.zeros((0, 4, 4))).shape == (0, 4, 4)


def test_consider_update_through_the_stack_equals_the_augmented_schmidt_update():
    meas = _meas(0.5)
    cfg = JavelinConfig()
    rng = np.random.default_rng(6)
    pred = rng.standard_normal((2, 4))
    J = rng.standard_normal((2, 4, 5))
    A = rng.standard_normal((5, 5))
    P = A @ A.T + np.eye(5)
    C = 0.1 * rng.standard_normal((5, 8))
    x = rng.standard_normal(5)
    m = stack_measurement(pred, J, meas, [(0, 0), (1, 1)], cfg, 0, ConsiderNoise(), C)
    xn, Pn, Cn, _ = consider_update(x, P, C, m)
    Pa = np.block([[P, C], [C.T, np.eye(8)]])
    xa, Pa2, _, _ = schmidt_update(
        np.r_[x, np.zeros(8)], Pa, np.hstack([m.H, m.B]), m.R, m.residual(), n_est=5
    )
    np.testing.assert_allclose(xn, xa[:5])
    np.testing.assert_allclose(Cn, Pa2[:5, 5:])
    np.testing.assert_allclose(Pn, Pa2[:5, :5])
    # a bias-free report reduces the consider update to the Joseph update
    m0 = stack_measurement(pred, J, _meas(0.0), [(0, 0), (1, 1)], cfg, 0, ConsiderNoise(), C)
    from tunnelkit.tracking.javelin.update import joseph_update

    x0, _, _ = joseph_update(x, P, stack_measurement(pred, J, _meas(0.0), [(0, 0), (1, 1)], cfg, 0))
    assert not np.allclose(xn, x0)
    xc, _, _, _ = consider_update(x, P, np.zeros_like(C), m0)
    np.testing.assert_allclose(
        xc,
        joseph_update(
            x, P, stack_measurement(pred, J, _meas(0.0), [(0, 0), (1, 1)], cfg, 0, ReportedNoise())
        )[0],
    )


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError, match="tau_s"):
        ConsiderNoise(tau_s=0.0)
    with pytest.raises(ValueError, match="n_est"):
        schmidt_update(np.zeros(2), np.eye(2), np.eye(2), np.eye(2), np.zeros(2), n_est=3)
    with pytest.raises(ValueError, match="bias_cov"):
        _meas(2.0)  # a repeating share larger than the reported covariance
