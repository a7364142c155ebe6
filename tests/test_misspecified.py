"""The misspecified bound (tunnelkit.studies.misspecified) against brute force: the pseudo-true
point against an independent least-squares refit, ``A`` against the finite-difference Hessian of
the cost, the sandwich against Monte-Carlo of the extraction's fit, and the CRLB when the model
holds."""

import warnings

import numpy as np
import pytest
from scipy.optimize import least_squares

from tunnelkit.constants import C
from tunnelkit.extraction.bounds import crlb_paths
from tunnelkit.extraction.ml import Problem, fit_problem
from tunnelkit.studies.misspecified import (
    misspecified_bound,
    parameter_vector,
    pseudo_true,
)

FC = 5.9e9
NF, NT = 24, 4
SIGMA2 = 0.05
THETA = np.array([[0.2, -0.1, 0.2], [-0.3, 0.25, 0.1]])
MU_F = np.array([-0.5, -0.9])
MU_T = np.array([0.1, -0.2])
GAIN = np.array([1 + 0.5j, 0.6 - 0.3j])


def _pos():
    g = np.arange(4) * C / FC / 2
    return np.array([[x, y, 0.0] for x in g for y in g])


def _tensors(eps):
    """The eq. 1 tensor of two paths plus ``eps`` times a known perturbation: the second
    derivative in ``mu_f`` of path 0's atom (a delay-curvature term, which eq. 1 cannot absorb
    and which bends the likelihood along ``mu_f`` most)."""
    prob = Problem(np.ones((16, NF, NT), complex), _pos(), FC)
    h = prob.model(THETA, MU_F, MU_T, GAIN)
    s = np.arange(NF)[None, :, None]
    return h, h - eps * s**2 * prob.model(THETA[:1], MU_F[:1], MU_T[:1], GAIN[:1])


def _cost(H, p):
    q = p.reshape(-1, 7)
    r = H - Problem(H, _pos(), FC).model(q[:, 2:5], q[:, 5], q[:, 6], q[:, 0] + 1j * q[:, 1])
    return r.ravel()


@pytest.fixture(scope="module")
def perturbed():
    _, H = _tensors(2e-3)
    pt = pseudo_true(H, _pos(), FC, (THETA, MU_F, MU_T), noise_power=SIGMA2)
    b = misspecified_bound(H, _pos(), FC, pt["theta"], pt["mu_f"], pt["mu_t"], pt["c"], SIGMA2)
    return H, pt, b


def test_pseudo_true_is_the_least_squares_refit(perturbed):
    """phi_0 from the extraction's own fit = scipy's least squares on all 7L real parameters,
    started at the truth; the bias is far from zero (the perturbation moves it)."""
    H, pt, _ = perturbed
    p_true = parameter_vector(THETA, MU_F, MU_T, GAIN).ravel()

    def res(p):
        r = _cost(H, p)
        return np.concatenate([r.real, r.imag])

    ref = least_squares(res, p_true, xtol=1e-14, ftol=1e-14, gtol=1e-14).x.reshape(-1, 7)
    got = parameter_vector(pt["theta"], pt["mu_f"], pt["mu_t"], pt["c"])
    bias = ref - p_true.reshape(-1, 7)
    assert np.abs(bias[:, 5]).max() > 1e-5  # the delay moves
    np.testing.assert_allclose(got, ref, atol=2e-3 * np.abs(bias).max())
    assert pt["residual_power"] > 0.05 * SIGMA2


def test_A_is_the_hessian_of_the_cost(perturbed):
    """A = Hessian of ||H - mu||^2 / sigma^2 at phi_0 (second differences), B its Gauss-Newton part."""
    H, pt, b = perturbed
    p0 = parameter_vector(pt["theta"], pt["mu_f"], pt["mu_t"], pt["c"]).ravel()
    n, h = p0.size, 1e-4

    def f(p):
        r = _cost(H, p)
        return float(np.vdot(r, r).real)

    E = np.eye(n) * h
    hess = np.array(
        [
            [
                (
                    f(p0 + E[i] + E[j])
                    - f(p0 + E[i] - E[j])
                    - f(p0 - E[i] + E[j])
                    + f(p0 - E[i] - E[j])
                )
                / (4 * h * h)
                for j in range(n)
            ]
            for i in range(n)
        ]
    )
    assert np.abs(hess / SIGMA2 - b["A"]).max() < 1e-4 * np.abs(b["A"]).max()
    assert not np.allclose(b["A"], b["B"], rtol=1e-3)  # the model error bends the likelihood
    assert b["definite"]
    # phi_0 is stationary: the score at phi_0 is far below its own standard deviation
    assert np.all(np.abs(b["gradient"]) < 1e-3 * np.sqrt(np.diag(b["B"])))


def test_no_model_error_gives_the_crlb():
    """delta = 0: phi_0 = phi, MCRB = CRLB, and the delay bound is crlb_paths' (the source
    parametrisation of extraction.bounds)."""
    H, _ = _tensors(0.0)
    pt = pseudo_true(H, _pos(), FC, (THETA, MU_F, MU_T), noise_power=SIGMA2)
    np.testing.assert_allclose(pt["theta"], THETA, atol=1e-9)
    np.testing.assert_allclose(pt["mu_f"], MU_F, atol=1e-9)
    b = misspecified_bound(H, _pos(), FC, pt["theta"], pt["mu_f"], pt["mu_t"], pt["c"], SIGMA2)
    np.testing.assert_allclose(b["mcrb"], b["crlb"], rtol=1e-8, atol=1e-14)
    uz = np.sqrt(1 - np.sum(THETA[:, :2] ** 2, axis=1))
    src = np.column_stack([THETA[:, :2], uz]) / THETA[:, 2:3]
    ref = crlb_paths(GAIN, src, _pos(), MU_F, MU_T, FC, NF, NT, SIGMA2)
    np.testing.assert_allclose(b["crlb_sd"][:, 5], ref["mu_f"], rtol=1e-6)
    np.testing.assert_allclose(b["crlb_sd"][:, 6], ref["mu_t"], rtol=1e-6)


def test_sandwich_against_monte_carlo(perturbed):
    """200 noisy refits about phi_0: their spread follows the MCRB (within the Monte-Carlo
    error), not the CRLB where the two differ (path 0's delay, 1.76x)."""
    H, pt, b = perturbed
    rng = np.random.default_rng(1)
    pos = _pos()
    est = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(200):
            n = np.sqrt(SIGMA2 / 2) * (
                rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape)
            )
            f = fit_problem(
                Problem(H + n, pos, FC),
                (pt["theta"], pt["mu_f"], pt["mu_t"]),
                noise_power=SIGMA2,
                n_reseed=0,
            )
            est.append(parameter_vector(f.theta, f.mu_f, f.mu_t, f.alpha))
    est = np.array(est)
    sd = est.std(axis=0)
    ratio = sd / b["mcrb_sd"]
    assert np.all((ratio > 0.82) & (ratio < 1.18)), ratio
    assert b["mcrb_sd"][0, 5] > 1.5 * b["crlb_sd"][0, 5]
    assert sd[0, 5] > 1.4 * b["crlb_sd"][0, 5]
    p0 = parameter_vector(pt["theta"], pt["mu_f"], pt["mu_t"], pt["c"])
    assert np.all(np.abs(est.mean(axis=0) - p0) < 0.3 * b["mcrb_sd"])


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"noise_power": -1.0}, "noise_power"),
        ({"noise_power": SIGMA2, "tolerance": 0.0}, "tolerance"),
    ],
)
def test_pseudo_true_bad_input(kw, name):
    H, _ = _tensors(0.0)
    with pytest.raises(ValueError, match=name):
        pseudo_true(H, _pos(), FC, (THETA, MU_F, MU_T), **kw)
    with pytest.raises(ValueError, match="start"):
        pseudo_true(H, _pos(), FC, "truth", noise_power=SIGMA2)


def test_bound_bad_input():
    H, _ = _tensors(0.0)
    with pytest.raises(ValueError, match="mu_f"):
        misspecified_bound(H, _pos(), FC, THETA, MU_F[:1], MU_T, GAIN, SIGMA2)
    with pytest.raises(ValueError, match="c"):
        misspecified_bound(H, _pos(), FC, THETA, MU_F, MU_T, GAIN * np.nan, SIGMA2)
    with pytest.raises(ValueError, match="noise_power"):
        misspecified_bound(H, _pos(), FC, THETA, MU_F, MU_T, GAIN, 0.0)


def test_model_error_test_allows_the_stated_share():
    """A residual of noise plus one unmodelled path carrying a share s0 of the received energy:
    the peak test needs about s0 (the path's energy over the received energy), the test passes
    at s0 (1 + 5 %) and fails at s0 / 2; pure noise passes at share 0 (false-alarm rate 1 %)."""
    from tunnelkit.signal_route.judging import model_error_test

    pos = _pos()
    rng = np.random.default_rng(3)
    shape = (16, NF, NT)
    noise = np.sqrt(SIGMA2 / 2) * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
    h, _ = _tensors(0.0)
    e_rx = float(np.vdot(h, h).real)
    y2 = e_rx + noise.size * SIGMA2
    plain = model_error_test(noise, 2, y2, pos, FC, SIGMA2, 0.0)
    assert plain["passed"] and plain["needed"] == 0.0
    prob = Problem(np.ones(shape, complex), pos, FC)
    # a far-field path on the FFT grid of the test (its periodogram sees all of its energy)
    extra = prob.model(
        np.array([[0.0, 0.0, 0.0]]), np.array([np.pi / 6]), np.array([0.0]), np.ones(1)
    )
    s0 = 0.02
    extra *= np.sqrt(s0 * e_rx / np.vdot(extra, extra).real)
    r = model_error_test(noise + extra, 2, y2, pos, FC, SIGMA2, 0.0)
    assert not r["passed"]
    assert abs(r["share_peak"] - s0) < 0.15 * s0
    assert model_error_test(noise + extra, 2, y2, pos, FC, SIGMA2, 1.05 * r["needed"])["passed"]
    assert not model_error_test(noise + extra, 2, y2, pos, FC, SIGMA2, 0.5 * s0)["passed"]
    for kw, name in (({"share": -0.1}, "share"), ({"n_paths": -1}, "n_paths")):
        args = {"n_paths": 2, "share": 0.0, **kw}
        with pytest.raises(ValueError, match=name):
            model_error_test(noise, args["n_paths"], y2, pos, FC, SIGMA2, args["share"])
    with pytest.raises(ValueError, match="residual"):
        model_error_test(noise.real, 2, y2, pos, FC, SIGMA2, 0.0)


def test_model_error_test_energy_threshold_rho_max():
    """``rho_max`` sets the energy test's threshold: the default is ``1 + z / sqrt(N)``, a looser
    one lowers the energy share by ``(rho_max' - rho_max) (N - 2.5 L) sigma^2 / E_rx`` and
    leaves the peak test alone; a non-positive or NaN ``rho_max`` is refused by name."""
    from tunnelkit.extraction.ml.fitting import RHO_Z
    from tunnelkit.signal_route.judging import model_error_test

    pos = _pos()
    rng = np.random.default_rng(4)
    shape = (16, NF, NT)
    noise = np.sqrt(SIGMA2 / 2) * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
    h, _ = _tensors(0.0)
    y2 = float(np.vdot(h, h).real) + noise.size * SIGMA2
    resid = 1.2 * noise  # 44 % above the noise's energy: flagged by the energy test
    N, L = noise.size, 2
    strict = 1.0 + RHO_Z / np.sqrt(N)
    base = model_error_test(resid, L, y2, pos, FC, SIGMA2, 0.0)
    same = model_error_test(resid, L, y2, pos, FC, SIGMA2, 0.0, rho_max=strict)
    assert base == same
    assert base["share_energy"] > 0 and not base["passed"]
    loose = model_error_test(resid, L, y2, pos, FC, SIGMA2, 0.0, rho_max=1.6)
    e_rx = y2 - N * SIGMA2
    drop = (1.6 - strict) * (N - 2.5 * L) * SIGMA2 / e_rx
    assert loose["share_energy"] == pytest.approx(base["share_energy"] - drop, rel=1e-9)
    assert loose["share_peak"] == base["share_peak"] and loose["rho"] == base["rho"]
    assert loose["passed"] and loose["needed"] == max(loose["share_peak"], 0.0)
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ValueError, match="rho_max"):
            model_error_test(resid, L, y2, pos, FC, SIGMA2, 0.0, rho_max=bad)
