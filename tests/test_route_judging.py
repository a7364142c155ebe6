"""A fit judged against noise plus the impairment power (tunnelkit.signal_route.judging): the
closed-form calibration share against brute-force draws, the re-judged fit on a tensor with
calibration error, the budget's slots matched by direction and delay (not by kind)."""

from dataclasses import replace

import numpy as np
import pytest

from tunnelkit.calibration import draw_calibration
from tunnelkit.channel import DiffuseSpec, Impairments
from tunnelkit.constants import C
from tunnelkit.extraction import PathEstimates
from tunnelkit.extraction.ml import Problem, fit_problem
from tunnelkit.extraction.numerics import spatial_phase
from tunnelkit.signal_route.judging import (
    BiasBudget,
    apply_budget,
    calibration_floor,
    calibration_share,
    impairment_share,
    rejudge,
)
from tunnelkit.tracking.javelin.measurement import PathMeasurements

FC = 5.9e9


@pytest.mark.parametrize("phase_deg, gain_db", [(0.5, 0.0), (2.0, 0.2), (10.0, 1.0), (0.0, 3.0)])
def test_calibration_share_against_draws(phase_deg, gain_db):
    """``1 - exp(-sigma_phi^2 - s^2)`` is ``1 - |E g|^2 / E |g|^2`` of the drawn gains (200 000
    elements), and the share a fitted common gain leaves (``1 - |sum g|^2 / (M sum |g|^2)`` of
    one M-element array, averaged over arrays) is below it: the closed form is an upper bound."""
    rng = np.random.default_rng(7)
    g = draw_calibration(rng, 200_000, phase_deg, gain_db)
    brute = 1.0 - abs(g.mean()) ** 2 / np.mean(abs(g) ** 2)
    share = calibration_share(phase_deg, gain_db)
    assert share == pytest.approx(brute, rel=0.03, abs=1e-6)
    arrays = g.reshape(-1, 16)
    left = 1.0 - abs(arrays.sum(1)) ** 2 / (16 * np.sum(abs(arrays) ** 2, 1))
    assert left.mean() <= share
    assert left.mean() == pytest.approx(share * 15 / 16, rel=0.05)


def test_impairment_share_adds_the_diffuse_share_and_checks_its_input():
    imp = Impairments(phase_sigma_deg=2.0, dmc=DiffuseSpec(0.1))
    assert impairment_share(imp) == pytest.approx(calibration_share(2.0, 0.0) + 0.1)
    assert impairment_share(Impairments()) == 0.0
    for kw, name in (
        ({"phase_sigma_deg": -1}, "phase_sigma_deg"),
        ({"gain_sigma_db": np.nan}, "gain_sigma_db"),
    ):
        args = {"phase_sigma_deg": 0.0, "gain_sigma_db": 0.0, **kw}
        with pytest.raises(ValueError, match=name):
            calibration_share(**args)
    with pytest.raises(TypeError, match="impairments"):
        impairment_share(0.5)


class _Est:
    """The parts of PathEstimates :func:`rejudge` reads (fit, eq. 1 factors, gains)."""

    def __init__(self, prob, fit):
        self.fit = fit
        self.alpha = fit.alpha
        a = np.exp(1j * spatial_phase(fit.theta, prob.pos, prob.k0)[0])
        self.factors = (
            a,
            np.exp(1j * prob.s * fit.mu_f[None, :]),
            np.exp(1j * prob.kk * fit.mu_t[None, :]),
        )

    def __len__(self):
        return len(self.alpha)

    model_tensor = PathEstimates.model_tensor


def _pos():
    g = np.arange(4) * C / FC / 2
    return np.array([[x, y, 0.0] for x in g for y in g])


def test_rejudge_passes_a_calibration_error_fit_at_the_closed_form_share():
    """Two paths seen through 6 deg of phase error at high SNR: the white-noise test flags the
    fit (its residual carries the calibration error), the test with the closed-form share
    passes it, with no floor it fails, and the share it needs is below the closed form."""
    theta = np.array([[0.2, -0.1, 0.2], [-0.3, 0.25, 0.1]])
    mu_f, mu_t = np.array([-0.5, -0.9]), np.array([0.1, -0.2])
    gain = np.array([1 + 0.5j, 0.6 - 0.3j])
    pos, sigma2 = _pos(), 1e-3
    rng = np.random.default_rng(11)
    prob0 = Problem(np.ones((16, 24, 4), complex), pos, FC)
    h = prob0.model(theta, mu_f, mu_t, gain) * draw_calibration(rng, 16, 6.0)[:, None, None]
    noise = np.sqrt(sigma2 / 2) * (rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape))
    prob = Problem(h + noise, pos, FC)
    with pytest.warns(RuntimeWarning):
        fit = fit_problem(prob, (theta, mu_f, mu_t), noise_power=sigma2, n_reseed=0)
    assert not fit.fit_ok
    est = _Est(prob, fit)
    share = calibration_share(6.0, 0.0)
    r = rejudge(est, prob.H, pos, FC, share)
    assert r["residual_only"] and r["passed"] and 0 < r["needed"] <= share
    assert not rejudge(est, prob.H, pos, FC, 0.0)["passed"]
    # the energy test at the fit's own threshold, not at the stricter default 1 + z / sqrt(N)
    resid = prob.H - np.einsum("ml,sl,kl,l->msk", *est.factors, est.alpha)
    N, L, n0 = prob.H.size, len(est), fit.noise_power
    e_rx = float(np.vdot(prob.H, prob.H).real) - N * n0
    want = (float(np.vdot(resid, resid).real) - fit.rho_max * (N - 2.5 * L) * n0) / e_rx
    assert r["share_energy"] == pytest.approx(want, rel=1e-9, abs=1e-15)
    with pytest.raises(ValueError, match="share"):
        rejudge(est, prob.H, pos, FC, -0.1)
    with pytest.raises(ValueError, match="H"):
        rejudge(est, prob.H[:8], pos, FC, share)


@pytest.mark.parametrize(
    "phase_deg, gain_db", [(2.0, 0.0), (1.0, 0.3), (0.0, 0.5), (20.0, 2.0), (45.0, 0.0)]
)
def test_calibration_floor_is_the_draws_quantile(phase_deg, gain_db):
    """The floor is the 99 % quantile over drawn arrays of the scatter one array leaves
    (within 3 %; gain errors of 3 dB and more have a heavier tail, module docstring),
    ``sum_m w_m |g_m / E g - 1|^2 |E g|^2 / E|g|^2`` with the received power's weights ``w_m``
    (20 000 arrays of 64 elements, equal and unequal weights, a spread like an array in a tunnel
    and wider): within 3 %; the closed
    form (the expectation) sits below it, and a draw above the expectation is common."""
    rng = np.random.default_rng(21)
    m, k = 64, 20_000
    g = draw_calibration(rng, m * k, phase_deg, gain_db).reshape(k, m)
    s = gain_db * np.log(10) / 20
    eg = np.exp(-(np.radians(phase_deg) ** 2) / 2 + s * s / 2)
    e2 = np.exp(2 * s * s)
    scatter = np.abs(g - eg) ** 2 / e2
    share = calibration_share(phase_deg, gain_db)
    for w in (np.ones(m), np.exp(1.0 * rng.standard_normal(m))):
        w = w / w.sum()
        real = scatter @ w
        assert real.mean() == pytest.approx(share, rel=0.02)
        q = np.quantile(real, 0.99)
        floor = calibration_floor(phase_deg, gain_db, w)
        assert floor == pytest.approx(q, rel=0.03)
        assert floor > share and np.mean(real > share) > 0.3
    assert calibration_floor(0.0, 0.0, np.ones(4)) == 0.0
    # the exact cumulants: the mean is the closed form, also far outside the small-angle range
    from tunnelkit.signal_route.judging import _element_cumulants

    for lv in ((60.0, 0.0), (0.0, 6.0), (20.0, 2.0), (0.5, 0.2)):
        assert _element_cumulants(*lv)[0] == pytest.approx(calibration_share(*lv), rel=1e-12)
    for args, name in (
        ((1.0, 0.0, np.zeros(4)), "element_power"),
        ((1.0, 0.0, [1.0, -1.0]), "element_power"),
        ((1.0, 0.0, np.ones(4), 0.7), "false_alarm"),
        ((-1.0, 0.0, np.ones(4)), "phase_sigma_deg"),
    ):
        with pytest.raises(ValueError, match=f"^{name}"):
            calibration_floor(*args)


def test_rejudge_passes_a_large_array_fit_whose_draw_leaves_more_than_the_expectation():
    """256 elements, two paths, 2 deg of phase error, an array whose power-weighted scatter is
    10-15 % above the closed form (the first such draw of the seed, as run 9 below): the fit absorbs little of it,
    so the test with the closed form (the expectation) flags the fit, the calibration floor at
    1 % false alarm passes it. Before the floor, 36 of 40 epochs of such a drive (28 GHz, 16 x
    16, run 9 of seed 0) were flagged and the tracker dead-reckoned."""
    g1 = np.arange(16) * C / FC / 2
    pos = np.array([[x, y, 0.0] for x in g1 for y in g1])
    theta = np.array([[0.2, -0.1, 0.05], [-0.3, 0.25, 0.04]])
    mu_f, mu_t = np.array([-0.5, -0.9]), np.array([0.1, -0.2])
    gain = np.array([1 + 0.5j, 0.6 - 0.3j])
    prob0 = Problem(np.ones((256, 24, 4), complex), pos, FC)
    clean = prob0.model(theta, mu_f, mu_t, gain)
    w = np.sum(np.abs(clean) ** 2, axis=(1, 2))
    w = w / w.sum()
    share = calibration_share(2.0, 0.0)
    rng = np.random.default_rng(5)
    for _ in range(200):
        cal = draw_calibration(rng, 256, 2.0)
        eg = np.exp(-(np.radians(2.0) ** 2) / 2)
        if 1.1 * share < w @ np.abs(cal - eg) ** 2 < 1.15 * share:
            break
    else:  # pragma: no cover - the seed's draws are fixed
        raise AssertionError("no draw 10-15 % above the expectation in 200")
    sigma2 = 1e-4
    h = clean * cal[:, None, None]
    noise = np.sqrt(sigma2 / 2) * (rng.standard_normal(h.shape) + 1j * rng.standard_normal(h.shape))
    prob = Problem(h + noise, pos, FC)
    with pytest.warns(RuntimeWarning):
        fit = fit_problem(prob, (theta, mu_f, mu_t), noise_power=sigma2, n_reseed=0)
    est = _Est(prob, fit)
    expected = rejudge(est, prob.H, pos, FC, share)
    assert expected["residual_only"] and not expected["passed"] and expected["needed"] > share
    r = rejudge(est, prob.H, pos, FC, 0.0, calibration=(2.0, 0.0))
    assert r["passed"] and r["calibration_floor"] > r["needed"] > share
    assert r["share"] == r["calibration_floor"]
    assert rejudge(est, prob.H, pos, FC, 0.0, calibration=np.array([2.0, 0.0])) == r
    with pytest.raises(TypeError, match=r"^calibration"):
        rejudge(est, prob.H, pos, FC, 0.0, calibration=2.0)
    with pytest.raises(ValueError, match=r"^calibration"):
        rejudge(est, prob.H, pos, FC, 0.0, calibration=(2.0, 0.0, 1.0))


def _budget():
    """Two epochs, four slots: the LoS and two walls mirrored about the array's axis (same
    kind, same delay), the road; epoch 1 without the second wall."""
    origin = np.array([[0.0, 0.0, 6.0]] * 2)
    ue = np.array([30.0, 0.0, 1.5])
    wall = np.array([0.0, 8.0, 0.0])
    src = np.array([ue, ue + wall, ue - wall, ue * np.array([1.0, 1.0, -1.0])])
    source = np.stack([src, src])
    exists = np.array([[True] * 4, [True, True, False, True]])
    extra = np.zeros((2, 4, 4, 4))
    rep = np.zeros((2, 4, 4, 4))
    for p in range(4):
        extra[:, p] = np.diag([1e-6, 2e-6, 1e-2, 1e-4]) * (p + 1)
        rep[:, p] = 0.5 * extra[:, p]
    return BiasBudget(source, exists, origin, extra, rep), src, origin[0]


def test_budget_slots_matched_by_direction_and_delay_with_an_unknown_clock_offset():
    b, src, origin = _budget()
    rel = src - origin
    r = np.linalg.norm(rel, axis=1)
    order = np.array([2, 0, 3, 1])  # any order; both walls have the same delay
    u = rel[order] / r[order, None]
    d = r[order] + 12.3  # the clock offset
    assert b.match(0, d, u).tolist() == order.tolist()
    # the second wall's slot absent at epoch 1: its estimate stays unmatched
    assert b.match(1, d, u).tolist() == [-1, 0, 3, 1]
    # an estimate far from every slot (clutter) is unmatched
    far = np.vstack([u, [[0.0, 0.0, 1.0]]])
    assert b.match(0, np.append(d, 90.0), far)[-1] == -1
    with pytest.raises(ValueError, match="k"):
        b.match(2, d, u)
    with pytest.raises(ValueError, match="direction"):
        b.match(0, d, u[:2])


def test_apply_budget_adds_the_matched_slots_budget_and_the_tracker_takes_it():
    b, src, origin = _budget()
    rel = src[[1, 0]] - origin
    r = np.linalg.norm(rel, axis=1)
    u = rel / r[:, None]
    phi, psi = np.arctan2(u[:, 1], u[:, 0]), np.arctan2(u[:, 2], np.hypot(u[:, 0], u[:, 1]))
    d = r + 3.0
    cov = np.stack([np.eye(3) * 1e-8] * 2)
    m = PathMeasurements(phi, psi, r, d, np.zeros(2), np.arange(2), cov, np.full(2, 1e-3),
                         origin=origin)  # fmt: skip
    out = apply_budget(m, b, 0)
    assert np.allclose(out.cov[0], cov[0] + b.extra[0, 1, :3, :3])
    assert np.allclose(out.cov[1], cov[1] + b.extra[0, 0, :3, :3])
    assert np.allclose(out.sigma_d**2, 1e-6 + b.extra[0, [1, 0], 3, 3])
    assert np.allclose(out.bias_cov, b.repeating[0, [1, 0]])
    assert out.bias_cov.shape == (2, 4, 4)  # checked against cov by the container itself
    np.testing.assert_array_equal(out.origin, origin)
    # without reported covariances there is nothing to add to
    assert apply_budget(replace(m, cov=None, sigma_d=None), b, 0).cov is None


def test_model_tensor_is_eq1_of_the_factors_and_gains():
    """``PathEstimates.model_tensor`` against the einsum over a random estimate's factors and
    gains; factors without one column per path are refused naming ``factors``."""
    rng = np.random.default_rng(5)
    L, M, Nf, Nt = 3, 6, 7, 4

    def cplx(*shape):
        return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)

    u = rng.standard_normal((L, 3))
    u[:, 2] = np.abs(u[:, 2])
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    real = {k: rng.standard_normal(L) for k in ("v", "kappa", "phi", "psi", "kappa_nf")}
    factors = (cplx(M, L), cplx(Nf, L), cplx(Nt, L))
    est = PathEstimates(
        alpha=cplx(L),
        d=np.sort(rng.uniform(10, 50, L)),
        direction=u,
        near_field=np.ones(L, bool),
        valid=np.ones(L, bool),
        delta=rng.standard_normal((L, M)),
        mu_f=rng.standard_normal(L),
        mu_t=rng.standard_normal(L),
        factors=factors,
        **real,
    )
    want = np.einsum("ml,sl,kl,l->msk", *factors, est.alpha)
    got = est.model_tensor()
    assert got.shape == (M, Nf, Nt)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    brute = sum(
        est.alpha[i] * factors[0][:, i, None, None] * factors[1][None, :, i, None]
        * factors[2][None, None, :, i]
        for i in range(L)
    )  # fmt: skip
    np.testing.assert_allclose(got, brute, rtol=1e-12, atol=1e-12)
    bad = replace(est, factors=(factors[0][:, :2], factors[1], factors[2]))
    with pytest.raises(ValueError, match="factors"):
        bad.model_tensor()
