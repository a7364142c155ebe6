"""Virtual-station tracking (Jiang 2023 eq. 40-45): model, EKF/UKF/TSWLS, registry, bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tunnelkit import crlb, positioning
from tunnelkit.tracking import registry
from tunnelkit.tracking import virtual_station as vs
from tunnelkit.tracking.cv import cv_process_noise, cv_transition, simulate_cv
from tunnelkit.tracking.pcrlb import vs_pcrlb


@pytest.fixture(scope="module")
def exp_hi():
    return vs.experiment("jiang2023-straight", level=2)


def test_cv_matrices_closed_form():
    F = cv_transition(0.1)
    assert np.allclose(F @ np.array([1.0, 2.0, 3.0, 4.0]), [1.3, 2.4, 3.0, 4.0])
    Q = cv_process_noise(0.1, 2.0)
    blk = 2.0 * np.array([[0.1**3 / 3, 0.1**2 / 2], [0.1**2 / 2, 0.1]])
    assert np.allclose(Q[np.ix_([0, 2], [0, 2])], blk) and np.allclose(
        Q[np.ix_([1, 3], [1, 3])], blk
    )
    assert np.allclose(Q[0, 1], 0.0) and np.allclose(Q[0, 3], 0.0)


def test_simulate_cv_increments_have_covariance_Q():
    x = simulate_cv([0, 0, 1, 1], 0.1, 0.5, 3, np.random.default_rng(3), size=20000)
    F, Q = cv_transition(0.1), cv_process_noise(0.1, 0.5)
    inc = x[:, 1] - x[:, 0] @ F.T
    white = inc @ np.linalg.inv(np.linalg.cholesky(Q)).T  # ~ N(0, I) if the covariance is Q
    assert np.allclose(np.cov(white.T), np.eye(4), atol=0.04)  # sampling sd of each entry ~0.007
    again = simulate_cv([0, 0, 1, 1], 0.1, 0.5, 3, np.random.default_rng(3), size=20000)
    assert np.array_equal(x, again)


def test_model_matches_foundation_and_jacobian_is_right(exp_hi):
    m = exp_hi.model
    x = np.array([30.0, 31.0, 10.0, 10.0])
    d, th = crlb.toa_doa(x[:2], m.stations)
    assert np.allclose(m.hx(x), np.r_[d, th])
    J = m.jacobian(x)
    Jn = crlb.numeric_jacobian(m.hx, x, angle_mask=m.angle_mask)
    assert np.allclose(J, Jn, atol=1e-7)
    assert np.allclose(np.diag(m.R), [2.0**2] * 2 + [np.radians(2.0) ** 2] * 2)


def test_los_model_puts_the_base_station_first():
    m = vs.model_from_scenario("jiang2023-straight", los=True)
    assert m.n_stations == 3 and m.dim_z == 6 and np.allclose(m.stations[0], 0.0)


def test_bearing_residual_and_mean_wrap_across_pi():
    m = vs.VsModel(np.array([[0.0, 0.0]]), 0.01, 0.1, 0.1, 0.1)
    a = np.array([1.0, np.pi - 0.01])
    b = np.array([1.0, -np.pi + 0.01])
    assert np.allclose(m.residual_z(a, b), [0.0, -0.02])
    sig = np.array([[1.0, np.pi - 0.01], [1.0, -np.pi + 0.01], [1.0, np.pi - 0.03]])
    mean = m.z_mean(sig, np.array([0.5, 0.25, 0.25]))
    assert np.isclose(abs(mean[1]), np.pi - 0.01, atol=1e-12)  # the naive mean would be ~0.8


def test_registry_has_the_four_in_order():
    assert list(registry.family("jiang2023")) == ["TSWLS", "EKF", "UKF", "UPF"]


def test_tswls_run_equals_per_epoch_tswls(exp_hi):
    Z, x0 = exp_hi.simulate(3, np.random.default_rng(1))
    est = vs.VsTSWLS.run(exp_hi.model, Z, x0, exp_hi.P0)
    m = exp_hi.model
    for r in range(3):
        for k in (0, 50, 99):
            p = positioning.tswls(m.stations, Z[r, k, :2], Z[r, k, 2:], m.sigma_d, m.sigma_theta)
            assert np.allclose(est[r, k, :2], p)
    one = vs.track(vs.VsTSWLS(m, x0[0], exp_hi.P0), Z[0])
    assert np.allclose(one[:, :2], est[0, :, :2])


def test_filters_lie_near_the_drives_bound_and_beat_tswls(exp_hi):
    """20 runs at (2 deg, 2 m) of the noise-free straight drive: RMSE / sqrt(PCRLB of that drive)
    in (1, 1.6] for EKF/UKF (a bound, and near it), TSWLS far above."""
    res = vs.monte_carlo(exp_hi, 20, 7, names=["TSWLS", "EKF", "UKF"])
    bound = vs_pcrlb(exp_hi.model, exp_hi.truth, exp_hi.P0, process_noise=False)
    ratio = {
        n: np.sqrt(np.mean(np.sum((e[..., :2] - exp_hi.truth[:, :2]) ** 2, -1)) / np.mean(bound**2))
        for n, e in res.items()
    }
    assert 1.0 < ratio["EKF"] < 1.6 and 1.0 < ratio["UKF"] < 1.6, ratio
    assert ratio["TSWLS"] > 3.0


@pytest.mark.parametrize("name", ["EKF", "UKF", "TSWLS"])
def test_missing_and_nan_epochs_predict_only(name, exp_hi):
    m = exp_hi.model
    f = registry.get("jiang2023", name)(m, exp_hi.truth[0], exp_hi.P0)
    f.update(m.hx(exp_hi.truth[0]))
    f.predict()
    before = np.array(f.x, copy=True)
    f.update(None)
    assert np.allclose(f.x, before)
    z = m.hx(exp_hi.truth[1])
    z[1] = np.nan
    with pytest.warns(RuntimeWarning, match="NaN"):
        f.update(z)
    assert np.allclose(f.x, before) and np.all(np.isfinite(f.P))
    Z = m.simulate(exp_hi.truth[:10, :2], np.random.default_rng(0))
    Z[3] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        est = vs.run_estimator(
            name, m, Z[None], exp_hi.truth[None, 0], exp_hi.P0, rng=np.random.default_rng(0)
        )
    assert np.all(np.isfinite(est))


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan])
def test_zero_or_negative_noise_is_refused(bad):
    st = np.array([[0.0, 0.0], [1.0, 1.0]])
    with pytest.raises(ValueError, match="sigma_d"):
        vs.VsModel(st, 0.01, bad, 0.1, 0.1)
    with pytest.raises(ValueError, match="sigma_theta"):
        vs.VsModel(st, bad, 0.1, 0.1, 0.1)
    with pytest.raises(ValueError, match="q"):
        vs.VsModel(st, 0.01, 0.1, 0.1, bad)


def test_bad_prior_and_measurement_shapes(exp_hi):
    m = exp_hi.model
    with pytest.raises(ValueError, match="P0"):
        vs.VsEKF(m, exp_hi.truth[0], -np.eye(4))
    with pytest.raises(ValueError, match="x0"):
        vs.VsUKF(m, [1.0, 2.0], exp_hi.P0)
    f = vs.VsEKF(m, exp_hi.truth[0], exp_hi.P0)
    with pytest.raises(ValueError, match="z"):
        f.update([1.0, 2.0])
    with pytest.raises(TypeError, match="model"):
        vs.VsEKF("model", exp_hi.truth[0], exp_hi.P0)
    with pytest.raises(ValueError, match="level"):
        vs.model_from_scenario("jiang2023-straight", level=7)


def test_regularized_cholesky_warns_and_stays_finite():
    P = np.array([[1.0, 1.0], [1.0, 1.0 - 1e-3]])  # indefinite
    with pytest.warns(RuntimeWarning, match="not positive definite"):
        L = vs.regularized_cholesky(P)
    assert np.all(np.isfinite(L)) and np.allclose(L @ L.T, P, atol=2e-3)
    with pytest.raises(ValueError, match="NaN"):
        vs.regularized_cholesky(np.full((2, 2), np.nan))


def test_ukf_survives_a_degenerate_covariance(exp_hi):
    m = exp_hi.model
    f = vs.VsUKF(m, exp_hi.truth[0], exp_hi.P0)
    f.filter.P = np.zeros((4, 4))  # breaks a plain Cholesky
    with pytest.warns(RuntimeWarning, match="not positive definite"):
        f.predict()
    f.update(m.hx(exp_hi.truth[1]))
    assert np.all(np.isfinite(f.x)) and np.all(np.isfinite(f.P))


def _long_truth(steps: int, period: float) -> np.ndarray:
    """Back and forth along the tunnel (50 m amplitude, 100 s period): stays inside for ever."""
    t = np.arange(steps) * period
    axis = np.array([1.0, 1.0]) / np.sqrt(2.0)
    w = 2 * np.pi / 100.0
    s, v = 50.0 * np.sin(w * t), 50.0 * w * np.cos(w * t)
    pos = np.array([60.0, 64.85]) + s[:, None] * axis
    return np.concatenate([pos, v[:, None] * axis], axis=-1)


@pytest.mark.parametrize("name", ["EKF", "UKF", "UPF"])
def test_long_run_stability_10000_steps(name):
    """10,000 epochs with 2 % dropped epochs (NaN) and 2 % gross outliers (+100 m on one range or
    +90 deg on one bearing): no NaN, every covariance symmetric PSD, never lost, the outliers
    gated. The UPF uses 20 particles here (stability, not accuracy, is under test) so the test
    stays fast."""
    m = vs.model_from_scenario("jiang2023-straight", level=1)
    truth = _long_truth(10_000, m.period)
    Z = m.simulate(truth[:, :2], np.random.default_rng(11))
    rng = np.random.default_rng(12)
    u = rng.random(len(Z))
    out = np.flatnonzero(u < 0.02)
    col = rng.integers(0, m.dim_z, out.size)
    Z[out, col] += np.where(col < m.n_stations, 100.0, np.pi / 2)
    Z[(u >= 0.02) & (u < 0.04)] = np.nan
    P0 = np.diag([1.0, 1.0, 1.0, 1.0])
    opts = {"rng": np.random.default_rng(5), "n_particles": 20} if name == "UPF" else {}
    f = registry.get("jiang2023", name)(m, truth[0], P0, **opts)
    worst_asym, worst_eig, max_err = 0.0, np.inf, 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # each NaN epoch warns
        for k in range(len(Z)):
            f.step(Z[k], first=(k == 0))
            P = np.asarray(f.P)
            assert np.all(np.isfinite(f.x)) and np.all(np.isfinite(P))
            worst_asym = max(worst_asym, float(np.abs(P - P.T).max()))
            worst_eig = min(
                worst_eig, float(np.linalg.eigvalsh(P).min() / max(1.0, np.abs(P).max()))
            )
            max_err = max(max_err, float(np.linalg.norm(f.position - truth[k, :2])))
    assert worst_asym < 1e-12
    assert worst_eig > -1e-12
    assert max_err < 10.0  # never lost: errors stay metres, not the tunnel length
    # the outliers are gated, with few false alarms (20 particles make a coarse predictive density)
    assert out.size * 0.95 <= f.n_rejected <= out.size + 0.01 * len(Z)


def test_reproduce_targets_and_rows_carry_the_paper_numbers():
    from tunnelkit.reproduce import targets
    from tunnelkit.reproduce.jiang_tables import table_rows

    assert {"jiang-table2", "jiang-table3"} <= set(targets())
    rows = table_rows("jiang2023_table3", los=True, runs=2, seed=0, n_particles=20, levels=[0])
    assert [r["algorithm"] for r in rows] == ["TSWLS", "EKF", "UKF", "UPF", "prediction only"]
    assert rows[3]["paper_mean_m"] == pytest.approx(0.0101) and rows[0][
        "paper_var_m2"
    ] == pytest.approx(0.0043)
    assert all(np.isfinite(r["ours_mean_m"]) and r["ours_mean_m"] > 0 for r in rows)


def test_figures_and_explorer_callback(exp_hi):
    from tunnelkit.plots.tracking import particle_cloud_figure, rmse_bound_figure, tracks_figure
    from tunnelkit.scenarios import load_scenario
    from tunnelkit.widgets.tracking import upf_figure

    sc = load_scenario("jiang2023-straight")
    est = {"EKF": exp_hi.truth + 0.1}
    fig = tracks_figure(sc.tunnel(), sc.base_station(), exp_hi.truth, est, every=10)
    assert len(fig.frames) == 11 and len(fig.frames[0].data) == 2
    fig = rmse_bound_figure(exp_hi.times, {"EKF": np.ones(100)}, np.ones(100) * 0.5)
    assert fig.data[-1].name == "sqrt(PCRLB), H along the nominal path (approx.)"
    snap = {
        "t": 0.0,
        "particles": np.zeros((5, 4)),
        "weights": np.full(5, 0.2),
        "truth": np.zeros(2),
        "estimate": np.zeros(2),
    }
    assert len(particle_cloud_figure([snap, snap]).data) == 6
    fig = upf_figure(n_particles=20, seed=1)
    assert len(fig.data) == 5 and "RMSE" in fig.data[0].name


def test_cv_process_noise_equals_van_loan_discretisation():
    """Brute force for eq. 40's Q: Van Loan's matrix exponential of the continuous white-noise
    acceleration model dX = A X dt + G dW, E[dW dW^T] = q I dt."""
    from scipy.linalg import expm

    T, q = 0.37, 1.7
    A = np.zeros((4, 4))
    A[0, 2] = A[1, 3] = 1.0
    G = np.zeros((4, 2))
    G[2, 0] = G[3, 1] = 1.0
    M = np.block([[-A, q * G @ G.T], [np.zeros((4, 4)), A.T]]) * T
    E = expm(M)
    Phi = E[4:, 4:].T
    Qd = Phi @ E[:4, 4:]
    assert np.allclose(Phi, cv_transition(T), atol=1e-12)
    assert np.allclose(Qd, cv_process_noise(T, q), rtol=1e-10, atol=1e-14)


def test_tswls_velocity_spans_missed_epochs(exp_hi):
    """Noise-free fixes on the constant-velocity truth: the velocity is the truth's even right
    after a missed epoch (the time between fixes is then two periods), and run() equals update()."""
    m = exp_hi.model
    truth = exp_hi.truth[:9]
    Z = m.hx(truth)
    Z[[0, 3, 5, 6]] = np.nan
    x0 = truth[0] + np.array([0.5, -0.5, 1.0, -1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        one = vs.track(vs.VsTSWLS(m, x0, exp_hi.P0), Z)
    run = vs.VsTSWLS.run(m, Z[None], x0[None], exp_hi.P0)[0]
    assert np.allclose(one, run, atol=1e-9)
    assert np.allclose(run[0], x0) and np.allclose(run[1, 2:], x0[2:])  # prior until 2nd fix
    assert np.allclose(run[1:, :2], truth[[1, 2, 2, 4, 4, 4, 7, 8], :2], atol=1e-6)  # held fixes
    assert np.allclose(run[2:, 2:], truth[2:, 2:], atol=1e-5)


def test_cv_process_noise_allows_zero_q_but_simulate_cv_refuses_it():
    """q = 0 is the noise-free CV model (Halili's cv_model builds on it); sampling needs q > 0."""
    assert np.array_equal(cv_process_noise(0.1, 0.0), np.zeros((4, 4)))
    with pytest.raises(ValueError, match="q: must be > 0"):
        simulate_cv([0, 0, 1, 1], 0.1, 0.0, 3, np.random.default_rng(0))
    with pytest.raises(ValueError, match="q: must be >= 0"):
        cv_process_noise(0.1, -1.0)


def test_monte_carlo_progress_bar_draws_nothing(exp_hi, capsys):
    """The bar changes no random stream: the same seed gives identical estimates (UPF included)."""
    kw = {"names": ["EKF", "UPF"], "options": {"UPF": {"n_particles": 40}}}
    quiet = vs.monte_carlo(exp_hi, 3, 11, **kw)
    shown = vs.monte_carlo(exp_hi, 3, 11, progress=True, **kw)
    assert "3 runs" in capsys.readouterr().err  # tqdm writes to stderr outside a notebook
    assert list(shown) == ["EKF", "UPF"]
    for n in quiet:
        np.testing.assert_array_equal(shown[n], quiet[n])
    # one estimator per call draws the UPF from another child seed: not the same numbers
    alone = vs.monte_carlo(exp_hi, 3, 11, names=["UPF"], options=kw["options"])
    assert not np.array_equal(alone["UPF"], quiet["UPF"])
