import numpy as np
import pytest
from javelin_geometric import toy_reflectors

from tunnelkit.crlb import numeric_jacobian
from tunnelkit.tracking.javelin import JavelinConfig, JavelinState
from tunnelkit.tracking.javelin.motion import motion_increment, predict


def _state_with_wall_vues(pu):
    st = JavelinState.initial(pu, 1.0)
    for pl in toy_reflectors():
        st.append(pl.mirror(np.asarray(pu))[1:], np.eye(2))
    return st


def test_ue_moves_by_speed_and_heading():
    st = JavelinState.initial([-30.0, 1.0, 1.0], 1.0)
    x, P = predict(st, 10.0, np.radians(30), 0.1, JavelinConfig())
    np.testing.assert_allclose(
        x, [-30.0 + np.cos(np.radians(30)), 1.0 + np.sin(np.radians(30)), 1.0]
    )
    assert np.all(np.linalg.eigvalsh(P - st.P) >= -1e-15)  # Q is PSD


@pytest.mark.parametrize("vue_motion", ["random_walk", "mirror"])
def test_G_is_the_derivative_of_the_increment(vue_motion):
    st = _state_with_wall_vues([-30.0, 1.0, 1.0])

    def inc(u):
        return motion_increment(st, u[0], u[1], 0.1, vue_motion)[0]

    _, G = motion_increment(st, 8.0, 0.2, 0.1, vue_motion)
    np.testing.assert_allclose(G, numeric_jacobian(inc, np.array([8.0, 0.2])), atol=1e-8)


def test_mirror_motion_is_exact_for_planar_reflectors():
    pu0 = np.array([-30.0, 1.0, 1.0])
    st = _state_with_wall_vues(pu0)
    speed, heading, dt = 10.0, np.radians(20), 0.1
    x, _ = predict(st, speed, heading, dt, JavelinConfig(), vue_motion="mirror")
    pu1 = pu0 + dt * speed * np.array([np.cos(heading), np.sin(heading), 0.0])
    truth = np.concatenate([pu1] + [pl.mirror(pu1)[1:] for pl in toy_reflectors()])
    np.testing.assert_allclose(x, truth, atol=1e-12)
    # the paper's random walk leaves the VUEs where they were
    x_rw, _ = predict(st, speed, heading, dt, JavelinConfig())
    np.testing.assert_allclose(x_rw[3:], st.x[3:])


def test_negative_dt_rejected():
    st = JavelinState.initial([-30.0, 1.0, 1.0], 1.0)
    with pytest.raises(ValueError, match=r"^dt"):
        predict(st, 1.0, 0.0, -0.1, JavelinConfig())


def test_the_midpoint_step_follows_a_steady_turn_where_the_held_one_lags():
    """On a circle driven at a steady rate the chord from epoch k to k+1 points along the mean of
    the two headings (brute force: the positions themselves), so dead reckoning on
    midpoint_messages keeps only the chord's length error (second order in the turn per step)
    where eq. 62's held heading lags by half a step; headings across +-pi average along the
    shorter arc; a missing message is held; the tracker configured "midpoint" equals the held
    tracker fed the midpoint messages; another name is refused naming motion_step."""
    from tunnelkit.reckoning import dead_reckoning
    from tunnelkit.tracking.javelin.motion import midpoint_messages

    R, v, dt, T = 30.0, 15.0, 0.1, 60
    t = dt * np.arange(T)
    ang = v * t / R + 0.5  # crosses +-pi on the way
    truth = R * np.stack([np.cos(ang), np.sin(ang)], -1)
    heading = np.angle(np.exp(1j * (ang + np.pi / 2)))
    speed = np.full(T, v)
    chords = np.angle(np.exp(1j * np.arctan2(*np.diff(truth, axis=0)[:, ::-1].T)))
    s_mid, h_mid = midpoint_messages(speed, heading)
    np.testing.assert_allclose(np.angle(np.exp(1j * (h_mid[:-1] - chords))), 0.0, atol=1e-12)
    held = dead_reckoning(t, speed, heading, truth[0]) - truth
    mid = dead_reckoning(t, s_mid, h_mid, truth[0]) - truth
    rms = lambda e: float(np.sqrt(np.mean(np.sum(e**2, 1))))  # noqa: E731
    w = v * dt / R  # the turn per step
    assert rms(mid) < 2 * T * v * dt * w**2 / 24  # the chords' length error, summed
    assert rms(held) > 100 * rms(mid)
    s2, h2 = midpoint_messages(
        [10.0, 12.0, np.nan, 9.0], [np.radians(179), np.radians(-179), 0.3, 0.2]
    )
    np.testing.assert_allclose(s2[:2], [11.0, 12.0])
    assert abs(np.angle(np.exp(1j * (h2[0] - np.pi)))) < 1e-12 and h2[1] == np.radians(-179)
    assert h2[3] == 0.2 and np.isnan(s2[2])
    with pytest.raises(ValueError, match=r"^speed, heading: "):
        midpoint_messages([1.0, 2.0], [0.0])
    with pytest.raises(ValueError, match=r"^heading: "):
        midpoint_messages([1.0, 2.0], [0.0, np.inf])
    with pytest.raises(ValueError, match=r"^motion_step: "):
        JavelinConfig(motion_step="euler")


def test_the_midpoint_tracker_is_the_held_one_on_the_midpoint_messages():
    import dataclasses

    from tunnelkit.simulation import evaluate, simulate_drive
    from tunnelkit.tracking.javelin import designs
    from tunnelkit.tracking.javelin.motion import midpoint_messages

    drive = simulate_drive("italiano2026-slalom", np.random.default_rng(3), n_epochs=8)
    d = designs.paper_vue()
    mid = d.with_(config=dataclasses.replace(d.config, motion_step="midpoint"))
    sp, hd = midpoint_messages(drive.speed, drive.heading)
    fed = dataclasses.replace(drive, speed=sp, heading=hd)
    a = evaluate(drive, mid).estimates
    np.testing.assert_array_equal(a, evaluate(fed, d).estimates)
    assert not np.array_equal(a, evaluate(drive, d).estimates)


def test_the_midpoint_step_survives_the_configs_copies_and_reads_no_message_ahead():
    """A config told an odometry model, or moved to another base station, keeps its motion step;
    epoch 0 of a midpoint run reads its own message (the estimate and the velocity the tracker
    reports there do not depend on the message of epoch 1)."""
    import dataclasses

    from tunnelkit.odometry import AUTOMOTIVE
    from tunnelkit.simulation import simulate_drive
    from tunnelkit.tracking.javelin import designs
    from tunnelkit.tracking.javelin.tracker import Javelin

    cfg = JavelinConfig(motion_step="midpoint")
    assert cfg.told(AUTOMOTIVE).motion_step == "midpoint"
    assert dataclasses.replace(cfg, base_station=(1.0, 0.0, 5.0)).motion_step == "midpoint"
    d = designs.paper_vue()
    d = d.with_(config=dataclasses.replace(d.config, motion_step="midpoint"))
    drive = simulate_drive("italiano2026-slalom", np.random.default_rng(4), n_epochs=3)
    other = drive.heading.copy()
    other[1] += 0.3
    runs = [
        Javelin(drive.truth[0], d).run(drive.epochs, drive.speed, h, drive.dt, keep_reports=True)
        for h in (drive.heading, other)
    ]
    np.testing.assert_array_equal(runs[0].estimates[0], runs[1].estimates[0])
    assert not np.array_equal(runs[0].estimates[2], runs[1].estimates[2])
