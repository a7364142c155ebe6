"""Halili 2022 trackers: Jacobian, adaptive R, the three approaches, observability, bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from tunnelkit import crlb
from tunnelkit import doppler_drive as dv
from tunnelkit.constants import C
from tunnelkit.tracking import doppler as dp
from tunnelkit.tracking import registry

CLEAN = {
    **dv.IDEAL,
    "reflection_coeff": 0.0,
    "speed_amplitude": 0.0,
}


@pytest.fixture(scope="module")
def drive():
    return dv.make_drive()


@pytest.fixture(scope="module")
def setup(drive):
    return dp.DopplerSetup.from_drive(drive)


def test_family_registered_lazily():
    fam = registry.family("halili2022")
    assert list(fam) == list(dp.APPROACHES)
    assert [cls.name for cls in fam.values()] == list(dp.APPROACHES)


def test_jacobian_matches_finite_differences(setup):
    rng = np.random.default_rng(0)
    for _ in range(20):
        s = np.concatenate([setup.tx + rng.uniform(-200, 200, 2), rng.uniform(-30, 30, 2)])
        J = dp.doppler_jacobian(s, setup)
        Jn = crlb.numeric_jacobian(lambda x: dp.doppler_model(x, setup)[..., None], s, step=1e-5)
        assert J.shape == (1, 4)
        assert np.allclose(J, Jn, rtol=1e-6, atol=1e-9)
    # vectorised over leading axes
    S = rng.uniform(-50, 50, (3, 5, 4))
    assert dp.doppler_jacobian(S, setup).shape == (3, 5, 1, 4)


def test_model_sign_pinned(setup):
    """Approaching state: positive; receding: negative; the paper's eq. 5 has the opposite sign."""
    before = np.array([setup.tx[0] - 100, setup.tx[1] - 7, 25.0, 0.0])
    after = np.array([setup.tx[0] + 100, setup.tx[1] - 7, 25.0, 0.0])
    assert dp.doppler_model(before, setup) > 100 and dp.doppler_model(after, setup) < -100
    w = before[:2] - setup.tx
    paper_eq5 = before[2:] @ w * setup.k / np.sqrt(w @ w + setup.dz**2)
    assert paper_eq5 == pytest.approx(-float(dp.doppler_model(before, setup)))


def test_cv_model_q():
    F, Q = dp.cv_model(0.5, 2.0)
    assert np.allclose(F @ [1, 2, 3, 4], [2.5, 4, 3, 4])
    assert Q[0, 0] == pytest.approx(2.0 * 0.5**3 / 3) and Q[0, 2] == pytest.approx(2.0 * 0.5**2 / 2)
    assert np.all(np.linalg.eigvalsh(Q) >= -1e-15)


def test_adaptive_r_posterior_is_consistent():
    """Eq. 15 with the posterior covariance recovers the true R; the paper's prior form overshoots."""
    setup = dp.DopplerSetup(np.zeros(2), 0.0, C, 1.0)  # H = f_c / c = 1
    est = {}
    for form in ("posterior", "paper"):
        rng = np.random.default_rng(1)
        kf = dp.SpeedKF(
            setup,
            0.0,
            sigma_hz=5.0,
            q=100.0,
            sigma_u0=1.0,
            adaptive=True,
            a=0.99,
            adaptive_form=form,
        )
        u, rs = 0.0, []
        for _ in range(12000):
            u += 10.0 * rng.standard_normal()
            kf.step(u + 20.0 * rng.standard_normal())
            rs.append(kf.kf.R[0, 0])
        est[form] = np.mean(rs[4000:])
    assert est["posterior"] == pytest.approx(400.0, rel=0.06)
    assert est["paper"] > 1.3 * 400.0


def test_ekf_converges_on_clean_drive():
    """Noise-free Doppler, 3 m along-track GNSS error: the pass by the transmitter removes most of it."""
    d = dv.make_drive(**CLEAN)
    m = dv.measure(d, np.random.default_rng(0))
    fix = dv.GnssFix(d.position[0] + [3.0, 0.0], d.velocity[0].copy(), 3.0, 0.1)
    tr = dp.run_approaches(d, m, fix, sigma_hz=1.0, approaches=("EKF DS",))["EKF DS"]
    err = np.linalg.norm(tr.position - d.position, axis=1)
    k = d.closest_index
    assert err[0] == pytest.approx(3.0)
    assert err[k + 100] < 1.0  # after the pass (3.2 s later)


def test_radial_approximation_loses_twice_the_offset():
    """Eq. 16 (dr the range change): the pass by the transmitter loses about 2 x closest distance."""
    d = dv.make_drive(**CLEAN)
    m = dv.measure(d, np.random.default_rng(0))
    fix = dv.GnssFix(d.position[0].copy(), d.velocity[0].copy(), 0.5, 0.05)
    # the paper's filters (no gate): at sigma = 1 Hz the random-walk speed KF cannot follow the
    # approach speed through the pass, and a gate would reject those Dopplers
    tr = dp.run_approaches(d, m, fix, sigma_hz=1.0, approaches=("KF DS and ToA",), gate=None)
    tr = tr["KF DS and ToA"]
    travelled = d.position[-1, 0] - d.position[0, 0]
    radial = d.range[0] + d.range[-1] - 2 * d.range.min()
    assert travelled - tr.position[-1, 0] == pytest.approx(travelled - radial, abs=0.5)
    assert travelled - radial == pytest.approx(2 * d.range.min(), rel=0.02)


def test_same_seed_same_numbers(drive):
    a = dp.error_study(
        drive, np.random.default_rng(5), sigmas={"32.79 Hz": 32.79}, approaches=("EKF DS",)
    )
    b = dp.error_study(
        drive, np.random.default_rng(5), sigmas={"32.79 Hz": 32.79}, approaches=("EKF DS",)
    )
    assert np.array_equal(a[("EKF DS", "32.79 Hz")], b[("EKF DS", "32.79 Hz")])


def test_small_r_hurts_with_multipath_bias(drive):
    """Paper sec. 6: with biased measurements, sigma = 10.37 Hz is worse than 103.70 Hz (EKF DS,
    the paper's filter: no gate)."""
    small = dp.mean_errors(drive, range(3), sigma_hz=10.37, approaches=("EKF DS",), gate=None)
    large = dp.mean_errors(drive, range(3), sigma_hz=103.70, approaches=("EKF DS",), gate=None)
    assert small["EKF DS"] > 1.5 * large["EKF DS"]


def test_which_approach_wins_depends_on_the_doppler_errors(drive):
    """Paper: EKF DS beats KF DS and ToA in mean error. On our drive this holds when the Doppler
    errors are white; correlated errors and outliers on the Doppler (our default) reverse it.
    The paper's filters (no gate)."""
    names = ("EKF DS", "KF DS and ToA")
    white = dv.make_drive(doppler_bias_hz=0.0, outlier_prob=0.0, cfo_walk_hz=0.0)
    mw = dp.mean_errors(white, range(4), sigma_hz=103.70, approaches=names, gate=None)
    assert mw["EKF DS"] < 0.95 * mw["KF DS and ToA"]
    md = dp.mean_errors(drive, range(4), sigma_hz=103.70, approaches=names, gate=None)
    assert md["EKF DS"] > 1.2 * md["KF DS and ToA"]


def test_gate_skips_outliers(drive, setup):
    fix = dv.gnss_fix(drive, np.random.default_rng(0))
    ekf = dp.DopplerEKF(setup, fix, sigma_hz=10.0)  # gate = 0.999 by default
    F, _ = dp.cv_model(setup.dt, 0.5)
    x_pred = F @ ekf.kf.x
    ekf.step(-120.0)  # approaching at 25 m/s means about +112 Hz: an outlier
    assert ekf.n_rejected == 1 and np.allclose(ekf.kf.x, x_pred)
    ekf.step(float(drive.doppler_los[2]))
    assert ekf.n_rejected == 1
    with pytest.raises(ValueError, match="gate"):
        dp.DopplerEKF(setup, fix, gate=1.5)
    plain = dp.mean_errors(drive, range(3), sigma_hz=32.79, approaches=("EKF DS",), gate=None)
    gated = dp.mean_errors(drive, range(3), sigma_hz=32.79, approaches=("EKF DS",))
    assert gated["EKF DS"] < 0.8 * plain["EKF DS"]


def test_snapshot_fim_against_numeric(setup):
    p = setup.tx + np.array([-40.0, -7.0])
    v = np.array([25.0, 0.0])
    F = dp.snapshot_fim(p, v, setup, sigma_hz=10.0, sigma_range=1.0)

    def h(x):
        s = np.concatenate([x, np.broadcast_to(v, x.shape)], -1)
        return np.stack([dp.doppler_model(s, setup), dv.slant_range(x, setup.tx, setup.dz)], -1)

    Fn = crlb.numeric_fim(h, p, np.diag([100.0, 1.0]), step=1e-4)
    assert np.allclose(F, Fn, rtol=1e-5)
    # one scalar measurement: rank one
    assert np.linalg.matrix_rank(dp.snapshot_fim(p, v, setup, sigma_hz=10.0), tol=1e-12) == 1


def test_lateral_information_vanishes_far_from_the_transmitter(setup):
    v = np.array([25.0, 0.0])
    near = dp.snapshot_fim(
        setup.tx + np.array([-10.0, -7.0]), v, setup, sigma_hz=10.0, sigma_range=1.0
    )
    far = dp.snapshot_fim(
        setup.tx + np.array([-900.0, -7.0]), v, setup, sigma_hz=10.0, sigma_range=1.0
    )
    assert far[1, 1] < 1e-3 * near[1, 1]
    assert far[0, 0] > 0.9 / 1.0  # range still pins the along-track position far away


def test_posterior_crlb_equals_kf_covariance(drive):
    """For linear dynamics the PCRLB recursion is the KF Riccati recursion with H at the truth."""
    n = 300
    P = dp.posterior_crlb(drive, sigma_hz=30.0, sigma_range=2.0)
    setup = dp.DopplerSetup.from_drive(drive)
    kf = KalmanFilter(dim_x=4, dim_z=2)
    kf.F, kf.Q = dp.cv_model(setup.dt, 0.5)
    kf.R = np.diag([30.0**2, 2.0**2])
    kf.P = np.diag([drive.config.gnss_sigma_m**2] * 2 + [drive.config.gnss_sigma_v**2] * 2)
    s = np.concatenate([drive.position, drive.velocity], -1)
    for k in range(n):
        if k:
            kf.predict()
        w = drive.position[k] - setup.tx
        hr = np.concatenate([w / dv.slant_range(drive.position[k], setup.tx, setup.dz), [0, 0]])
        kf.H = np.vstack([dp.doppler_jacobian(s[k], setup), hr])
        kf.update(np.zeros(2))  # the covariance does not depend on the value
    assert np.allclose(P[n - 1], kf.P, rtol=1e-6, atol=1e-10)


def test_posterior_crlb_observability(drive):
    """Doppler alone: the along-track bound collapses at the pass; the lateral one stays loose far away."""
    P = dp.posterior_crlb(drive, sigma_hz=32.79)
    k = drive.closest_index
    sx, sy = np.sqrt(P[:, 0, 0]), np.sqrt(P[:, 1, 1])
    assert sx[k + 30] < 0.5 * sx[k - 30]
    assert sy[k - 300] > 5 * sy[k + 30]
    # a worse GNSS fix raises the bound before the pass
    P20 = dp.posterior_crlb(drive, sigma_hz=32.79, sigma_p0=20.0)
    assert np.sqrt(P20[200, 0, 0]) > 3 * sx[200]


def test_dropped_and_nan_doppler_predict_only(drive, setup):
    fix = dv.gnss_fix(drive, np.random.default_rng(0))
    ekf = dp.DopplerEKF(setup, fix, sigma_hz=30.0)
    F, _ = dp.cv_model(setup.dt, 0.5)
    x_pred = F @ ekf.kf.x
    with pytest.warns(dp.MeasurementWarning, match="dropped"):
        ekf.step(float("nan"))
    assert np.allclose(ekf.kf.x, x_pred)
    with pytest.warns(dp.MeasurementWarning):
        ekf.step(None)
    with pytest.raises(ValueError, match="z"):
        ekf.step(float("inf"))
    with pytest.raises(TypeError, match="z"):
        ekf.step("fast")


def test_run_with_dropped_epochs_warns_once():
    d = dv.make_drive(drop_prob=0.05)
    rng = np.random.default_rng(0)
    m = dv.measure(d, rng)
    fix = dv.gnss_fix(d, rng)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        out = dp.run_approaches(d, m, fix, approaches=("EKF DS", "KF DS and ToA"))
    assert (
        len([x for x in w if issubclass(x.category, dp.MeasurementWarning)]) == 2
    )  # one per tracker
    for tr in out.values():
        assert np.all(np.isfinite(tr.position))


def test_toa_earlier_than_possible_is_rejected(setup):
    kf = dp.RangeKF(setup, 100.0, sigma_toa=1e-9, calibration_epochs=1)
    kf.step(25.0, 100.0 / C)  # calibrates
    d_before = kf.distance
    with pytest.warns(dp.MeasurementWarning, match="physical minimum"):
        kf.step(25.0, 0.5 / C)  # 0.5 m, below the transmitter's height above the antenna
    assert kf.distance == pytest.approx(d_before - 25.0 * setup.dt)
    with pytest.warns(dp.MeasurementWarning, match="not a time of flight"):
        kf.step(25.0, -1e-9)


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"sigma_hz": -1.0}, "sigma_hz"),
        ({"q": -0.5}, "q"),
        ({"sigma_hz": 0.0}, "sigma_hz"),
        ({"a": 1.5}, "a"),
        ({"adaptive_form": "prior"}, "adaptive_form"),
    ],
)
def test_bad_configuration(drive, setup, kw, match):
    fix = dv.gnss_fix(drive, np.random.default_rng(0))
    with pytest.raises(ValueError, match=match):
        dp.DopplerEKF(setup, fix, **kw)


def test_speed_of_zero_is_refused(setup):
    with pytest.raises(ValueError, match="heading is undefined"):
        dv.GnssFix(np.zeros(2), np.zeros(2), 1.0, 0.1)
    with pytest.raises(ValueError, match="v0"):
        dp.HeadingDeadReckoning(np.zeros(2), np.zeros(2))
    with pytest.raises(ValueError, match="sigma_toa"):
        dp.RangeKF(setup, 100.0, sigma_toa=-1e-9)
    with pytest.raises(ValueError, match="q"):
        dp.SpeedKF(setup, 25.0, q=-1.0)
    with pytest.raises(ValueError, match="approaches"):
        dp.run_approaches(dv.make_drive(), None, None, approaches=("Magic",))


def test_reproduce_target_labels_paper_and_ours():
    from tunnelkit.reproduce import run

    rep = run("halili", runs=1, seed=0)
    recs = rep.records()
    assert len(recs) == 16  # 3 approaches x (the paper + 4 sigmas), then dead reckoning
    paper = [r for r in recs if r["source"].startswith("paper")]
    assert [r["mean_m"] for r in paper] == [20.30, 30.46, 21.04]  # data/reference, measured drive
    ours = [r for r in recs if r["source"].startswith("ours")]
    assert all(r["p90_m"] > r["mean_m"] > 0 for r in ours)
    assert any("measured" in n for n in rep.notes) and "synthetic" in rep.to_table()


def test_figures_and_explorer(drive, setup):
    from tunnelkit.plots import doppler as pl
    from tunnelkit.widgets.doppler import doppler_explorer, doppler_figure

    fig = doppler_figure(sigma_hz=50.0, q=0.5, doppler_bias_hz=0.0, seed=1)
    assert len(fig.data) == 9 and "mean error" in fig.layout.title.text
    ex = doppler_explorer()
    ex.set(sigma_hz=100.0)
    assert ex.values["sigma_hz"] == 100.0 and len(ex.figure.data) == 9
    with pytest.raises(ValueError, match="sigma_hz"):
        doppler_figure(sigma_hz=-1.0)
    errs = {("EKF DS", "32.79 Hz"): np.arange(10.0), ("KF DS and ToA", "dynamic"): np.arange(5.0)}
    cdf = pl.approach_cdfs(errs, {("EKF DS", "32.79 Hz"): 58.19})
    assert len(cdf.data) == 3
    P = dp.posterior_crlb(drive, sigma_hz=30.0)
    assert len(pl.pcrlb_figure(drive, {"Doppler": P}).data) == 2
    assert len(pl.information_figure(drive, setup).data) == 4


def test_cv_model_equals_the_tracking_cv_model():
    """Halili eq. 2-3 and the filterpy-built Jiang eq. 41 / white-noise-acceleration Q agree."""
    from tunnelkit.tracking.cv import cv_process_noise, cv_transition

    F, Q = dp.cv_model(0.032, 0.5)
    assert np.allclose(F, cv_transition(0.032)) and np.allclose(Q, cv_process_noise(0.032, 0.5))


def test_range_kf_step_is_eq_17_to_21_by_hand(setup):
    """One predict/update of the ToA KF computed by hand: d = d - dt u, P + q dt, H = 1/c."""
    d0, sig_d0, q, s_toa, u = 120.0, 2.0, 0.5, 3e-9, 24.0
    kf = dp.RangeKF(setup, d0, sigma_toa=s_toa, q=q, sigma_d0=sig_d0, calibrate=False)
    z = 117.9 / C
    got = kf.step(u, z)
    d_pred = d0 - setup.dt * u  # eq. 17 with the approach sign
    P_pred = sig_d0**2 + q * setup.dt  # eq. 18
    H = 1.0 / C
    K = P_pred * H / (H * P_pred * H + s_toa**2)  # eq. 19
    d_post = d_pred + K * (z - H * d_pred)  # eq. 20
    assert got == pytest.approx(d_post, rel=1e-12)
    assert kf.kf.P[0, 0] == pytest.approx((1 - K * H) * P_pred, rel=1e-9)  # eq. 21


def test_cv_model_is_bitwise_the_tracking_cv_model_and_allows_zero_q():
    from tunnelkit.tracking.cv import cv_process_noise, cv_transition

    F, Q = dp.cv_model(0.032, 0.5)
    assert np.array_equal(F, cv_transition(0.032)) and np.array_equal(
        Q, cv_process_noise(0.032, 0.5)
    )
    assert np.array_equal(dp.cv_model(0.032, 0.0)[1], np.zeros((4, 4)))
