"""JAVELIN told an odometry model: the odometry error states after the UE, their prediction
(the Jacobian against finite differences, the message formed as ``Odometry.draw`` forms it) and
their convergence to the drawn scale factor and heading bias on a long drive with radio."""

import numpy as np
import pytest

from tunnelkit.crlb import numeric_jacobian
from tunnelkit.odometry import AUTOMOTIVE, WHITE, Odometry
from tunnelkit.tracking.javelin import Javelin, JavelinConfig, JavelinState, PathMeasurements
from tunnelkit.tracking.javelin.motion import odometry_transition, predict
from tunnelkit.tracking.javelin.odometrystates import kinematic, odometry_columns
from tunnelkit.tracking.javelin.state import first_vue, track_slice


def _told_state(vues=2):
    st = JavelinState.initial([-30.0, 1.0, 1.0], 1.0, odometry=(0.01, 0.02, 1e-4))
    st.x[3:6] = [0.012, -0.015, 3e-4]
    for k in range(vues):
        st.append([4.0 + k, 2.0 - k], np.eye(2))
    return st


def test_told_white_is_the_paper_state_and_automotive_adds_three_states():
    cfg = JavelinConfig()
    assert cfg.told(WHITE) == cfg and cfg.n_odo == 0 and cfg.odometry_sigmas is None
    auto = cfg.told(AUTOMOTIVE)
    assert auto.n_odo == 3 and auto.sigma_speed == AUTOMOTIVE.speed_noise
    assert auto.odometry_sigmas == (0.01, AUTOMOTIVE.heading_bias, AUTOMOTIVE.yaw_rate_bias)
    assert Javelin([-40.0, 1.5, -3.3]).state.dim == 3
    from tunnelkit.tracking.javelin import JavelinDesign

    trk = Javelin([-40.0, 1.5, -3.3], JavelinDesign(config=auto))
    assert trk.state.dim == 6 and trk.state.n_odo == 3
    np.testing.assert_allclose(np.sqrt(np.diag(trk.P)[3:]), auto.odometry_sigmas)
    with pytest.raises(TypeError, match="odometry: expected an Odometry"):
        cfg.told(0.01)
    with pytest.raises(ValueError, match="sigma_heading_bias"):
        JavelinConfig(sigma_heading_bias=-0.1)


def test_the_vues_start_after_the_odometry_states():
    st = _told_state()
    assert first_vue(3) == 6 and st.n_vue == 2 and st.odometry == slice(3, 6)
    assert track_slice(1, 3) == slice(6, 8) and track_slice(2, 3) == slice(8, 10)
    np.testing.assert_allclose(st.positions()[1:, 1:], [[4.0, 2.0], [5.0, 1.0]])
    np.testing.assert_allclose(kinematic(st.x, 3), np.r_[st.x[:3], st.x[6:]])
    J = np.ones((2, 4, 7))
    Jo = odometry_columns(J, 3)
    assert Jo.shape == (2, 4, 10) and not Jo[..., 3:6].any() and Jo[..., 6:].all()
    keep = st.x[[0, 1, 2, 3, 4, 5, 8, 9]].copy()
    st.remove([1])
    np.testing.assert_allclose(st.x, keep)
    assert st.n_vue == 1 and st.copy().n_odo == 3
    with pytest.raises(ValueError, match="6 \\+ 2 n entries"):
        JavelinState(np.zeros(7), np.eye(7), n_odo=3)


@pytest.mark.parametrize("vue_motion", ["random_walk", "mirror"])
def test_the_odometry_jacobian_is_the_derivative_of_the_prediction(vue_motion):
    st = _told_state()
    speed, heading, dt = 9.0, 0.3, 0.1

    def f(z):  # the predicted state as a function of the odometry states and the message
        trial = st.copy()
        trial.x[3:6] = z[:3]
        inc = odometry_transition(trial, z[3], z[4], dt, vue_motion)[0]
        return trial.x + inc

    z0 = np.r_[st.x[3:6], speed, heading]
    num = numeric_jacobian(f, z0)
    _, F, G = odometry_transition(st, speed, heading, dt, vue_motion)
    np.testing.assert_allclose(F[:, 3:6], num[:, :3], atol=1e-7)
    # the message's white noise: d/dn_v of nu / (1 + s) and d/dn_theta of theta - b
    np.testing.assert_allclose(G, num[:, 3:], atol=1e-7)
    np.testing.assert_allclose(F[:, :3], np.eye(st.dim)[:, :3])  # the UE: F = I as the paper


def test_the_prediction_undoes_the_drawn_scale_and_bias():
    """A message formed as ``Odometry.draw`` forms it (no white noise) from the true motion,
    corrected with the true scale and bias, moves the UE exactly as the truth moves."""
    t = np.array([0.0, 0.1])
    v, th = np.array([20.0, 20.0]), np.array([0.2, 0.2])
    odo = Odometry(speed_scale=0.05, heading_bias=0.1, speed_noise=0.0, heading_noise=0.0)
    rng = np.random.default_rng(3)
    spd, hdg = odo.draw(t, v, th, rng)
    rng = np.random.default_rng(3)
    rng.standard_normal(4)  # the white draws (zero sigma), then the scale and the bias
    s, b = 0.05 * rng.standard_normal(), 0.1 * rng.standard_normal()
    st = JavelinState.initial([0.0, 0.0, 0.0], 1.0, odometry=(0.05, 0.1, 0.0))
    st.x[3:5] = s, b
    cfg = JavelinConfig().told(odo.__class__(speed_scale=0.05, heading_bias=0.1))
    x, P = predict(st, spd[0], hdg[0], 0.1, cfg)
    np.testing.assert_allclose(x[:2], 0.1 * 20.0 * np.array([np.cos(0.2), np.sin(0.2)]))
    np.testing.assert_allclose(x[3:6], [s, b, 0.0])
    assert np.all(np.linalg.eigvalsh(P) >= -1e-12)


def _line_of_sight(p, bs, sig, rng):
    q = p - bs
    phi = np.arctan2(q[1], q[0]) + sig[0] * rng.standard_normal()
    psi = np.arctan2(q[2], np.hypot(q[0], q[1])) + sig[1] * rng.standard_normal()
    r = np.linalg.norm(q)
    kap = r + sig[2] * rng.standard_normal()
    return PathMeasurements(
        np.array([phi]), np.array([psi]), np.array([kap]), np.array([r]), np.array([np.nan])
    )


def test_the_odometry_states_converge_to_the_drawn_scale_and_bias():
    """A 600 m straight drive at 20 m/s past a base station measuring the LoS (seeded): the
    told tracker's scale factor and heading bias end within a few of their posterior sigmas of
    the drawn values, far inside their priors, and its position beats the untold tracker's."""
    rng = np.random.default_rng(11)
    T, dt, v = 301, 0.1, 20.0
    t = dt * np.arange(T)
    truth = np.column_stack([-300.0 + v * t, np.full(T, 3.0), np.full(T, -4.0)])
    odo = Odometry(speed_scale=0.02, heading_bias=np.radians(2.0))
    draws = np.random.default_rng(5)
    spd, hdg = odo.draw(t, np.full(T, v), np.zeros(T), draws)
    draws = np.random.default_rng(5)
    draws.standard_normal(2 * T)  # the white speed and heading noise first (Odometry.draw)
    s, b = 0.02 * draws.standard_normal(), np.radians(2.0) * draws.standard_normal()
    bs = np.array([0.0, 0.0, 0.0])
    sig = (np.radians(0.2), np.radians(0.2), 0.3)
    epochs = [_line_of_sight(p, bs, sig, rng) for p in truth]
    base = JavelinConfig(sigma_phi=sig[0], sigma_psi=sig[1], sigma_kappa=sig[2], sigma_p0_ue=1.0)
    from tunnelkit.tracking.javelin import JavelinDesign

    told = Javelin(truth[0], JavelinDesign(config=base.told(odo)))
    run = told.run(epochs, spd, hdg, dt)
    sd = np.sqrt(np.diag(told.P)[3:5])
    err = told.x[3:5] - [s, b]
    assert np.all(np.abs(err) <= 4.0 * sd), (err, sd)
    assert np.all(sd < 0.2 * np.array([0.02, np.radians(2.0)]))
    untold = Javelin(truth[0], JavelinDesign(config=base)).run(epochs, spd, hdg, dt)
    e_told = np.linalg.norm(run.estimates[:, :2] - truth[:, :2], axis=1)
    e_untold = np.linalg.norm(untold.estimates[:, :2] - truth[:, :2], axis=1)
    assert np.sqrt(np.mean(e_told**2)) < np.sqrt(np.mean(e_untold**2))


def test_the_drive_bound_with_odometry_reduces_to_dead_reckoning_without_radio():
    """``drive_pcrlb(..., odometry=)`` with no radio information is
    :func:`~tunnelkit.reckoning.dead_reckoning_bound` along the drive; the white model gives the
    white bound of the two sigmas; the radio's information lowers it below both."""
    from tunnelkit.design import DesignSetup, drive_pcrlb
    from tunnelkit.reckoning import dead_reckoning_bound

    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    T = 40
    traj = setup.trajectory
    v = np.linalg.norm(traj.velocity[:T, :2], axis=1)
    th = np.arctan2(traj.velocity[:T, 1], traj.velocity[:T, 0])
    none = np.zeros((T, 2, 2))
    auto = drive_pcrlb(setup, none, sigma_p0=1.0, odometry=AUTOMOTIVE)
    ref = dead_reckoning_bound(traj.t[:T], v, th, AUTOMOTIVE, sigma_start=1.0)
    np.testing.assert_allclose(auto, ref, rtol=1e-12)
    info = np.tile(np.diag([4.0, 1.0]), (T, 1, 1))  # fixes of 0.5 m along, 1 m across
    white = drive_pcrlb(setup, info, sigma_p0=1.0)
    np.testing.assert_allclose(drive_pcrlb(setup, info, sigma_p0=1.0, odometry=WHITE), white,
                               rtol=1e-6)  # fmt: skip
    radio = drive_pcrlb(setup, info, sigma_p0=1.0, odometry=AUTOMOTIVE)
    assert np.all(radio <= ref + 1e-12) and radio[-1] < 0.5 * ref[-1]
    assert np.all(radio >= white - 1e-12)  # the repeating errors only add
    with pytest.raises(ValueError, match="sigma_speed, sigma_heading"):
        drive_pcrlb(setup, info, sigma_speed=0.2, odometry=AUTOMOTIVE)


def test_the_told_tracker_is_not_below_the_posterior_bound():
    """Monte-Carlo (seeded): drives whose scale factor, heading bias and start are drawn from
    the priors the tracker is told, the LoS measured with the told sigmas. The told tracker's
    2-D RMSE at the end and over the drive is not below the posterior bound
    (:func:`~tunnelkit.reckoning.posterior_bound` with the LoS's information about the
    horizontal position, height known: more than the tracker has) beyond the Monte-Carlo error,
    and lies within a few tens of per cent above it."""
    from tunnelkit.reckoning import posterior_bound
    from tunnelkit.tracking.javelin import JavelinDesign, draw_start

    T, dt, v, runs = 201, 0.1, 20.0, 24
    t = dt * np.arange(T)
    truth = np.column_stack([-300.0 + v * t, np.full(T, 3.0), np.full(T, -4.0)])
    odo = Odometry(speed_scale=0.02, heading_bias=np.radians(2.0), yaw_rate_bias=1e-3)
    sig = (np.radians(0.5), np.radians(0.5), 2.0)
    cfg = JavelinConfig(sigma_phi=sig[0], sigma_psi=sig[1], sigma_kappa=sig[2], sigma_p0_ue=1.0,
                        sigma_p0_height=0.01).told(odo)  # fmt: skip
    rng = np.random.default_rng(2026)
    err2 = np.zeros(T)
    for _ in range(runs):
        spd, hdg = odo.draw(t, np.full(T, v), np.zeros(T), rng)
        start = draw_start(truth[0], 1.0, rng, sigma_height=0.01)
        epochs = [_line_of_sight(p, np.zeros(3), sig, rng) for p in truth]
        trk = Javelin(start, JavelinDesign(config=cfg))
        est = trk.run(epochs, spd, hdg, dt).estimates
        err2 += np.sum((est[:, :2] - truth[:, :2]) ** 2, axis=1) / runs
    info = np.empty((T, 2, 2))
    for k, p in enumerate(truth):  # phi, psi, kappa about (x, y) at the truth, z known
        from tunnelkit.geometry import spherical_jacobian

        H = spherical_jacobian(p[None])[0][:, :2]
        info[k] = H.T @ np.diag(1.0 / np.square(sig)) @ H
    bound = posterior_bound(t, np.full(T, v), np.zeros(T), odo, info, sigma_start=1.0)
    rmse = np.sqrt(err2)
    # an RMSE over 24 drives: its standard error about 1 / sqrt(2 * 24) = 14 %
    assert rmse[-1] >= 0.7 * bound[-1] and np.sqrt(np.mean(err2)) >= 0.7 * np.sqrt(
        np.mean(bound**2)
    )
    assert rmse[-1] <= 1.4 * bound[-1]


def test_a_told_term_of_zero_is_a_known_state():
    """A repeating term told as zero leaves its state's prior variance zero (the state is known):
    our design's first fix (every path tried as the LoS, scored by its prior distance) must not
    need the inverse of that covariance (it raised LinAlgError: singular matrix), here along a
    row of sites on a car's odometry."""
    from dataclasses import replace

    from tunnelkit.design import DesignSetup
    from tunnelkit.design.longtunnel import long_tunnel_study

    setup = DesignSetup.from_scenario("mont-blanc-28ghz")
    for term in ("speed_scale", "heading_bias", "yaw_rate_bias"):
        res = long_tunnel_study(setup, ("8x8",), (400.0,), length=800.0, runs=1, speed=19.44,
                                odometry="automotive",
                                told_odometry=replace(AUTOMOTIVE, **{term: 0.0}))  # fmt: skip
        row = res.rows[0]
        assert np.isfinite(row["rmse"]) and row["rmse"] < row["dr_rmse"], (term, row)
