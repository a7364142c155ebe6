"""Vectorised unscented particle filter (Jiang 2023 section 4.2.2): equivalence, resampling, faults."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tunnelkit.tracking import upf
from tunnelkit.tracking import virtual_station as vs
from tunnelkit.tracking.pcrlb import vs_pcrlb


@pytest.fixture(scope="module")
def exp_hi():
    return vs.experiment("jiang2023-straight", level=2)


def test_batched_proposal_equals_one_filterpy_ukf_per_particle(exp_hi):
    m = exp_hi.model
    rng = np.random.default_rng(2)
    parts = exp_hi.truth[0] + rng.standard_normal((7, 4))
    A = rng.standard_normal((7, 4, 4))
    covs = 0.3 * A @ np.swapaxes(A, -1, -2) + 0.1 * np.eye(4)
    z = m.simulate(exp_hi.truth[1:2, :2], rng)[0]
    m_pred, P_pred = parts @ m.F.T, m.F @ covs @ m.F.T + m.Q
    for alpha in (1.0, 0.5):
        a, b = upf.ukf_proposal(m, m_pred, P_pred, z, alpha=alpha)
        c, d = upf.ukf_proposal_reference(m, parts, covs, z, alpha=alpha)
        assert np.allclose(a, c, atol=1e-10) and np.allclose(b, d, atol=1e-10)


def test_merwe_weights_sum_to_one():
    Wm, Wc, lam = upf.merwe_weights(4, 0.5, 2.0, 0.0)
    assert np.isclose(Wm.sum(), 1.0) and np.isclose(lam, 0.25 * 4 - 4)
    assert np.isclose(Wc[0], Wm[0] + 1 - 0.25 + 2)


def test_systematic_resample_counts_and_batch():
    w = np.array([0.5, 0.25, 0.125, 0.125, 0.0])
    idx = upf.systematic_resample(w, np.random.default_rng(0))
    counts = np.bincount(idx, minlength=5)
    assert np.all(np.abs(counts - 5 * w) < 1.0) and counts[4] == 0  # systematic: floor/ceil of N w
    W = np.random.default_rng(1).dirichlet(np.ones(50), size=30)
    idx_b = upf.systematic_resample(W, np.random.default_rng(3))
    assert idx_b.shape == (30, 50) and idx_b.min() >= 0 and idx_b.max() <= 49
    for r in range(30):
        assert np.all(np.abs(np.bincount(idx_b[r], minlength=50) - 50 * W[r]) < 1.0)
    assert np.array_equal(idx_b, upf.systematic_resample(W, np.random.default_rng(3)))
    assert np.allclose(upf.effective_sample_size(np.full(8, 1 / 8)), 8.0)


def test_upf_tracks_near_the_pcrlb(exp_hi):
    """10 runs, 300 particles at (2 deg, 2 m): RMSE / sqrt(PCRLB) below 1.2 (measured ~0.95)."""
    Z, x0 = exp_hi.simulate(10, np.random.default_rng(4))
    est = upf.UnscentedParticleFilter.run(
        exp_hi.model, Z, x0, exp_hi.P0, rng=np.random.default_rng(5), n_particles=300
    )
    bound = vs_pcrlb(exp_hi.model, exp_hi.truth, exp_hi.P0)
    ratio = np.sqrt(
        np.mean(np.sum((est[..., :2] - exp_hi.truth[:, :2]) ** 2, -1)) / np.mean(bound**2)
    )
    assert 0.6 < ratio < 1.2


def test_same_seed_same_numbers(exp_hi):
    Z, x0 = exp_hi.simulate(2, np.random.default_rng(4))
    a = upf.UnscentedParticleFilter.run(
        exp_hi.model, Z[:, :10], x0, exp_hi.P0, rng=np.random.default_rng(9), n_particles=50
    )
    b = upf.UnscentedParticleFilter.run(
        exp_hi.model, Z[:, :10], x0, exp_hi.P0, rng=np.random.default_rng(9), n_particles=50
    )
    assert np.array_equal(a, b)


def test_carried_proposal_of_the_paper_degenerates(exp_hi):
    """eq. 52 as printed (each particle's own covariance propagated) collapses the weights when Q is
    small: the effective sample size after the update stays near 1."""
    Z, x0 = exp_hi.simulate(1, np.random.default_rng(4))
    ess = {}
    for prop in ("carried", "conditional"):
        vals = upf.one_epoch_ess(
            exp_hi.model,
            Z[0],
            x0[0],
            exp_hi.P0,
            rng=np.random.default_rng(1),
            proposal=prop,
            epochs=20,
        )
        ess[prop] = np.median(vals[5:])
    assert ess["carried"] < 5 and ess["conditional"] > 50


@pytest.mark.parametrize(
    "kw,err,match",
    [
        ({"n_particles": 0}, ValueError, "n_particles"),
        ({"n_particles": 2.5}, TypeError, "n_particles"),
        ({"resample_threshold": 1.5}, ValueError, "resample_threshold"),
        ({"proposal": "magic"}, ValueError, "proposal"),
        ({"rng": None}, TypeError, "rng"),
    ],
)
def test_bad_arguments(exp_hi, kw, err, match):
    args = {"rng": np.random.default_rng(0), **kw}
    with pytest.raises(err, match=match):
        upf.UnscentedParticleFilter(exp_hi.model, exp_hi.truth[0], exp_hi.P0, **args)


def test_missing_and_nan_measurements(exp_hi):
    m = exp_hi.model
    f = upf.UnscentedParticleFilter(
        m, exp_hi.truth[0], exp_hi.P0, rng=np.random.default_rng(0), n_particles=50
    )
    f.update(m.hx(exp_hi.truth[0]))
    f.predict()
    w_before = f.weights.copy()
    f.update(None)  # missed epoch: particles move by the motion model, weights unchanged
    assert np.allclose(f.weights, w_before) and np.all(np.isfinite(f.x))
    f.predict()
    z = m.hx(exp_hi.truth[2])
    z[0] = np.nan
    with pytest.warns(RuntimeWarning, match="NaN"):
        f.update(z)
    assert np.all(np.isfinite(f.x)) and np.all(np.isfinite(f.P))
    with pytest.raises(ValueError, match="z"):
        f.predict()
        f.update(z[:3])


def test_batched_nan_row_only_skips_that_run(exp_hi):
    m = exp_hi.model
    x0 = np.stack([exp_hi.truth[0]] * 2)
    f = upf.UnscentedParticleFilter(m, x0, exp_hi.P0, rng=np.random.default_rng(0), n_particles=40)
    Z = np.stack([m.hx(exp_hi.truth[0])] * 2)
    Z[1, 2] = np.nan
    with pytest.warns(RuntimeWarning, match="1 measurement"):
        f.update(Z)
    assert f.x.shape == (2, 4) and np.all(np.isfinite(f.x))
    assert not np.allclose(f.weights[0], 1 / 40) and np.allclose(f.weights[1], 1 / 40)


def test_degenerate_particle_covariance_is_regularised(exp_hi):
    m = exp_hi.model
    f = upf.UnscentedParticleFilter(
        m,
        exp_hi.truth[0],
        exp_hi.P0,
        rng=np.random.default_rng(0),
        n_particles=30,
        proposal="carried",
    )
    f.update(m.hx(exp_hi.truth[0]))
    f.covs[:] = 0.0
    f.covs[:, 0, 0] = -1e-3  # not a covariance at all
    with pytest.warns(RuntimeWarning, match="not positive definite"):
        f.predict()
        f.update(m.hx(exp_hi.truth[1]))
    assert np.all(np.isfinite(f.x)) and np.all(np.isfinite(f.P))


def test_all_zero_weights_recover(exp_hi):
    m = exp_hi.model
    f = upf.UnscentedParticleFilter(
        m, exp_hi.truth[0], exp_hi.P0, rng=np.random.default_rng(0), n_particles=30
    )
    f.update(m.hx(exp_hi.truth[0]))
    f.predict()
    f.log_w[:] = -np.inf  # every weight is zero
    with pytest.warns(RuntimeWarning, match="vanished"):
        f.update(m.hx(exp_hi.truth[1]))
    assert np.isclose(f.weights.sum(), 1.0) and np.all(np.isfinite(f.x))
    # a wildly wrong measurement makes all likelihoods underflow in linear scale; logs keep it finite
    f.predict()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        f.update(m.hx(exp_hi.truth[2]) + np.r_[1e4, 1e4, 0.0, 0.0])
    assert np.isclose(f.weights.sum(), 1.0) and np.all(np.isfinite(f.x))


def test_log_gauss_chol_matches_scipy_up_to_the_constant():
    """The proposal/transition densities of eq. 60 against scipy's multivariate normal."""
    from scipy.stats import multivariate_normal

    rng = np.random.default_rng(0)
    A = rng.standard_normal((3, 4, 4))
    covs = A @ np.swapaxes(A, -1, -2) + 0.2 * np.eye(4)
    d = rng.standard_normal((3, 5, 4))
    const = 0.5 * 4 * np.log(2 * np.pi)
    got = upf._log_gauss_chol(d, np.linalg.cholesky(covs)[:, None])  # batched factors
    ref = np.array([multivariate_normal(np.zeros(4), covs[b]).logpdf(d[b]) for b in range(3)])
    assert np.allclose(got - const, ref, rtol=1e-10, atol=1e-10)
    got2 = upf._log_gauss_chol(d, np.linalg.cholesky(covs[0]))  # one shared factor
    assert np.allclose(got2 - const, multivariate_normal(np.zeros(4), covs[0]).logpdf(d))


def _brute_force_posterior(m, x0, P0, zs, n, rng):
    """Bootstrap importance sampling from the prior and the motion model: weighted mean, sd."""
    xs = x0 + rng.standard_normal((n, 4)) @ np.linalg.cholesky(P0).T
    lw = m.log_likelihood(zs[0], xs)
    for z in zs[1:]:
        xs = xs @ m.F.T + rng.standard_normal((n, 4)) @ np.linalg.cholesky(m.Q).T
        lw = lw + m.log_likelihood(z, xs)
    w = np.exp(lw - lw.max())
    w /= w.sum()
    mean = w @ xs
    return mean, np.sqrt(w @ (xs - mean) ** 2)


def test_upf_weights_give_the_brute_force_posterior(exp_hi):
    """eq. 59-61 (proposal draw, proposal density, transition density, likelihood) checked on two
    epochs against bootstrap importance sampling with many samples (no resampling in the UPF)."""
    m = exp_hi.model
    P0 = np.diag([9.0, 9.0, 1.0, 1.0])  # a prior the measurement clearly sharpens
    zs = m.simulate(exp_hi.truth[:2, :2], np.random.default_rng(0))
    x0 = exp_hi.truth[0] + np.array([1.5, -1.0, 0.3, -0.2])
    mean, sd = _brute_force_posterior(m, x0, P0, zs, 400_000, np.random.default_rng(5))
    f = upf.UnscentedParticleFilter(
        m, x0, P0, rng=np.random.default_rng(1), n_particles=20_000, resample_threshold=1e-9
    )
    f.update(zs[0])
    f.predict()
    f.update(zs[1])
    # Monte-Carlo sd of the difference is ~0.013 posterior sd; a wrong density factor moves the
    # mean by 0.05-0.15 sd and the spread by 20-40 %
    assert np.all(np.abs(f.x - mean) < 0.06 * sd)
    assert np.allclose(np.sqrt(np.diag(f.P)), sd, rtol=0.05)
