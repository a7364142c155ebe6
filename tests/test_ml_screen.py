"""The early screen of the ML search (a first fit not converged by ``SCREEN_ITER`` iterations is
re-initialised at once when its residual fails the test; the Levenberg-Marquardt iteration is
resumable), and the lengthened drive of ``tunnelkit reproduce javelin-table1 --length``."""

import numpy as np
import pytest

from tunnelkit import channel, evaluation, simulation
from tunnelkit.cli import main
from tunnelkit.extraction import ml
from tunnelkit.extraction.ml import fitting
from tunnelkit.reproduce import run
from tunnelkit.simulation.variants import drive_variant

SMALL = channel.SRSConfig(n_rb=20, comb=4, n_symbols=6)  # 60 tones x 6 symbols


def _scene(seed, n_paths=3, **kw):
    return evaluation.random_scene(np.random.default_rng(seed), n_paths, config=SMALL, **kw)


def _twice(seed, du, noise_seed=8):
    """A scene and a start with the second source counted twice (``du`` apart in u_x) and the
    third missing: the local fit crawls for many iterations."""
    sc = _scene(seed, n_paths=3, snr_db=(0.0, 5.0))
    H = sc.tensor(np.random.default_rng(noise_seed))
    r = np.linalg.norm(sc.sources, axis=1)
    th = np.column_stack([sc.sources[:, :2] / r[:, None], 1 / r])
    mf, mt = sc.mu_f.copy(), sc.mu_t.copy()
    th[2], mf[2], mt[2] = th[1] + [du, 0.0, 0.0], mf[1], mt[1]
    return sc, H, (th, mf, mt)


def _without_screen(fn):
    old = fitting.SCREEN_ITER
    try:
        fitting.SCREEN_ITER = 10**6
        return fn()
    finally:
        fitting.SCREEN_ITER = old


def test_lm_resumed_from_its_state_runs_the_iterations_of_one_call():
    """m iterations, then n more from the returned point and state: the same point, cost and
    iteration count as m + n iterations in one call (bit for bit)."""
    sc, H, (th, mf, mt) = _twice(71, 0.004)
    prob = ml.Problem(H, sc.element_positions, SMALL.fc)
    sigma2 = prob.noise_floor(3)
    one = fitting._lm(prob, th, mf, mt, sigma2, 60)
    n = one[4]
    # converged within the cap, late enough to split: how many iterations it takes depends on the
    # machine's BLAS (16 on one CPU, 30-60 on another), the identity below does not
    assert 4 <= n < 60 and one[5], n
    m = n // 2
    state: dict = {}
    a = fitting._lm(prob, th, mf, mt, sigma2, m, state)
    assert a[4] == m and not a[5]
    b = fitting._lm(prob, *a[:3], sigma2, 60 - m, state)
    for x, y in zip(b[:3], one[:3]):
        np.testing.assert_array_equal(x, y)
    assert b[3]["cost"] == one[3]["cost"] and a[4] + b[4] == one[4] and b[5]
    assert state["lam"] > 0 and state["ev"]["cost"] == b[3]["cost"]


def test_the_screen_leaves_a_fit_that_passes_as_it_was():
    """A first fit still iterating at the screen whose residual passes the test goes on to its
    end exactly as without the screen (bit for bit)."""
    sc, H, start = _twice(5, 0.02)
    pos = sc.element_positions
    screened = ml.fit_ml(H, start, pos, SMALL)
    plain = _without_screen(lambda: ml.fit_ml(H, start, pos, SMALL))
    assert screened.n_iter > fitting.SCREEN_ITER and screened.n_reseed == 0
    np.testing.assert_array_equal(screened.theta, plain.theta)
    assert screened.cost == plain.cost and screened.n_iter == plain.n_iter and screened.fit_ok


def test_the_screen_reinitialises_a_crawling_wrong_basin_early():
    """One source counted twice and another missing, a first fit that has not converged in 60
    iterations: with the screen it stops at SCREEN_ITER, its residual fails the test and the
    re-initialisation finds the missing source, in fewer iterations than without the screen;
    the same verdict and errors within the bound."""
    sc, H, start = _twice(11, 0.02)
    pos = sc.element_positions
    prob = ml.Problem(H, pos, SMALL.fc)
    assert not fitting._lm(prob, *start, prob.noise_floor(3), 60)[5]  # crawling
    fit = ml.fit_ml(H, start, pos, SMALL)
    plain = _without_screen(lambda: ml.fit_ml(H, start, pos, SMALL))
    assert fit.fit_ok and plain.fit_ok and fit.n_iter < plain.n_iter
    assert fit.cost <= plain.cost + fit.noise_power
    for f in (fit, plain):
        est = ml.estimates_from_fit(f, pos, SMALL, SMALL.n_tones, SMALL.n_symbols, 0.0)
        err = evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, sc.crlb())
        assert np.all(np.abs(err) < 5.0), err


def test_drive_variant_lengthens_the_straight_drive_and_checks_its_arguments():
    route = drive_variant("italiano2026-straight", 120.0)
    pos = route.trajectory.position
    preset = simulation.scenario_route("italiano2026-straight").trajectory.position
    assert pos[0, 0] == pytest.approx(preset[-1, 0] + 120.0, abs=1.5)
    assert pos[-1, 0] == pytest.approx(preset[-1, 0], abs=1.5)
    np.testing.assert_allclose(pos[:, 1:], preset[:1, 1:].repeat(len(pos), 0))  # same lane
    step = np.diff(pos[:, 0])
    np.testing.assert_allclose(step, np.diff(preset[:, 0])[0], rtol=1e-9)  # same speed x period
    assert drive_variant("italiano2026-straight", 120) is route  # kept
    with pytest.raises(ValueError, match="length"):
        drive_variant("italiano2026-straight", 500.0)
    with pytest.raises(ValueError, match="length"):
        drive_variant("italiano2026-straight", -1.0)
    with pytest.raises(TypeError, match="scenario"):
        drive_variant(route, 120.0)


def test_length_is_refused_where_it_does_not_apply(capsys):
    with pytest.raises(ValueError, match="length"):
        run("jiang-crlb", runs=10, length=120.0)
    with pytest.raises(ValueError, match="length"):
        run("javelin-table1", runs=1, length=120.0, channel="sionna")
    assert main(["reproduce", "javelin-table2", "--runs", "1", "--length", "120"]) == 2
    assert "--length" in capsys.readouterr().err
