"""SR-NF validity (Italiano et al. 2026, Theorems 3.1/3.4): bounds against exact geometry."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tunnelkit import cli, fresnel, geometry, reflection
from tunnelkit.constants import C

PAPER = dict(R=3.5, W=3.0, y_u=2.5, fc=5.9e9, eps_phi=0.15)
GEOS = [  # (R, W, y_u, z_u, fc)
    (3.5, 3.0, 2.5, 0.0, 5.9e9),
    (100.0, 3.0, 2.5, 0.0, 5.9e9),
    (200.0, 2.0, 1.0, 0.0, 28e9),
    (30.0, 5.0, -3.0, 0.0, 5.9e9),
    (5.0, 5.0, 1.0, 0.0, 28e9),
    (20.0, 3.0, 2.9, -3.3, 3.5e9),
]


def brute_force_mismatch(pos: np.ndarray, R, W, y_u, z_u, fc) -> np.ndarray:
    """Independent route: each antenna's own specular point (reflection.specular_point), the path
    UE -> wall -> antenna summed segment by segment; the SR model's reflector is the reference
    antenna's specular point, its path reflector -> antenna."""
    wall = geometry.Plane(np.array([0.0, 1.0, 0.0]), -W)
    ue = np.array([R, y_u, z_u])
    s = reflection.specular_point(ue, pos, wall)  # (K, 3), one per antenna
    true_len = np.linalg.norm(s - ue, axis=-1) + np.linalg.norm(pos - s, axis=-1)
    s0 = reflection.specular_point(ue, np.zeros(3), wall)
    sr_len = np.linalg.norm(pos - s0, axis=-1)
    lam = C / fc
    return 2 * np.pi / lam * ((true_len - true_len[0]) - (sr_len - sr_len[0]))


def test_paper_design_example_eq25():
    # section 4.2: R = 3.5 m, W = 3 m, y_u = 2.5 m, eps = 0.15 rad, 5.9 GHz -> 9.88
    assert fresnel.mmax_2d(3.5, 3.0, 2.5, 5.9e9, 0.15) == pytest.approx(9.88, abs=0.01)
    assert round(fresnel.mmax_2d(**PAPER)) ** 2 == 100


def test_eq25_solves_eq34_with_eq33():
    # at M = eq. 25 the paraxial mismatch (eq. 33) at the array edge equals eps exactly
    for R, W, y_u, _, fc in GEOS:
        M = fresnel.mmax_2d(R, W, y_u, fc, 0.2)
        lam = C / fc
        edge = (M - 1) * lam / 2
        phase = 2 * np.pi / lam * abs(W - y_u) / (2 * R * W) * edge**2
        assert phase == pytest.approx(0.2, rel=1e-12)


@pytest.mark.parametrize("R, W, y_u, z_u, fc", GEOS)
def test_exact_mismatch_matches_brute_force(R, W, y_u, z_u, fc):
    pos = fresnel.ula_positions(64, fc)
    ours = fresnel.mismatch_profile(pos, R, W, y_u, fc, z_u=z_u)
    ref = brute_force_mismatch(pos, R, W, y_u, z_u, fc)
    np.testing.assert_allclose(ours, ref, atol=1e-8)
    ura = fresnel.ura_positions(12, fc).reshape(-1, 3)
    np.testing.assert_allclose(
        fresnel.mismatch_profile(ura, R, W, y_u, fc, z_u=z_u),
        brute_force_mismatch(ura, R, W, y_u, z_u, fc),
        atol=1e-8,
    )
    assert fresnel.phase_mismatch(64, R, W, y_u, fc, z_u=z_u) == pytest.approx(
        np.max(np.abs(ref)), abs=1e-8
    )


def test_reference_specular_point_is_eq32_and_geometry():
    ps = fresnel.reference_specular_point(3.5, 3.0, 2.5, -1.0)
    assert ps[0] == pytest.approx(3.5 * 3.0 / (2 * 3.0 - 2.5), rel=1e-14)  # eq. 32
    wall = geometry.Plane(np.array([0.0, 1.0, 0.0]), -3.0)
    np.testing.assert_allclose(
        ps, reflection.specular_point([3.5, 2.5, -1.0], np.zeros(3), wall), atol=1e-12
    )
    np.testing.assert_allclose(fresnel.vue(3.5, 3.0, 2.5, -1.0), [3.5, 3.5, -1.0])


@pytest.mark.parametrize("R, W, y_u, z_u, fc", GEOS)
@pytest.mark.parametrize("eps", [0.05, 0.15, 0.6])
def test_mmax_exact_is_the_largest_admissible_array(R, W, y_u, z_u, fc, eps):
    m = fresnel.mmax_exact(R, W, y_u, fc, eps, z_u=z_u)
    assert m >= 2
    assert fresnel.phase_mismatch(m, R, W, y_u, fc, z_u=z_u) <= eps
    assert fresnel.phase_mismatch(m + 1, R, W, y_u, fc, z_u=z_u) > eps


def test_mmax_exact_grid_matches_scalar():
    Rg = np.geomspace(0.5, 300, 9)[:, None]
    yg = np.array([-4.0, 0.0, 2.0, 2.95])[None, :]
    grid = fresnel.mmax_exact_grid(Rg, 3.0, yg, 28e9, 0.15, z_u=-1.0)
    assert grid.shape == (9, 4) and grid.dtype.kind == "i"
    for i in range(9):
        for j in range(4):
            assert grid[i, j] == fresnel.mmax_exact(
                float(Rg[i, 0]), 3.0, float(yg[0, j]), 28e9, 0.15, z_u=-1.0
            )


@pytest.mark.parametrize("R, W, y_u, z_u, fc", GEOS[:4])
def test_mmax_exact_ura_is_the_largest_admissible_square(R, W, y_u, z_u, fc):
    m = fresnel.mmax_exact_ura(R, W, y_u, fc, 0.15, z_u=z_u)
    assert fresnel.phase_mismatch_ura(m, R, W, y_u, fc, z_u=z_u) <= 0.15
    assert fresnel.phase_mismatch_ura(m + 1, R, W, y_u, fc, z_u=z_u) > 0.15


def test_ura_geometry_section_4_1():
    pos = fresnel.ura_positions(4, 5.9e9, N=3)
    d = C / 5.9e9 / 2
    assert pos.shape == (4, 3, 3)
    np.testing.assert_allclose(pos[0, 0], 0.0)
    np.testing.assert_allclose(np.linalg.norm(pos[1, 0] - pos[0, 0]), d)
    np.testing.assert_allclose(np.linalg.norm(pos[0, 1] - pos[0, 0]), d)
    boresight = np.array([math.cos(math.radians(30)), 0.0, -math.sin(math.radians(30))])
    np.testing.assert_allclose((pos - pos[0, 0]).reshape(-1, 3) @ boresight, 0.0, atol=1e-15)


def test_paraxial_bound_is_tight_far_away_and_loose_at_the_paper_example():
    for R, W, y_u, fc in [(100.0, 3.0, 2.5, 5.9e9), (200.0, 2.0, 1.0, 28e9)]:
        assert fresnel.paraxial_ratio(R, W, y_u) < 0.05
        ratio = fresnel.mmax_2d(R, W, y_u, fc, 0.15) / fresnel.mmax_exact(R, W, y_u, fc, 0.15)
        assert ratio == pytest.approx(1.0, abs=0.02)
    # the paper's example has (2W - y_u)/R = 1: eq. 25 gives 9.88, the exact ULA allows 15
    assert fresnel.paraxial_ratio(3.5, 3.0, 2.5) == pytest.approx(1.0)
    assert fresnel.mmax_exact(**PAPER) == 15
    assert fresnel.mmax_exact_ura(**PAPER) == 11  # 10 x 10 = 100 antennas holds exactly


def test_second_order_profile_converges_to_exact():
    # the corrected eq. 41 is exact to second order: the relative error shrinks with the aperture
    prof = fresnel.aperture_profile(200, 3.5, 3.0, 2.5, 5.9e9)
    rel = np.abs(prof.mismatch_second_order[1:] / prof.mismatch[1:] - 1)
    # third-order remainder: the relative error grows linearly with y_m (doubling y doubles it)
    assert rel[0] < 0.01
    np.testing.assert_allclose(rel[1] / rel[0], 2.0, rtol=0.02)
    np.testing.assert_allclose(rel[19] / rel[9], 2.0, rtol=0.1)
    # eq. 33 keeps a constant factor (rho/R)^3 = 2^1.5 off at the paper's geometry
    np.testing.assert_allclose(prof.mismatch_paraxial[1] / prof.mismatch[1], 2**1.5, rtol=1e-2)


def test_derivation_steps():
    prof = fresnel.aperture_profile(16, 400.0, 3.0, 2.5, 28e9)
    k = 2 * np.pi / (C / 28e9)
    # the linear terms of eq. 28 and eq. 31 (with eq. 32) cancel exactly: their difference is eq. 33
    np.testing.assert_allclose(
        k * (prof.delta_star_fresnel - prof.delta_sr_fresnel), prof.mismatch_paraxial, atol=1e-12
    )
    # far away the Fresnel expansions are accurate to a small fraction of the mismatch itself
    assert np.max(np.abs(k * (prof.delta_star_fresnel - prof.delta_star))) < 0.02
    np.testing.assert_allclose(prof.d_v, np.hypot(400.0, 3.5 - prof.y))
    assert prof.x_p0 == pytest.approx(400 * 3 / 3.5)


@pytest.mark.parametrize("R, W, y_u, z_u, fc", GEOS)
def test_nonparaxial_bound_tracks_exact(R, W, y_u, z_u, fc):
    exact = fresnel.mmax_exact(R, W, y_u, fc, 0.15, z_u=z_u)
    # exact is an integer (the continuous bound rounded down, give or take higher orders)
    assert abs(fresnel.mmax_nonparaxial(R, W, y_u, fc, 0.15, z_u=z_u) - exact) <= 1 + 0.04 * exact


def test_eq37_as_printed():
    assert fresnel.mmax_3d([3.5, 3.5, 0.0], 5.9e9, 0.15) == pytest.approx(
        1 + 2 * math.sqrt(math.hypot(3.5, 3.5) * 0.15 / ((C / 5.9e9) * math.pi))
    )
    # conservative for 0 <= y_u < W, optimistic (too many antennas) for a UE across the BS line
    assert fresnel.mmax_3d([100, 3.5, 0], 5.9e9, 0.15) < fresnel.mmax_exact(
        100, 3, 2.5, 5.9e9, 0.15
    )
    assert (
        fresnel.mmax_3d([30, 13, 0], 5.9e9, 0.15) > fresnel.mmax_exact(30, 5, -3, 5.9e9, 0.15) + 1
    )
    vec = fresnel.mmax_3d(np.array([[3.5, 3.5, 0.0], [100.0, 3.5, 0.0]]), 5.9e9, 0.15)
    assert vec.shape == (2,)


def test_fraunhofer():
    for R, fc in [(3.5, 5.9e9), (120.0, 28e9)]:
        m = fresnel.mmax_fraunhofer(R, fc)
        assert fresnel.fraunhofer_distance(fresnel.aperture(m, fc), fc) == pytest.approx(R)
    assert fresnel.fraunhofer_distance(1.0, C) == pytest.approx(2.0)  # lambda = 1 m


def test_vectorised_bounds_broadcast():
    R = np.array([3.5, 100.0])
    np.testing.assert_allclose(
        fresnel.mmax_2d(R, 3.0, 2.5, 5.9e9, 0.15),
        [fresnel.mmax_2d(r, 3.0, 2.5, 5.9e9, 0.15) for r in R],
    )
    assert isinstance(fresnel.mmax_2d(3.5, 3.0, 2.5, 5.9e9, 0.15), float)


@settings(max_examples=40, deadline=None)
@given(
    R=st.floats(0.5, 300),
    W=st.floats(0.5, 8),
    frac=st.floats(-2.0, 0.98),
    z_u=st.floats(-5, 5),
    eps=st.floats(0.02, 1.0),
)
def test_mismatch_grows_with_the_array_and_exact_mmax_is_consistent(R, W, frac, z_u, eps):
    y_u = frac * W
    fc = 28e9
    m = fresnel.mmax_exact(R, W, y_u, fc, eps, z_u=z_u)
    if m >= 2:
        assert fresnel.phase_mismatch(m, R, W, y_u, fc, z_u=z_u) <= eps
    assert fresnel.phase_mismatch(m + 1, R, W, y_u, fc, z_u=z_u) > eps
    a, b = (fresnel.phase_mismatch(k, R, W, y_u, fc, z_u=z_u) for k in (8, 9))
    assert b >= a


@pytest.mark.parametrize(
    "fn, kwargs, err, name",
    [
        (fresnel.mmax_2d, dict(PAPER, y_u=3.0), ValueError, "y_u"),
        (fresnel.mmax_exact, dict(PAPER, y_u=3.0), ValueError, "y_u"),
        (fresnel.mmax_nonparaxial, dict(PAPER, y_u=3.0), ValueError, "y_u"),
        (fresnel.mmax_2d, dict(PAPER, y_u=3.5), ValueError, "y_u"),
        (fresnel.mmax_2d, dict(PAPER, eps_phi=0.0), ValueError, "eps_phi"),
        (fresnel.mmax_exact, dict(PAPER, eps_phi=-0.1), ValueError, "eps_phi"),
        (fresnel.mmax_2d, dict(PAPER, fc=0.0), ValueError, "fc"),
        (fresnel.mmax_exact, dict(PAPER, fc=-5.9e9), ValueError, "fc"),
        (fresnel.mmax_2d, dict(PAPER, R=0.0), ValueError, "R"),
        (fresnel.mmax_exact, dict(PAPER, R=-1.0), ValueError, "R"),
        (fresnel.mmax_2d, dict(PAPER, W=0.0), ValueError, "W"),
        (fresnel.mmax_2d, dict(PAPER, R=float("nan")), ValueError, "R"),
        (fresnel.mmax_2d, dict(PAPER, R=None), TypeError, "R"),
        (fresnel.mmax_exact, dict(PAPER, R="3.5"), TypeError, "R"),
        (fresnel.mmax_2d, dict(PAPER, eps_phi=True), TypeError, "eps_phi"),
    ],
)
def test_bad_input_names_the_parameter(fn, kwargs, err, name):
    with pytest.raises(err, match=rf"^{name}:"):
        fn(**kwargs)


def test_y_u_on_the_wall_says_the_bound_is_infinite():
    with pytest.raises(ValueError, match="infinite"):
        fresnel.mmax_2d(3.5, 3.0, 3.0, 5.9e9, 0.15)


@pytest.mark.parametrize(
    "M, err",
    [
        (1, ValueError),
        (0, ValueError),
        (-3, ValueError),
        (3.5, TypeError),
        (4.0, TypeError),
        ("8", TypeError),
    ],
)
def test_bad_M(M, err):
    geo = dict(R=3.5, W=3.0, y_u=2.5, fc=5.9e9)
    with pytest.raises(err, match=r"^M:"):
        fresnel.phase_mismatch(M, **geo)
    with pytest.raises(err, match=r"^M:"):
        fresnel.phase_mismatch_ura(M, **geo)
    with pytest.raises(err, match=r"^M:"):
        fresnel.aperture_profile(M, **geo)


def test_bad_vue_and_positions():
    with pytest.raises(ValueError, match=r"^p_v:"):
        fresnel.mmax_3d([1.0, 2.0], 5.9e9, 0.15)
    with pytest.raises(ValueError, match=r"^p_v:"):
        fresnel.mmax_3d([0.0, 0.0, 0.0], 5.9e9, 0.15)
    with pytest.raises(ValueError, match=r"^positions:"):
        fresnel.mismatch_profile(np.zeros((4, 2)), 3.5, 3.0, 2.5, 5.9e9)


def test_design_report_and_summary():
    s = fresnel.mmax_summary(**PAPER)
    assert s.exact == 15 and s.exact_ura == 11 and s.eq25 == pytest.approx(9.884, abs=1e-3)
    assert s.as_dict()["ratio"] == pytest.approx(9.8844 / 15, abs=1e-4)
    rep = fresnel.design_report([dict(PAPER, label="paper"), dict(PAPER, R=100.0)])
    assert len(rep.rows) == 2 and rep.records()[0]["exact ULA"] == 15
    assert "paper" in rep.to_table()


def test_cli_mmax(capsys):
    assert cli.main(["mmax", "--M", "10", "--fc", "5.9GHz", "28e9", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["exact ULA"] for r in out["rows"]] == [15, 32]
    assert out["rows"][0]["eq.25"] == pytest.approx(9.8844, abs=1e-4)
    assert out["verdicts"][0]["valid"] and out["verdicts"][0]["ura_valid"]
    assert cli.main(["mmax", "--no-ura"]) == 0
    assert "9.884" in capsys.readouterr().out
    assert cli.main(["mmax", "--y-u", "3"]) == 2
    assert "y_u" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli.main(["mmax", "--fc", "fast"])


def test_every_public_name_resolves():
    import importlib

    for name in fresnel.__all__:
        assert getattr(fresnel, name) is not None, name
    for sub in ("bounds", "exact", "summary"):
        mod = importlib.import_module(f"tunnelkit.fresnel.{sub}")
        for name in mod.__all__:
            assert getattr(mod, name) is not None, name


def test_signed_mismatch_checks_its_arguments():
    pv, ps = fresnel.vue(3.5, 3.0, 2.5), fresnel.reference_specular_point(3.5, 3.0, 2.5)
    pos = fresnel.ula_positions(8, 5.9e9)
    np.testing.assert_array_equal(
        fresnel.signed_mismatch(pv, ps, pos, C / 5.9e9),
        fresnel.mismatch_profile(pos, 3.5, 3.0, 2.5, 5.9e9),
    )
    with pytest.raises(ValueError, match="pos"):
        fresnel.signed_mismatch(pv, ps, pos[:, :2], 0.05)
    with pytest.raises(ValueError, match="lam"):
        fresnel.signed_mismatch(pv, ps, pos, 0.0)
    with pytest.raises(ValueError, match="pv"):
        fresnel.signed_mismatch([np.nan, 0, 0], ps, pos, 0.05)
