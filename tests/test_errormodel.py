"""design.errormodel: the fast measurement route's statistics are what it says."""

import numpy as np
import pytest

from tunnelkit.design.errormodel import PathErrorModel, psd_sqrt


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
    z = np.stack([m.draw(rng) for _ in range(4000)])
    err = (z - m.truth).reshape(4000, 2, -1)
    emp = np.einsum("nti,ntj->tij", err, err) / 4000
    scale = np.diagonal(m.cov, axis1=1, axis2=2).max()
    assert np.abs(emp - m.cov).max() < 0.1 * scale  # 4000 draws: about 2 % sampling error


def test_calibration_bias_is_drawn_once_per_drive_with_its_variance():
    m = _model(cov=np.zeros((2, 8, 8)), crlb=np.zeros((2, 8, 8)), phase_sigma_rad=0.1)
    rng = np.random.default_rng(3)
    b = np.stack([m.draw(rng) - m.truth for _ in range(4000)])  # (N, T, P, 4)
    var = b.var(axis=0)
    want = 0.01 * (m.k_phase**2).sum(-1)
    assert np.allclose(var, want, rtol=0.1)


def test_absent_paths_are_nan_and_may_hold_nan():
    ex = np.array([[True, False], [True, True]])
    truth = np.random.default_rng(0).standard_normal((2, 2, 4))
    truth[0, 1] = np.nan
    m = _model(exists=ex, truth=truth)
    z = m.draw(np.random.default_rng(0))
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
    e = np.stack([m.draw(rng) - m.truth for _ in range(6000)])  # (N, T, P, 4)
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
    root = m.noise_sqrt()
    assert np.allclose(root @ root.transpose(0, 2, 1), m.cov)
    a = m.draw(np.random.default_rng(5))
    b = m.draw(np.random.default_rng(5), noise_sqrt=root)
    assert np.array_equal(a, b)
    with pytest.raises(ValueError, match="noise_sqrt"):
        m.draw(np.random.default_rng(5), noise_sqrt=root[:, :4, :4])


def test_budget_scales_only_its_correlated_share():
    m = _model(phase_sigma_rad=0.1, bias=np.full((2, 2, 4), 0.05))
    ideal = _model(k_phase=None)  # same cov, nothing correlated: the scale changes nothing
    assert np.allclose(ideal.budget(4.0), ideal.budget())
    idx = np.arange(2)
    cov = np.moveaxis(m.cov.reshape(2, 2, 4, 2, 4)[:, idx, :, idx, :], 0, 1)
    assert np.allclose(m.budget(3.0) - cov, 3.0 * (m.budget() - cov))
    for bad in (0.5, -1.0, float("nan")):
        with pytest.raises(ValueError, match="correlated_scale"):
            m.budget(bad)
