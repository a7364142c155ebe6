"""Physically impossible results of the design and the trackers are refused where they are
built (the records' checks), and the checks the contracts added name what is wrong."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from javelin_geometric import geometric_stream, toy_drive, toy_reflectors

from tunnelkit import _checks, design
from tunnelkit.design import verdict
from tunnelkit.design.errordraws import psd_sqrt
from tunnelkit.tracking.javelin import JavelinConfig, JavelinDesign, run_javelin


@pytest.fixture(scope="module")
def setup():
    return design.DesignSetup.from_scenario("italiano2026-straight")


@pytest.fixture(scope="module")
def bounds(setup):
    return design.route_bounds(setup, "4x4", epochs=[5, 10, 15])


def test_a_negative_or_nan_position_bound_is_refused(bounds):
    for bad in (-bounds.peb, np.full_like(bounds.peb, np.nan)):
        with pytest.raises(ValueError, match=r"^peb: "):
            dataclasses.replace(bounds, peb=bad)
    ok = dataclasses.replace(bounds, peb=np.full_like(bounds.peb, np.inf))  # not identifiable
    assert np.isinf(ok.peb).all()
    with pytest.raises(ValueError, match=r"^mismatch: "):
        dataclasses.replace(bounds, mismatch=-bounds.mismatch - 1.0)
    with pytest.raises(ValueError, match=r"^used: "):  # one row per epoch, like x
        dataclasses.replace(bounds, used=bounds.used[:-1])


def test_a_predicted_error_is_a_length(setup):
    a = design.predicted_error(
        setup, "4x4", design.DesignImpairments(phase_error_deg=0.5), epochs=[5, 10]
    )
    assert np.all(a.predicted >= a.peb)
    for name in ("predicted", "calibration", "wideband", "diffuse"):
        with pytest.raises(ValueError, match=rf"^{name}: "):
            dataclasses.replace(a, **{name: np.full(2, np.nan)})
        with pytest.raises(ValueError, match=rf"^{name}: "):
            dataclasses.replace(a, **{name: np.full(2, -0.1)})
    with pytest.raises(TypeError, match=r"^spec: "):
        dataclasses.replace(a, spec="4x4")


def test_an_error_model_with_a_negative_variance_is_refused(setup):
    m = design.path_error_model(setup, "4x4", epochs=[5, 10])
    k = int(np.flatnonzero(np.repeat(m.exists[0], 4))[0])
    for name in ("crlb", "cov"):
        bad = np.array(getattr(m, name))
        bad[0, k, k] = -abs(bad[0, k, k]) - 1e-6
        with pytest.raises(ValueError, match=rf"^{name}: "):
            dataclasses.replace(m, **{name: bad})


def test_the_quantiles_of_the_verdict_stay_in_zero_to_infinity():
    rng = np.random.default_rng(0)
    e = np.abs(rng.standard_normal(40))
    assert 0.0 <= verdict.share_quantile(e, 0.9) < np.inf
    e_nan = e.copy()
    e_nan[:10] = np.nan  # no estimate: counted as infinite
    assert verdict.share_quantile(e_nan, 0.9) == np.inf
    with pytest.raises(ValueError, match=r"^values: "):
        verdict.share_quantile(-e, 0.9)
    with pytest.raises(TypeError, match=r"^values: "):
        verdict.share_quantile("x", 0.9)
    with pytest.raises(ValueError, match=r"^yield_: "):
        verdict.judge(0.2, units=20, yield_=float("nan"), ci=[0.1, 0.2])
    with pytest.raises(ValueError, match=r"^ci: "):
        verdict.judge(0.2, units=20, yield_=0.1, ci=[])
    with pytest.raises(ValueError, match=r"^ci: "):
        verdict.judge(0.2, units=20, yield_=0.5, ci=[0.6, 1.2])


@pytest.fixture(scope="module")
def javelin_run():
    rng = np.random.default_rng(0)
    bs = (0.0, 0.0, 4.8)
    P, V = toy_drive(8, 0.1, amplitude=0.5, speed=4.0)
    eps = geometric_stream(
        P, V, toy_reflectors(), rng, bs=bs, sigma_phi=0.02, sigma_psi=0.02, sigma_d=0.3
    )
    spd, hdg = np.linalg.norm(V, axis=1), np.arctan2(V[:, 1], V[:, 0])
    cfg = JavelinDesign(JavelinConfig(base_station=bs, sigma_p0_ue=1.0))
    return run_javelin(eps, spd, hdg, 0.1, P[0], cfg, keep_reports=True)


def test_a_nan_tracker_state_is_not_a_valid_estimate(javelin_run):
    run = javelin_run
    assert np.isfinite(run.estimates).all()
    bad = run.estimates.copy()
    bad[3, 0] = np.nan
    with pytest.raises(ValueError, match=r"^estimates: "):
        dataclasses.replace(run, estimates=bad)
    rep = run.reports[2]
    with pytest.raises(ValueError, match=r"^estimate: "):
        dataclasses.replace(rep, estimate=np.array([np.nan, 0.0, 1.0]))
    with pytest.raises(ValueError, match=r"^nis: "):
        dataclasses.replace(rep, nis=-1.0)
    with pytest.raises(ValueError, match=r"^covariances: "):
        dataclasses.replace(run, covariances=run.covariances[:, :2, :2])


def test_the_added_argument_kinds_name_the_parameter():
    assert _checks.series("d", [1.0, np.nan]).shape == (2,)
    with pytest.raises(ValueError, match=r"^d: "):
        _checks.series("d", np.zeros((2, 2)))
    with pytest.raises(TypeError, match=r"^d: "):
        _checks.series("d", "1.0")
    assert _checks.sign("sign", -1) == -1.0
    for bad in (0.0, 2.0, float("nan")):
        with pytest.raises(ValueError, match=r"^sign: "):
            _checks.sign("sign", bad)
    assert _checks.bound("b", float("inf")) == float("inf")
    with pytest.raises(ValueError, match=r"^b: "):
        _checks.bound("b", float("nan"))
    assert _checks.optional_real("speed", float("nan")) is None
    with pytest.raises(TypeError, match=r"^speed: "):
        _checks.optional_real("speed", "fast")
    with pytest.raises(TypeError, match=r"^drive: .*\(with epochs\)"):
        _checks.attributes("drive", object(), ("epochs",), "a drive")
    with pytest.raises(TypeError, match=r"^planes\[1\]: "):
        _checks.items("planes", [toy_reflectors()[0], 3], type(toy_reflectors()[0]))
    with pytest.raises(ValueError, match=r"^S: "):
        psd_sqrt(np.ones((2, 3)))


def test_parse_array_names_spec_and_the_design_functions_pass_it_on(setup):
    with pytest.raises(ValueError, match=r"^spec: cannot read '8y8'"):
        design.route_bounds(setup, "8y8")
    with pytest.raises(TypeError, match=r"^spec: "):
        design.path_bounds(setup, 8)
    with pytest.raises(ValueError, match=r"^mount_height: "):
        setup.variant(mount_height=-1.0)


def test_a_design_row_refuses_impossible_statistics_and_keeps_never_met():
    row = design.DesignRow("4x4", 16, 0.02, peb_median_m=np.inf, x_m=np.arange(3.0),
                           peb_m=np.array([0.1, np.inf, np.nan]), error_p90_ci95_m=[0.1, np.inf])  # fmt: skip
    assert np.isinf(row.peb_median_m) and row.to_json()["peb_median_m"] is None
    for field, bad in [("runs", -1), ("rmse_m", -0.1), ("met_share", np.nan), ("n_elements", 0),
                       ("error_p90_ci95_m", [0.1]), ("status", ""), ("array", 3)]:  # fmt: skip
        with pytest.raises((TypeError, ValueError), match=rf"^{field}: "):
            design.DesignRow(**{"array": "4x4", "n_elements": 16, "aperture_diagonal_m": 0.02,
                                field: bad})  # fmt: skip
    with pytest.raises(ValueError, match=r"^peb_m: "):  # one value per x
        design.DesignRow("4x4", 16, 0.02, x_m=np.arange(3.0), peb_m=np.ones(2))
    assert design.DesignReport("x", [row], {}, {}).warnings == []
    for rows in ([], [row, "8x8"]):
        with pytest.raises((TypeError, ValueError), match=r"^rows(\[1\])?: "):
            design.DesignReport("x", rows, {}, {})
    assert design.report.DesignRow is design.records.DesignRow  # the same record, re-exported
