"""design.errormodel: the fast measurement route's statistics are what it says."""

import numpy as np
import pytest

from tunnelkit.design.errordraws import _repetition, draw, noise_sqrt, psd_sqrt, split
from tunnelkit.design.errormodel import PathErrorModel


def _model(T=2, P=2, M=3, **kw):
    rng = np.random.default_rng(1)
    A = rng.standard_normal((T, 4 * P, 4 * P))
    cov = A @ A.transpose(0, 2, 1) * 1e-2
    args = dict(
        t=np.arange(T) * 0.1,
        exists=np.ones((T, P), bool),
        kinds=("los", "wall")[:P],
        truth=rng.standard_normal((T, P, 4)),
        v=np.zeros((T, P)),
        crlb=cov,
        cov=cov,
        bias=np.zeros((T, P, 4)),
        k_phase=rng.standard_normal((T, P, 4, M)),
        k_gain=None,
    )
    args.update(kw)
    return PathErrorModel(**args)


def test_psd_sqrt_reproduces_the_matrix_and_tolerates_singular():
    rng = np.random.default_rng(0)
    A = rng.standard_normal((5, 6, 3))
    S = A @ A.transpose(0, 2, 1)  # rank 3
    L = psd_sqrt(S)
    assert np.allclose(L @ L.transpose(0, 2, 1), S, atol=1e-10)


def test_draw_has_the_stated_mean_and_covariance():
    m = _model(phase_sigma_rad=0.0)
    rng = np.random.default_rng(7)
    z = np.stack([draw(m, rng) for _ in range(4000)])
    err = (z - m.truth).reshape(4000, 2, -1)
    emp = np.einsum("nti,ntj->tij", err, err) / 4000
    scale = np.diagonal(m.cov, axis1=1, axis2=2).max()
    assert np.abs(emp - m.cov).max() < 0.1 * scale  # 4000 draws: about 2 % sampling error


def test_calibration_bias_is_drawn_once_per_drive_with_its_variance():
    m = _model(cov=np.zeros((2, 8, 8)), crlb=np.zeros((2, 8, 8)), phase_sigma_rad=0.1)
    rng = np.random.default_rng(3)
    b = np.stack([draw(m, rng) - m.truth for _ in range(4000)])  # (N, T, P, 4)
    var = b.var(axis=0)
    want = 0.01 * (m.k_phase**2).sum(-1)
    assert np.allclose(var, want, rtol=0.1)


def test_absent_paths_are_nan_and_may_hold_nan():
    ex = np.array([[True, False], [True, True]])
    truth = np.random.default_rng(0).standard_normal((2, 2, 4))
    truth[0, 1] = np.nan
    m = _model(exists=ex, truth=truth)
    z = draw(m, np.random.default_rng(0))
    assert np.all(np.isnan(z[0, 1])) and np.all(np.isfinite(z[1]))


@pytest.mark.parametrize(
    "kw, param",
    [
        ({"truth": np.zeros((2, 2, 3))}, "truth"),
        ({"cov": np.full((2, 8, 8), np.nan)}, "cov"),
        ({"kinds": ("los",)}, "kinds"),
        ({"phase_sigma_rad": -1.0}, "phase_sigma_rad"),
        ({"k_phase": np.zeros((2, 2, 3))}, "k_phase"),
    ],
)
def test_bad_fields_are_refused_by_name(kw, param):
    with pytest.raises((ValueError, TypeError), match=param):
        _model(**kw)


def test_budget_is_the_second_moment_of_the_drawn_error():
    m = _model(phase_sigma_rad=0.1, bias=np.full((2, 2, 4), 0.05))
    rng = np.random.default_rng(11)
    e = np.stack([draw(m, rng) - m.truth for _ in range(6000)])  # (N, T, P, 4)
    emp = np.einsum("ntpi,ntpj->tpij", e, e) / e.shape[0]
    want = m.budget()
    scale = np.abs(want).max()
    assert np.abs(emp - want).max() < 0.06 * scale
    ideal = _model(k_phase=None)
    idx = np.arange(2)
    crlb = np.moveaxis(ideal.crlb.reshape(2, 2, 4, 2, 4)[:, idx, :, idx, :], 0, 1)
    assert np.allclose(ideal.budget(), crlb)


def test_draw_with_the_noise_root_computed_once_is_the_same_draw():
    m = _model(phase_sigma_rad=0.1, bias=np.full((2, 2, 4), 0.05))
    root = noise_sqrt(m)
    assert np.allclose(root @ root.transpose(0, 2, 1), m.cov)
    a = draw(m, np.random.default_rng(5))
    b = draw(m, np.random.default_rng(5), noise_sqrt=root)
    assert np.array_equal(a, b)
    with pytest.raises(ValueError, match="noise_sqrt"):
        draw(m, np.random.default_rng(5), noise_sqrt=root[:, :4, :4])


def test_repetition_is_the_mean_pairwise_correlation_brute_force():
    m = _model(T=5, P=2, M=4, phase_sigma_rad=0.1)
    k = m.k_phase
    want = np.zeros((2, 4))
    for p in range(2):
        for c in range(4):
            u = k[:, p, c] / np.linalg.norm(k[:, p, c], axis=1, keepdims=True)
            want[p, c] = np.mean([u[t] @ u[s] for t in range(5) for s in range(5) if t != s])
    assert np.allclose(_repetition(m.exists, k), np.clip(want, 0, 1))
    # a sensitivity that is the same every epoch repeats entirely
    same = np.repeat(k[:1], 5, axis=0)
    assert np.allclose(_repetition(m.exists, same), 1.0)
    # a bias (normalise=False): the sum over pairs of b_t b_s over (n - 1) sum b_t^2
    b = np.random.default_rng(3).standard_normal((5, 2, 4, 1))
    w = np.zeros((2, 4))
    for p in range(2):
        for c in range(4):
            x = b[:, p, c, 0]
            w[p, c] = (x.sum() ** 2 - (x**2).sum()) / (4 * (x**2).sum())
    assert np.allclose(_repetition(m.exists, b, normalise=False), np.clip(w, 0, 1))


def test_split_keeps_every_variance_and_repeats_what_one_draw_repeats():
    m = _model(T=4, P=2, phase_sigma_rad=0.1, bias=np.full((4, 2, 4), 0.05))
    white, rep = split(m)
    budget = m.budget()
    d = np.diagonal
    assert np.allclose(d(white + rep, axis1=-2, axis2=-1), d(budget, axis1=-2, axis2=-1))
    assert np.all(np.linalg.eigvalsh(white) > -1e-12) and np.all(np.linalg.eigvalsh(rep) > -1e-12)
    # a calibration sensitivity the same every epoch and a constant bias repeat entirely:
    # brute force, the covariance of one drive's errors at two different epochs
    k1 = np.repeat(m.k_phase[:1], 4, axis=0)
    small = 0.01 * m.cov  # the white error only adds sampling noise to the cross moment
    const = _model(
        T=4,
        P=2,
        phase_sigma_rad=0.1,
        k_phase=k1,
        bias=np.full((4, 2, 4), 0.05),
        cov=small,
        crlb=small,
    )
    _, rep1 = split(const)
    rng = np.random.default_rng(2)
    e = np.stack([draw(const, rng) - const.truth for _ in range(6000)])  # (N, T, P, 4)
    cross = np.einsum("npi,npj->pij", e[:, 0], e[:, 2]) / e.shape[0]
    assert np.abs(cross - rep1[0]).max() < 0.06 * np.abs(rep1[0]).max()
