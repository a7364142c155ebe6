"""The pair test of the ML stage (``ml.pair_test``, the GLRT of one path against two for each
close pair of a fit): its statistic against an independent fit of the merged model, its null
distribution (one path fitted as a close pair) against ``PAIR_LLR`` by Monte-Carlo, its power
on a resolvable pair, and where the verdict is reported (``MLFit.unresolved``,
``PathEstimates.unresolved``, ``fit_ok``)."""

import warnings
from dataclasses import replace

import numpy as np
import pytest

from tunnelkit import channel, evaluation, extraction
from tunnelkit.constants import C
from tunnelkit.extraction import ml
from tunnelkit.extraction.ml.lm import lm_fit

SMALL = channel.SRSConfig(n_rb=20, comb=4, n_symbols=6)  # 60 tones x 6 symbols


def _one_source(rng, snr_db=25.0):
    sc = evaluation.random_scene(rng, 1, config=SMALL, snr_db=(snr_db, snr_db))
    H = sc.tensor(rng) / np.sqrt(SMALL.noise_power)  # unit noise power
    prob = ml.Problem(H, sc.element_positions, SMALL.fc)
    r = np.linalg.norm(sc.sources, axis=1)
    th = np.column_stack([sc.sources[:, :2] / r[:, None], 1 / r])
    mf = -2 * np.pi * SMALL.tone_spacing * sc.d / C
    mt = 2 * np.pi * SMALL.fc * SMALL.symbol_period * sc.v / C
    return prob, th, mf, mt


def _close_pair_fit(prob, th, mf, mt):
    """The best two-path fit started from the path split in two (a path counted twice)."""
    best = None
    for du in ((0.02, 0.0), (0.0, 0.02), (0.05, 0.0)):
        t2 = np.vstack([th, th])
        t2[0, :2] += du
        t2[1, :2] -= du
        fit = lm_fit(prob, ml.project_feasible(t2), np.repeat(mf, 2), np.repeat(mt, 2), 1.0, 100)
        if best is None or fit[3]["cost"] < best[3]["cost"]:
            best = fit
    return best


def test_statistic_is_the_cost_drop_of_the_merged_model():
    """One source fitted as a close pair: ``llr`` equals the cost of the one-path fit started at
    the truth (an independent maximum of the merged model) less the pair's, in noise powers."""
    for seed in (1, 2):
        prob, th, mf, mt = _one_source(np.random.default_rng(seed))
        two = _close_pair_fit(prob, th, mf, mt)
        rows = ml.pair_test(prob, *two[:3], 1.0, z_max=np.inf)
        one = lm_fit(prob, th, mf, mt, 1.0, 200)
        assert rows.shape == (1, 4)
        assert rows[0, 3] == pytest.approx(one[3]["cost"] - two[3]["cost"], abs=1e-3)
        assert rows[0, 3] >= -1e-6
        z = ml.separations(prob, *two[:3], 1.0)[0]
        assert rows[0, 2] == pytest.approx(z, rel=1e-9)


def test_null_false_alarm_rate_by_monte_carlo():
    """One source (post-integration SNR 300) fitted as a close pair in 60 draws: the pair is
    declared resolved (llr >= PAIR_LLR) at most 4 times (at the stated 1 %, P(>= 5) = 0.3 %);
    and the null is not degenerate (its median above 1 noise power)."""
    rng = np.random.default_rng(5)
    llr = []
    for _ in range(60):
        prob, th, mf, mt = _one_source(rng)
        two = _close_pair_fit(prob, th, mf, mt)
        llr.append(ml.pair_test(prob, *two[:3], 1.0, z_max=np.inf)[0, 3])
    llr = np.array(llr)
    assert np.sum(llr >= ml.PAIR_LLR) <= 4, np.sort(llr)[-6:]
    assert np.median(llr) > 1.0


def test_resolvable_pair_is_resolved_and_far_pairs_not_tested():
    """Two sources a beamwidth apart at high SNR: the test declares them resolved; with the
    default ``z_max`` a pair further apart than PAIR_TEST_Z is not tested at all."""
    sc = evaluation.random_scene(np.random.default_rng(7), 2, config=SMALL, snr_db=(20.0, 20.0))
    H = sc.tensor(np.random.default_rng(8)) / np.sqrt(SMALL.noise_power)
    prob = ml.Problem(H, sc.element_positions, SMALL.fc)
    r = np.linalg.norm(sc.sources, axis=1)
    th = np.column_stack([sc.sources[:, :2] / r[:, None], 1 / r])
    mf = -2 * np.pi * SMALL.tone_spacing * sc.d / C
    mt = 2 * np.pi * SMALL.fc * SMALL.symbol_period * sc.v / C
    fit = lm_fit(prob, th, mf, mt, 1.0, 100)
    rows = ml.pair_test(prob, *fit[:3], 1.0, z_max=np.inf)
    assert rows.shape == (1, 4) and rows[0, 3] > ml.PAIR_LLR
    z = ml.separations(prob, *fit[:3], 1.0)[0]
    assert (ml.pair_test(prob, *fit[:3], 1.0).shape[0] == 1) == (z < ml.PAIR_TEST_Z)
    far = rows.copy()
    far[0, 2] = ml.RESOLVE_Z
    np.testing.assert_array_equal(ml.resolution.unresolved_partners(far, 2), [-1, -1])
    low = far.copy()
    low[0, 3] = ml.PAIR_LLR - 1e-9
    np.testing.assert_array_equal(ml.resolution.unresolved_partners(low, 2), [1, 0])
    close = far.copy()
    close[0, 2] = ml.RESOLVE_Z * (1 - 1e-9)  # two paths, closer than the bound can tell
    np.testing.assert_array_equal(ml.resolution.unresolved_partners(close, 2), [1, 0])


def test_unresolved_partners_takes_the_least_resolved():
    rows = np.array([[0, 1, 9.0, 3.0], [1, 2, 9.0, 1.0], [0, 3, 9.0, 50.0], [3, 4, 2.0, 99.0]])
    np.testing.assert_array_equal(ml.resolution.unresolved_partners(rows, 6), [1, 2, 1, 4, 3, -1])


def test_verdict_reported_on_the_fit_and_the_estimates():
    """extract_paths: ``PathEstimates.unresolved`` is ``MLFit.unresolved`` in the sorted order
    (partners matched through ``mu_f``), and a reported pair fails ``fit_ok`` with its reason."""
    sc = evaluation.random_scene(np.random.default_rng(3), 4, config=SMALL, snr_db=(5.0, 10.0))
    src = sc.sources.copy()
    src[1] = src[0] * 1.01 + 0.01  # the second source on top of the first: one path's worth
    d = sc.d.copy()
    d[1] = d[0] + 0.05
    sc = replace(sc, sources=src, d=d)
    H = sc.tensor(np.random.default_rng(4))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(H, 4, sc.element_positions, sc.config)
    fit = est.fit
    assert fit.unresolved.shape == (4,) and est.unresolved.shape == (4,)
    o = [int(np.argmin(np.abs(fit.mu_f - m))) for m in est.mu_f]  # est row -> fit row
    for k, p in enumerate(est.unresolved):
        q = fit.unresolved[o[k]]
        assert (p < 0) == (q < 0)
        if p >= 0:
            assert o[p] == q
    llr, z = fit.pairs[:, 3], fit.pairs[:, 2]
    assert ("pair not resolved" in fit.reason) == bool(np.any(llr < ml.PAIR_LLR))
    assert bool(np.any(fit.unresolved >= 0)) == bool(
        np.any((llr < ml.PAIR_LLR) | (z < ml.RESOLVE_Z))
    )
    if np.any(fit.unresolved >= 0):
        assert not est.fit_ok
    with pytest.raises(ValueError, match="unresolved"):
        replace(est, unresolved=np.arange(4))  # a path its own partner


def test_pair_test_checks_its_arguments():
    prob, th, mf, mt = _one_source(np.random.default_rng(1))
    two = _close_pair_fit(prob, th, mf, mt)
    for kw, name in (({"z_max": 0.0}, "z_max"), ({"z_max": np.nan}, "z_max"),
                     ({"max_iter": 0}, "max_iter"), ({"max_iter": 10**7}, "max_iter")):  # fmt: skip
        with pytest.raises((TypeError, ValueError), match=name):
            ml.pair_test(prob, *two[:3], 1.0, **kw)
    with pytest.raises(ValueError, match="noise_power"):
        ml.pair_test(prob, *two[:3], -1.0)
    with pytest.raises(ValueError, match="mu_f"):
        ml.pair_test(prob, two[0], two[1][:1], two[2], 1.0)
    assert ml.pair_test(prob, th, mf, mt, 1.0).shape == (0, 4)  # one path: no pair


def test_lm_fit_checks_its_arguments():
    prob, th, mf, mt = _one_source(np.random.default_rng(1))
    for args, kw, name in (
        (("x", th, mf, mt, 1.0, 5), {}, "prob"),
        ((prob, "x", mf, mt, 1.0, 5), {}, "theta"),
        ((prob, th, mf[:0], mt, 1.0, 5), {}, "mu_f"),
        ((prob, th, mf, mt, np.nan, 5), {}, "sigma2"),
        ((prob, th, mf, mt, -1.0, 5), {}, "sigma2"),
        ((prob, th, mf, mt, 1.0, -1), {}, "max_iter"),
        ((prob, th, mf, mt, 1.0, 10**7), {}, "max_iter"),
        ((prob, th, mf, mt, 1.0, 5), {"state": 3}, "state"),
    ):
        with pytest.raises((TypeError, ValueError), match=name):
            lm_fit(*args, **kw)
