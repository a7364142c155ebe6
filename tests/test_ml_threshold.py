"""The threshold in SNR of the ML stage (method of interval errors, ``ml.resolution``): the outlier
probability against brute force, the threshold SNR, the per-path verdict and where it is reported
(``PathEstimates.below_threshold``)."""

import warnings

import numpy as np
import pytest

from tunnelkit import channel, evaluation, extraction
from tunnelkit.extraction import ml

SMALL = channel.SRSConfig(n_rb=20, comb=4, n_symbols=6)  # 60 tones x 6 symbols


def _brute_outlier(rng, snr, n_cells, n=200_000):
    """The largest of ``n_cells - 1`` unit exponentials (drawn by its inverse CDF) against the
    path cell ``|sqrt(snr) + n_0|^2``."""
    K = n_cells - 1
    mx = -np.log(-np.expm1(np.log(rng.random(n)) / K))
    z = (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / np.sqrt(2)
    return np.mean(mx > np.abs(np.sqrt(snr) + z) ** 2)


@pytest.mark.parametrize(("n_cells", "snr"), [(300, 8.0), (300, 13.0), (492_000, 28.5), (2, 3.0)])
def test_outlier_probability_against_brute_force_and_under_the_union_bound(n_cells, snr):
    rng = np.random.default_rng(11)
    p = float(ml.outlier_probability(snr, n_cells))
    mc = _brute_outlier(rng, snr, n_cells)
    tol = 4 * np.sqrt(p * (1 - p) / 200_000) + 1e-4
    assert abs(mc - p) < tol, (mc, p)
    assert p <= 0.5 * (n_cells - 1) * np.exp(-snr / 2) + 1e-12  # the union bound
    if n_cells == 2:  # one wrong cell: exactly the non-coherent pairwise error e^{-snr/2} / 2
        assert p == pytest.approx(0.5 * np.exp(-snr / 2), rel=1e-6)


def test_snr_threshold_is_the_root_and_falls_with_the_outlier_rate():
    N = 100 * 410 * 12  # the paper's tensor
    g = ml.snr_threshold(N)
    assert float(ml.outlier_probability(g, N)) == pytest.approx(ml.OUTLIER_RATE, rel=1e-4)
    assert 28.0 < g < 2 * np.log(0.5 * (N - 1) / ml.OUTLIER_RATE)  # below the union bound's root
    assert ml.snr_threshold(N, 0.1) < g < ml.snr_threshold(N, 0.001)
    assert ml.snr_threshold(10 * N) > g
    assert ml.snr_threshold(1) == 0.0
    p = ml.outlier_probability([0.0, g, 60.0], N)
    assert p.shape == (3,) and p[2] < 1e-5
    assert p[0] == pytest.approx(1 - 1 / N, rel=1e-9)  # zero SNR: a draw of N exponentials
    for bad, name in ((0, "n_cells"), (2.5, "n_cells")):
        with pytest.raises((TypeError, ValueError), match=name):
            ml.snr_threshold(bad)
    for bad in (0.0, 1.0, np.nan):
        with pytest.raises(ValueError, match="outlier"):
            ml.snr_threshold(N, bad)
    with pytest.raises(ValueError, match="snr"):
        ml.outlier_probability([-1.0], N)
    with pytest.raises(ValueError, match="snr"):
        ml.outlier_probability([np.nan], N)


def test_below_threshold_per_path():
    N = 1000
    g = ml.snr_threshold(N)
    sig = np.array([g * 0.9, g * 1.1, 1e6, 1e6])
    res = np.array([np.inf, np.inf, ml.RESOLVE_Z * 0.99, ml.RESOLVE_Z])
    np.testing.assert_array_equal(ml.below_threshold(sig, res, N), [True, False, True, False])
    with pytest.raises(ValueError, match="resolution"):
        ml.below_threshold(sig, res[:3], N)
    with pytest.raises(ValueError, match="n_cells"):
        ml.snr_threshold(10**12)
    with pytest.raises(ValueError, match="resolution"):
        ml.below_threshold(sig, np.array([np.nan, 1, 1, 1.0]), N)
    with pytest.raises(ValueError, match="significance"):
        ml.below_threshold(np.array([np.nan, 1, 1, 1.0]), res, N)


def test_path_estimates_say_which_path_is_below_the_threshold():
    """A scene of strong sources: no path below; the same scene with one source scaled down to
    half the threshold SNR: that path (and only it) below, at the estimate."""
    sc = evaluation.random_scene(np.random.default_rng(3), 3, config=SMALL, snr_db=(15.0, 20.0))
    H = sc.tensor(np.random.default_rng(4))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(H, 3, sc.element_positions, sc.config)
    N = H.size
    assert est.below_threshold.dtype == bool and est.below_threshold.shape == (3,)
    np.testing.assert_array_equal(
        est.below_threshold, ml.below_threshold(est.significance, est.resolution, N)
    )
    assert not est.below_threshold.any()
    paper = extraction.extract_paths(H, 3, sc.element_positions, sc.config, refine="joint")
    assert paper.below_threshold is None
