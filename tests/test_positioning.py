import numpy as np
import pytest

from tunnelkit import crlb, positioning

LEVELS = [(0.5, 0.1), (1.0, 1.0), (2.0, 2.0)]


def _rmse_ratio(jiang, deg, sd, runs, seed, solver="tswls"):
    vs, p = jiang["vs"], jiang["start"]
    sth = np.radians(deg)
    d_hat, th_hat = positioning.simulate_toa_doa(
        p, vs, sth, sd, np.random.default_rng(seed), size=runs
    )
    if solver == "tswls":
        est = positioning.tswls(vs, d_hat, th_hat, sd, sth)
    else:
        est = positioning.ls_toa_doa(vs, d_hat, th_hat)
    rmse = np.sqrt(np.mean(np.sum((est - p) ** 2, -1)))
    return rmse / float(crlb.crlb_rmse(p, vs, sth, sd))


def test_tswls_is_efficient_at_jiang_low_noise(jiang):
    """2,000 seeded trials at (0.5 deg, 0.1 m): RMSE / sqrt(CRLB) in [0.95, 1.10]."""
    ratio = _rmse_ratio(jiang, 0.5, 0.1, 2000, seed=2023)
    assert 0.95 <= ratio <= 1.10, ratio


@pytest.mark.parametrize(("deg", "sd"), LEVELS[1:])
def test_tswls_near_bound_at_higher_noise(jiang, deg, sd):
    assert 0.93 <= _rmse_ratio(jiang, deg, sd, 2000, seed=7) <= 1.12


def test_ls_is_not_efficient(jiang):
    assert _rmse_ratio(jiang, 0.5, 0.1, 2000, seed=5, solver="ls") > 1.5


def test_noise_free_solutions_are_exact(jiang):
    vs, p = jiang["vs"], jiang["start"]
    d, th = crlb.toa_doa(p, vs)
    np.testing.assert_allclose(positioning.ls_toa_doa(vs, d, th), p, atol=1e-9)
    np.testing.assert_allclose(positioning.tswls(vs, d, th, 0.1, 0.01), p, atol=1e-9)


def test_tswls_never_nan_near_zero_coordinate(jiang):
    # a vehicle on the y axis makes x_hat ~ 0 and W1 singular: stage 1 must be kept, no NaN
    vs = jiang["vs"]
    p = np.array([0.0, 5.0])
    d_hat, th_hat = positioning.simulate_toa_doa(
        p, vs, 0.01, 0.1, np.random.default_rng(0), size=500
    )
    est = positioning.tswls(vs, d_hat, th_hat, 0.1, 0.01)
    assert np.all(np.isfinite(est))
    assert np.sqrt(np.mean(np.sum((est - p) ** 2, -1))) < 1.0


def test_simulation_is_reproducible(jiang):
    a = positioning.simulate_toa_doa(
        jiang["start"], jiang["vs"], 0.01, 0.1, np.random.default_rng(9), size=3
    )
    b = positioning.simulate_toa_doa(
        jiang["start"], jiang["vs"], 0.01, 0.1, np.random.default_rng(9), size=3
    )
    np.testing.assert_array_equal(a[0], b[0])
    with pytest.raises(TypeError, match=r"rng: expected a numpy\.random\.Generator"):
        positioning.simulate_toa_doa(jiang["start"], jiang["vs"], 0.01, 0.1, 42)


def test_toa_only_candidates_are_mirror_images(jiang):
    vs, p = jiang["vs"], jiang["start"]
    d, _ = crlb.toa_doa(p, vs)
    c = positioning.toa_only_candidates(vs, d)
    assert min(np.linalg.norm(c - p, axis=-1)) < 1e-9
    # the other candidate is p mirrored in the station line y = -x
    other = c[np.argmax(np.linalg.norm(c - p, axis=-1))]
    np.testing.assert_allclose(other, [-p[1], -p[0]], atol=1e-9)
    with pytest.raises(ValueError, match="d_hat: the range circles do not intersect"):
        positioning.toa_only_candidates(vs, [1.0, 1.0])


@pytest.mark.parametrize(
    ("d_hat", "theta_hat", "match"),
    [
        ([np.nan, 10.0], [0.1, 0.2], "d_hat: contains NaN"),
        ([10.0, 10.0], [np.inf, 0.2], "theta_hat: contains NaN or infinite"),
        ([10.0, 10.0, 3.0], [0.1, 0.2, 0.3], "d_hat: expected one range per station"),
        ([10.0, -1.0], [0.1, 0.2], "d_hat: ranges must be > 0"),
        ([10.0, 10.0], [0.1], "theta_hat: shape"),
    ],
)
def test_bad_measurements(jiang, d_hat, theta_hat, match):
    with pytest.raises(ValueError, match=match):
        positioning.tswls(jiang["vs"], d_hat, theta_hat, 0.1, 0.01)


def test_tswls_needs_both_sigmas(jiang):
    with pytest.raises(ValueError, match="sigma_d: must be > 0"):
        positioning.tswls(jiang["vs"], [20.0, 10.0], [0.1, 0.2], 0.0, 0.01)
    with pytest.raises(ValueError, match="TSWLS needs both"):
        positioning.tswls(jiang["vs"], [20.0, 10.0], [0.1, 0.2], 0.1, None)
