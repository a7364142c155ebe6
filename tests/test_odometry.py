"""Odometry as a model: the white preset draws as the drive simulator always drew, the refusals
name their parameter, and dead reckoning's Monte-Carlo error sits on its bound."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tunnelkit.odometry import AUTOMOTIVE, SIGMA_HEADING, SIGMA_SPEED, WHITE, Odometry
from tunnelkit.reckoning import _step, _transition, dead_reckoning, dead_reckoning_bound

DT = 0.1
N_MC = 2000


def _straight(length=1000.0, speed=20.0):
    T = round(length / speed / DT) + 1
    return np.arange(T) * DT, np.full(T, speed), np.zeros(T)


def _curved(T=501, speed=15.0, omega=0.05):
    t = np.arange(T) * DT
    return t, speed + 2.0 * np.sin(0.1 * t), 0.3 + omega * t


def _monte_carlo(odometry, t, v, th, seed, n=N_MC, sigma_start=0.0):
    """Squared 2-D errors (n, T) of dead reckoning over ``n`` drives, and the arrival patterns."""
    rng = np.random.default_rng(seed)
    T = t.size
    S, H = np.empty((n, T)), np.empty((n, T))
    for i in range(n):
        S[i], H[i] = odometry.draw(t, v, th, rng)
    start = sigma_start * rng.standard_normal((n, 2))
    truth = dead_reckoning(t, v, th, np.zeros(2))  # the truth: the same kinematics, exact inputs
    err = dead_reckoning(t, S, H, start) - truth
    return (err**2).sum(-1), np.isfinite(S)


def test_white_preset_draws_as_the_simulator_did():
    t, v, th = _curved(T=80)
    old = np.random.default_rng(20261202)
    want_v = v + SIGMA_SPEED * old.standard_normal(t.size)
    want_h = th + SIGMA_HEADING * old.standard_normal(t.size)
    new = np.random.default_rng(20261202)
    got_v, got_h = WHITE.draw(t, v, th, new)
    assert got_v.tobytes() == want_v.tobytes() and got_h.tobytes() == want_h.tobytes()
    assert new.bit_generator.state == old.bit_generator.state  # the rng consumed the same
    assert WHITE == Odometry.white() and WHITE.is_white and not AUTOMOTIVE.is_white


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"speed_scale": 1.0}, "speed_scale"),
        ({"speed_scale": -0.01}, "speed_scale"),
        ({"heading_drift": -1e-5}, "heading_drift"),
        ({"heading_drift": float("inf")}, "heading_drift"),
        ({"speed_noise": -0.1}, "speed_noise"),
        ({"heading_bias": float("nan")}, "heading_bias"),
        ({"yaw_rate_bias": -1e-6}, "yaw_rate_bias"),
        ({"heading_noise": -1.0}, "heading_noise"),
        ({"rate": 0.0}, "rate"),
        ({"dropout": 1.0}, "dropout"),
        ({"dropout": -0.1}, "dropout"),
    ],
)
def test_refusals_name_the_parameter(kw, name):
    with pytest.raises((ValueError, TypeError), match=name):
        Odometry(**kw)


def test_refusals_of_the_calls_name_the_argument():
    t, v, th = _straight(100.0)
    with pytest.raises(TypeError, match="rng"):
        WHITE.draw(t, v, th, 0)
    with pytest.raises(ValueError, match="speed"):
        WHITE.draw(t, v[:-1], th, np.random.default_rng(0))
    with pytest.raises(ValueError, match="t:"):
        dead_reckoning(t[::-1], v, th, np.zeros(2))
    with pytest.raises(ValueError, match="speed_msg"):
        dead_reckoning(t, np.full_like(v, np.nan), th, np.zeros(2))
    with pytest.raises(ValueError, match="sigma_start"):
        dead_reckoning_bound(t, v, th, WHITE, -1.0)
    with pytest.raises(TypeError, match="odometry"):
        dead_reckoning_bound(t, v, th, "white")


def test_rate_and_dropouts_leave_nan_and_dead_reckoning_holds():
    t, v, th = _straight(100.0)
    slow = Odometry(rate=5.0)  # a message every other 10 Hz epoch
    s, h = slow.draw(t, v, th, np.random.default_rng(3))
    assert np.isnan(s[1::2]).all() and np.isfinite(s[::2]).all() and np.isnan(h[1::2]).all()
    lossy = Odometry(dropout=0.3)
    s, _ = lossy.draw(t, v, th, np.random.default_rng(4))
    assert 0.15 < np.isnan(s).mean() < 0.45
    # holding: a missing message repeats the last one exactly
    msg = np.array([10.0, np.nan, np.nan, 12.0, np.nan])
    p = dead_reckoning(np.arange(5.0), msg, np.zeros(5), np.zeros(2))
    np.testing.assert_allclose(p[:, 0], [0, 10, 20, 30, 42])


def test_zero_noise_gives_zero_error_and_a_zero_bound():
    t, v, th = _curved()
    exact = Odometry(speed_noise=0.0, heading_noise=0.0)
    s, h = exact.draw(t, v, th, np.random.default_rng(0))
    assert np.array_equal(s, v) and np.array_equal(h, th)
    truth = dead_reckoning(t, v, th, np.array([5.0, -2.0]))
    assert np.array_equal(dead_reckoning(t, s, h, np.array([5.0, -2.0])), truth)
    assert not dead_reckoning_bound(t, v, th, exact, 0.0).any()


@pytest.mark.parametrize("fresh", [True, False])
def test_the_bound_jacobians_match_finite_differences(fresh):
    rng = np.random.default_rng(11)
    dt, vp, thp, v = 0.1, 17.0, 0.7, 18.5
    F, G = _transition(dt, vp, thp, v, fresh)
    h = 1e-6
    x0, w0 = np.zeros(7), np.zeros(3)
    Fn = np.column_stack(
        [(_step(x0 + h * e, w0, dt, vp, thp, v, fresh) - _step(x0 - h * e, w0, dt, vp, thp, v, fresh)) / (2 * h) for e in np.eye(7)]
    )  # fmt: skip
    Gn = np.column_stack(
        [(_step(x0, w0 + h * e, dt, vp, thp, v, fresh) - _step(x0, w0 - h * e, dt, vp, thp, v, fresh)) / (2 * h) for e in np.eye(3)]
    )  # fmt: skip
    np.testing.assert_allclose(F, Fn, atol=1e-7)
    np.testing.assert_allclose(G, Gn, atol=1e-7)
    # a small random error state: the step is its linearisation to second order
    x = 1e-4 * rng.standard_normal(7)
    w = 1e-4 * rng.standard_normal(3)
    np.testing.assert_allclose(_step(x, w, dt, vp, thp, v, fresh), F @ x + G @ w, atol=1e-8)


def _mse_and_se(e2):
    return e2.mean(0), e2.std(0, ddof=1) / np.sqrt(e2.shape[0])


@pytest.mark.parametrize(
    ("odometry", "drive", "seed"),
    [
        (WHITE, _straight, 1),
        (AUTOMOTIVE, _straight, 2),
        (replace(AUTOMOTIVE, dropout=0.0), _curved, 3),
        (Odometry(speed_scale=0.05, heading_bias=0.05, heading_drift=0.01), _curved, 4),
    ],
)
def test_dead_reckoning_attains_its_bound(odometry, drive, seed):
    """Linear enough: the Monte-Carlo MSE within 4.5 standard errors of the bound at every
    epoch (the bound averaged over the drives' arrival patterns when messages are lost)."""
    t, v, th = drive()
    e2, arrived = _monte_carlo(odometry, t, v, th, seed, sigma_start=0.5)
    mse, se = _mse_and_se(e2)
    bound2 = (dead_reckoning_bound(t, v, th, odometry, 0.5, arrived=arrived) ** 2).mean(0)
    assert np.all(np.abs(mse - bound2) <= 4.5 * se + 1e-12)
    assert np.all(bound2 > 0)


def test_held_messages_on_a_curve_never_beat_the_bound():
    """Lost messages held while the truth turns: dead reckoning's error adds the model error the
    bound does not hold, so it sits above the bound, never below it by more than MC noise."""
    t, v, th = _curved(omega=0.2)
    odo = replace(AUTOMOTIVE, dropout=0.5)
    e2, arrived = _monte_carlo(odo, t, v, th, 5)
    mse, se = _mse_and_se(e2)
    bound2 = (dead_reckoning_bound(t, v, th, odo, 0.0, arrived=arrived) ** 2).mean(0)
    assert np.all(mse >= bound2 - 4.5 * se)
    assert mse[-1] > bound2[-1]  # the held headings cost something at the end


def test_the_bound_without_a_pattern_is_the_schedule_s():
    t, v, th = _straight(200.0)
    full = dead_reckoning_bound(t, v, th, replace(AUTOMOTIVE, dropout=0.0))
    assert np.array_equal(full, dead_reckoning_bound(t, v, th, AUTOMOTIVE))
    pattern = np.ones((1, t.size), bool)
    assert np.allclose(dead_reckoning_bound(t, v, th, AUTOMOTIVE, arrived=pattern)[0], full)
    # on a straight drive at constant speed a lost message only loses information
    lossy = np.random.default_rng(0).random((5, t.size)) > 0.3
    assert np.all(dead_reckoning_bound(t, v, th, AUTOMOTIVE, arrived=lossy) >= full - 1e-12)


def test_a_drive_with_lost_messages_runs_and_scores():
    """The drive simulator draws through the model; JAVELIN predicts over a lost message with
    the last one (NaN: missing) and the drive scores."""
    from tunnelkit import simulation
    from tunnelkit.simulation.scoring import evaluate

    kw = {"condition": "L", "n_epochs": 10}
    odo = Odometry(rate=5.0, dropout=0.4, heading_bias=0.02, speed_scale=0.01)
    d = simulation.simulate_drive(
        "italiano2026-straight", np.random.default_rng(8), odometry=odo, **kw
    )
    assert np.isnan(d.speed).sum() >= 5 and np.isnan(d.speed[0])  # the first one lost too
    ev = evaluate(d)
    assert np.isfinite(ev.estimates).all() and np.isfinite(ev.metrics["rmse_2d_m"])
    white = simulation.simulate_drive("italiano2026-straight", np.random.default_rng(8), **kw)
    same = simulation.simulate_drive(
        "italiano2026-straight", np.random.default_rng(8), odometry=WHITE, **kw
    )
    assert white.speed.tobytes() == same.speed.tobytes()
    assert white.heading.tobytes() == same.heading.tobytes()
    with pytest.raises(TypeError, match="odometry: expected"):
        simulation.simulate_drive(
            "italiano2026-straight", np.random.default_rng(8), odometry=0.3, **kw
        )


def test_the_study_reports_the_drift_beside_the_bound():
    from tunnelkit.studies.odometry import MODELS, drift, drift_rows, drift_table

    d = drift(WHITE, n_drives=400, seed=0, length=2000.0)
    mse = d.rmse**2
    assert np.all(np.abs(mse - d.bound**2) <= 4.5 * d.mse_se + d.along**2 + 1e-12)
    # the cosine of the heading noise: every step short by sigma^2 / 2 on average
    short = -(1.0 - np.exp(-(SIGMA_HEADING**2) / 2)) * d.distance[-1]
    assert abs(d.along[-1] - short) < 0.25 * abs(short)
    rows = drift_rows(n_drives=50, seed=1, distances=(40.0, 100.0), speed=13.89)
    assert [r["distance"] for r in rows] == [40.0, 100.0]
    assert all(r["automotive_bound"] > r["white_bound"] > 0 for r in rows)
    table = drift_table(rows).splitlines()
    assert len(table) == 4 and all(m in table[0] for m in MODELS)
    with pytest.raises(ValueError, match="distances"):
        d.at([2500.0])


def test_the_javelin_tables_take_a_named_odometry_and_say_so(capsys):
    from tunnelkit.cli import main
    from tunnelkit.reproduce import run

    with pytest.raises(ValueError, match="odometry"):
        run("jiang-crlb", runs=10, odometry="automotive")
    with pytest.raises(ValueError, match="odometry"):
        run("javelin-table1", runs=1, odometry="gyro")
    assert main(["reproduce", "halili", "--runs", "1", "--odometry", "automotive"]) == 2
    assert "--odometry" in capsys.readouterr().err
    from tunnelkit.reproduce.javelin_tables import javelin_table

    kw = {"extractions": ("ml",), "n_epochs": 12}
    white = javelin_table("italiano2026-straight", "italiano2026_table1", ("L",), 1, 3, False, **kw)
    auto = javelin_table(
        "italiano2026-straight", "italiano2026_table1", ("L",), 1, 3, False,
        odometry="automotive", **kw,
    )  # fmt: skip
    assert "odometry" not in white.meta and auto.meta["odometry"] == "automotive"
    assert any("automotive odometry model" in n for n in auto.notes)
    assert "automotive odometry" in auto.title
    dr = (
        {r[0]: r for r in white.rows}["dead reckoning-L"],
        {r[0]: r for r in auto.rows}["dead reckoning-L"],
    )
    assert dr[0][2] != dr[1][2]  # other messages, another dead reckoning


def test_the_javelin_tables_step_as_each_design_does_unless_told_and_say_so(capsys):
    """By default each design takes its own step: the paper's design eq. 62's held message, ours
    the midpoint of two (and each column's dead reckoning the same); ``motion_step`` makes every
    JAVELIN take one. On the slalom the midpoint takes most of dead reckoning's error away (the
    held step lags a turning drive); the report says which; a target without V2X messages and an
    unknown step are refused naming the option."""
    from tunnelkit.cli import main
    from tunnelkit.reproduce import run
    from tunnelkit.reproduce.javelin_tables import javelin_table

    with pytest.raises(ValueError, match=r"^motion_step: target .jiang-crlb."):
        run("jiang-crlb", runs=10, motion_step="midpoint")
    with pytest.raises(ValueError, match=r"^motion_step: "):
        run("javelin-table2", runs=1, motion_step="euler")
    assert main(["reproduce", "halili", "--runs", "1", "--motion-step", "midpoint"]) == 2
    assert "--motion-step" in capsys.readouterr().err
    args = ("italiano2026-slalom", "italiano2026_table2", ("L",), 2, 3, False)
    kw = {"extractions": ("ml",), "n_epochs": 20}
    own, held, mid = (javelin_table(*args, motion_step=s, **kw) for s in (None, "held", "midpoint"))
    assert "motion_step" not in own.meta and mid.meta["motion_step"] == "midpoint"
    assert held.meta["motion_step"] == "held" and "held" in held.title
    assert "midpoint" in mid.title and "midpoint" not in own.title
    assert any("ours" in n and "eq. 62" in n for n in own.notes if n.startswith("Motion step"))
    assert any("motion_step='midpoint'" in n for n in mid.notes)

    def dr(t, col):  # dead reckoning in column col (0 the paper's design, 2 ours)
        return {(r[0], r[1]): r for r in t.rows}[("dead reckoning-L", "rmse_2d_m")][2 + col]

    assert own.columns[4] == "our design, ML route" and own.columns[2].startswith("paper design")
    assert dr(own, 2) == dr(mid, 2) and dr(own, 0) == dr(held, 0)
    assert dr(mid, 0) < 0.5 * dr(held, 0) and dr(mid, 2) < 0.5 * dr(held, 2)
