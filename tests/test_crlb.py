import numpy as np
import pytest
from conftest import random_inside

from tunnelkit import crlb

SIG = (np.radians(0.5), 0.1)


def _h(vs):
    return lambda p: np.concatenate(crlb.toa_doa(p, vs), -1)


def test_analytic_jacobian_matches_finite_differences(jiang):
    vs = jiang["vs"]
    pts = random_inside(jiang["tunnel"], 300, np.random.default_rng(0))
    J = crlb.toa_doa_jacobian(pts, vs)
    Jn = crlb.numeric_jacobian(_h(vs), pts, angle_mask=[False, False, True, True])
    np.testing.assert_allclose(J, Jn, rtol=1e-6, atol=1e-9)
    # the sign the paper drops (eq. A2): dtheta/dx = -(y - y_v)/d^2
    dy = pts[:, 1] - vs[0, 1]
    assert np.all(np.sign(J[:, 2, 0]) == -np.sign(dy))


def test_numeric_fim_matches_corrected_closed_form_at_1000_positions(jiang):
    """Relative error in Frobenius norm <= 1e-6 everywhere inside the tunnel."""
    vs = jiang["vs"]
    pts = random_inside(jiang["tunnel"], 1000, np.random.default_rng(1))
    R = np.diag([SIG[1] ** 2] * 2 + [SIG[0] ** 2] * 2)
    F = crlb.fim_toa_doa(pts, vs, *SIG)
    Fn = crlb.numeric_fim(_h(vs), pts, R, angle_mask=[False, False, True, True])
    rel = np.linalg.norm(F - Fn, axis=(-2, -1)) / np.linalg.norm(F, axis=(-2, -1))
    assert rel.max() < 1e-6
    # the printed form differs measurably (its cross term has the wrong sign)
    Fp = crlb.fim_toa_doa(pts, vs, *SIG, form="paper")
    relp = np.linalg.norm(Fp - Fn, axis=(-2, -1)) / np.linalg.norm(F, axis=(-2, -1))
    assert np.median(relp) > 1e-3


def test_fim_with_los_station_and_per_station_sigmas(jiang):
    st = np.vstack([jiang["bs"], jiang["vs"]])
    p = jiang["start"]
    s_th = np.radians([0.3, 0.5, 1.0])
    s_d = np.array([0.1, 0.2, 0.4])
    R = np.diag(np.concatenate([s_d**2, s_th**2]))
    Fn = crlb.numeric_fim(_h(st), p, R, angle_mask=[False] * 3 + [True] * 3)
    np.testing.assert_allclose(crlb.fim_toa_doa(p, st, s_th, s_d), Fn, rtol=1e-6)


def test_crlb_trace_equals_trace_of_inverse(jiang):
    pts = random_inside(jiang["tunnel"], 50, np.random.default_rng(2))
    F = crlb.fim_toa_doa(pts, jiang["vs"], *SIG)
    np.testing.assert_allclose(
        crlb.crlb_trace(F), np.trace(np.linalg.inv(F), axis1=-2, axis2=-1), rtol=1e-10
    )
    F3 = np.eye(3) * [1.0, 2.0, 4.0]
    assert crlb.crlb_trace(F3) == pytest.approx(1.75)


def test_toa_only_fim_is_singular_on_the_station_line(jiang):
    # a point on the line through both virtual stations (and the BS), inside the tunnel
    t = jiang["tunnel"]
    p = t.from_tunnel_frame(np.array([t.to_tunnel_frame(jiang["bs"])[0], 4.0]))
    F = crlb.fim_toa_doa(p, jiang["vs"], None, 0.1)
    assert abs(np.linalg.det(F)) < 1e-9 * np.trace(F) ** 2
    with pytest.raises(ValueError, match="F: singular"):
        crlb.crlb_trace(F)
    assert np.isfinite(crlb.crlb_rmse(p, jiang["vs"], np.radians(0.5), 0.1))


def test_wrap_angle():
    np.testing.assert_allclose(
        crlb.wrap_angle([np.pi + 0.1, -np.pi - 0.1, 0.3]), [-np.pi + 0.1, np.pi - 0.1, 0.3]
    )


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"sigma_theta": 0.0}, "sigma_theta: must be > 0"),
        ({"sigma_d": -1.0}, "sigma_d: must be > 0"),
        ({"sigma_d": [0.1, 0.2, 0.3]}, "sigma_d: expected a scalar or one value per station"),
        ({"sigma_theta": None, "sigma_d": None}, "at least one measurement"),
        ({"p": [np.nan, 1.0]}, "p: contains NaN"),
        ({"p": [np.inf, 1.0]}, "p: contains NaN or infinite"),
        ({"p": [-13.333333333333334, 13.333333333333334]}, "p: coincides with a station"),
        ({"p": [1.0, 2.0, 3.0]}, "p: expected 2-D"),
        ({"form": "printed"}, "form:"),
    ],
)
def test_fim_bad_input(jiang, kwargs, match):
    args = {"p": jiang["start"], "stations": jiang["vs"], "sigma_theta": SIG[0], "sigma_d": SIG[1]}
    args.update(kwargs)
    with pytest.raises((ValueError, TypeError), match=match):
        crlb.fim_toa_doa(**args)


def test_numeric_fim_bad_input(jiang):
    with pytest.raises(ValueError, match="R: must be symmetric positive definite"):
        crlb.numeric_fim(_h(jiang["vs"]), jiang["start"], -np.eye(4))
    with pytest.raises(ValueError, match="R: has size 3"):
        crlb.numeric_fim(_h(jiang["vs"]), jiang["start"], np.eye(3))
    with pytest.raises(ValueError, match="step: must be > 0"):
        crlb.numeric_jacobian(_h(jiang["vs"]), jiang["start"], step=0.0)
