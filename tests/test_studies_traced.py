"""The traced design's pieces: the drive loop equals the one drive simulator, the adapter, the
stored sigmas and the design read from them."""

from __future__ import annotations

import json
import os
from dataclasses import replace

import numpy as np
import pytest

from tunnelkit.simulation import simulate_routes
from tunnelkit.simulation.drives import path_measurements, scenario_route
from tunnelkit.simulation.prefilter import (
    FLOORS,
    check_provenance,
    geometry_keep,
    scene_provenance,
    traced_measurements,
)
from tunnelkit.studies.traced import (
    simulate_traced,
    traced_design,
    traced_errors,
    write_traced_errors,
)
from tunnelkit.tracking.javelin import designs


def _same_drive(a, b):
    assert a.faults == b.faults
    np.testing.assert_array_equal(a.los, b.los)
    np.testing.assert_array_equal(a.n_true, b.n_true)
    np.testing.assert_array_equal(a.speed, b.speed)
    np.testing.assert_array_equal(a.heading, b.heading)
    for pa, pb, ta, tb in zip(a.epochs, b.epochs, a.truth_index, b.truth_index, strict=True):
        assert (pa is None) == (pb is None)
        np.testing.assert_array_equal(ta, tb)
        if pa is not None:
            for f in ("phi", "psi", "kappa", "d", "source"):
                np.testing.assert_array_equal(getattr(pa, f), getattr(pb, f))


@pytest.mark.parametrize("cond", ["L", "N@0.5"])
def test_the_loop_draws_and_measures_as_the_drive_simulator(cond):
    """Same seed: the paper's and the ML route's drives equal simulate_routes' (image channel)."""
    ref = simulate_routes(
        "italiano2026-straight", np.random.default_rng(3), condition=cond,
        extractions=("paper", "ml"), n_epochs=3,
    )  # fmt: skip
    got = simulate_traced("italiano2026-straight", np.random.default_rng(3), condition=cond,
                          n_epochs=3)  # fmt: skip
    for e in ("paper", "ml"):
        _same_drive(got[e], ref[e])
    # the traced adapter keeps a subset of every epoch's ML measurements, in their order
    for pa, pt in zip(got["ml-all"].epochs, got["ml-traced"].epochs, strict=True):
        if pt is not None:
            assert set(pt.source) <= set(pa.source)
            assert np.all(np.diff(pt.source) > 0)


def test_an_adapter_measures_its_extractions_epochs_without_a_draw():
    """simulate_routes' adapters: an extra route fed the same epochs; with the ordinary adapter it
    equals its extraction's drive, and the other routes and draws are those without it."""
    kw = dict(condition="N@0.5", extractions=("paper", "ml"), n_epochs=3)
    ref = simulate_routes("italiano2026-straight", np.random.default_rng(4), **kw)
    calls = []

    def spy(ep, route):
        calls.append(ep.k)
        return path_measurements(ep, route)

    got = simulate_routes(
        "italiano2026-straight", np.random.default_rng(4), adapters={"copy": ("ml", spy)}, **kw
    )
    assert list(got) == ["paper", "ml", "copy"]
    for e in ("paper", "ml"):
        _same_drive(got[e], ref[e])
    _same_drive(got["copy"], ref["ml"])
    assert got["copy"].extraction == "ml"
    failed = {int(f.split(":")[0].split()[1]) for f in ref["ml"].faults if "failed (" in f}
    assert calls == [k for k in range(3) if k not in failed]  # once per measured epoch


@pytest.mark.parametrize(
    "adapters, exc, match",
    [
        ([("x", ("ml", path_measurements))], TypeError, "adapters: expected a dict"),
        ({"ml": ("ml", path_measurements)}, ValueError, "adapters: expected new route names"),
        ({"x": ("coherent", path_measurements)}, ValueError, "not one of the extractions"),
        ({"x": ("ml", None)}, TypeError, "must map to"),
        ({"x": ("nope", path_measurements)}, ValueError, "extraction: expected one of"),
    ],
)
def test_bad_adapters_are_named(adapters, exc, match):
    with pytest.raises(exc, match=match):
        simulate_routes(
            "italiano2026-straight", np.random.default_rng(0), extractions=("paper", "ml"),
            n_epochs=1, adapters=adapters,
        )  # fmt: skip


def test_the_adapter_passes_a_flagged_fit_and_drops_an_inconsistent_path():
    route = scenario_route("italiano2026-straight")
    ep = route.epoch(5, np.random.default_rng(1), refine="ml")
    keep = geometry_keep(ep, route)
    assert keep.tolist() == list(range(len(ep.measurements)))  # eq.-1 channel: all agree
    flagged = replace(ep, estimates=replace(ep.estimates, fit_ok=False))
    assert path_measurements(flagged, route)[0] is None  # the ordinary adapter drops it
    pm, why = traced_measurements(flagged, route)
    assert why is None and len(pm) == len(ep.measurements)
    # one path's range moved by 5 m (far beyond the 0.3 m floor): dropped, the others kept
    m = ep.measurements
    d = m.d.copy()
    d[1] += 5.0
    bad = replace(ep, measurements=replace(m, d=d))
    kept = geometry_keep(bad, route)
    assert 1 not in kept and len(kept) == len(m) - 1
    with pytest.raises(ValueError, match="floors"):
        geometry_keep(ep, route, floors=(0.0, 0.3))


def test_the_stored_errors_set_the_design(tmp_path):
    rec = {"scenario": "italiano2026-straight", "condition": "L", "seed": 0, "runs": 1,
           "rows": [["los", 3, 1.0, 2.0, 30.0, 0.5, 0], ["all", 9, 9.0, 8.0, 33.0, 1.1, 1]]}  # fmt: skip
    rec.update(scene_provenance())
    p = write_traced_errors(rec, tmp_path / "e.json")
    assert json.loads(open(p).read())["rows"][1][0] == "all"
    d = traced_design(p)
    assert d.config.sigma_phi == pytest.approx(np.radians(9.0))
    assert d.config.sigma_psi == pytest.approx(np.radians(8.0))
    assert d.config.sigma_kappa == 33.0 and d.config.sigma_delta_d == 1.1
    base = designs.ours_ml()
    assert replace(d.config, sigma_phi=1, sigma_psi=1, sigma_kappa=1, sigma_delta_d=1) == replace(
        base.config, sigma_phi=1, sigma_psi=1, sigma_kappa=1, sigma_delta_d=1
    )  # every other number from ours_ml
    # with the record's lag-1 error correlation: each sigma its long-run value
    rec["correlation"] = {"phi": {"r": 0.6, "pairs": 9}, "psi": {"r": 0.0, "pairs": 9}}
    d2 = traced_design(write_traced_errors(rec, tmp_path / "c.json"))
    assert d2.config.sigma_phi == pytest.approx(np.radians(9.0) * 2.0)
    assert d2.config.sigma_psi == pytest.approx(np.radians(8.0))
    with pytest.raises(FileNotFoundError, match="path"):
        traced_errors(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text(json.dumps({"rows": [["los", 1, 1, 1, 1, 1, 0]]}))
    with pytest.raises(ValueError, match="path"):
        traced_errors(tmp_path / "bad.json")


def test_stored_sigmas_of_another_scene_are_refused_never_reused(tmp_path):
    """The record's ray-tracer settings and scene key are checked against the current ones: any
    difference is refused (naming it), a record without them is used with a warning."""
    import warnings

    cur = scene_provenance()
    assert cur["rt_key"]["scene"] and cur["rt_settings"]["max_depth"] >= 1
    rows = [["all", 9, 9.0, 8.0, 33.0, 1.1, 1]]
    ok = write_traced_errors({"rows": rows, **cur}, tmp_path / "ok.json")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert traced_errors(ok)["rows"] == rows  # same scene: no warning
    for part, name, value in [
        ("rt_settings", "scattering_coefficient", 0.5),
        ("rt_key", "scene", "0" * 64),
        ("rt_key", "sionna_rt", "0.0.1"),
    ]:
        other = json.loads(json.dumps(cur))
        other[part][name] = value
        p = write_traced_errors({"rows": rows, **other}, tmp_path / f"{name}.json")
        with pytest.raises(ValueError, match=rf"path: .*{part}\.{name}: stored"):
            traced_errors(p)
        with pytest.raises(ValueError, match=rf"{part}\.{name}"):
            traced_design(p)
        assert traced_errors(p, check=False)["rows"] == rows  # read as it is, on request
        with pytest.raises(ValueError, match="another scene"):
            check_provenance(json.loads(open(p).read()), cur)
    legacy = write_traced_errors(
        {"rows": rows, "rt_settings": cur["rt_settings"]}, tmp_path / "legacy.json"
    )
    with pytest.warns(UserWarning, match="carries no rt_key"):
        traced_errors(legacy)
    assert check_provenance({"rows": rows}, cur) == ["rt_settings", "rt_key"]
    with pytest.raises(TypeError, match="check"):
        traced_errors(ok, check="yes")


def test_the_traced_note_says_when_the_tables_ray_tracer_differs():
    from tunnelkit.reproduce.javelin_traced import traced_note as _traced_note

    cur = dict(traced_errors(check=False)["rt_settings"])
    assert "ray tracer differs" not in _traced_note({"diffuse_floor": True}, {"rt_settings": cur})
    cur["scattering_coefficient"] = 0.5
    note = _traced_note({"diffuse_floor": True}, {"rt_settings": cur})
    assert "ray tracer differs" in note and "scattering_coefficient: 0.3 there, 0.5 here" in note


def test_the_stored_record_states_its_procedure():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # it carries its scene, and the scene is the current one
        rec = traced_errors()
    assert set(rec["rt_key"]) >= {"scene", "settings", "sionna_rt", "trajectory", "arrays"}
    assert rec["procedure"] == "tunnelkit.studies.traced.measure_traced_errors"
    assert rec["seed"] == 0 and rec["scenario"] == "italiano2026-straight"
    assert rec["condition"] == "L" and rec["nuisance"] == {"diffuse_floor": True}
    assert FLOORS[1] > 0


@pytest.mark.skipif(os.environ.get("TUNNELKIT_SKIP_RT") == "1", reason="TUNNELKIT_SKIP_RT=1")
def test_the_traced_table_has_the_traced_column_scored_on_the_traced_drive(monkeypatch):
    """``javelin_table(channel="sionna")`` (two epochs, one run) adds the traced columns; the
    traced column's JAVELIN-L score is the traced design's on simulate_traced's ``ml-traced``
    drive of the same child seed, the line-of-sight column's the line-of-sight design's on the
    ``ml-all`` drive cut to the path taken for the line of sight and told the survey's table,
    started told 0.1 m (not the other columns' 1 m); the image channel's table has neither."""
    from tunnelkit.montecarlo import spawn_rngs
    from tunnelkit.reproduce import javelin_tables as jt
    from tunnelkit.reproduce import javelin_traced as jtr
    from tunnelkit.simulation import evaluate

    # the slalom's survey is measured on first use (3 design drives): the straight's shipped one
    straight = jtr.los_survey("italiano2026-straight")
    monkeypatch.setattr(jt, "los_survey", lambda scenario, progress=False: straight)
    nuis = {"diffuse_floor": True}
    rep = jt.javelin_table("italiano2026-slalom", "italiano2026_table2", ("L",), 1, 0, False,
                           extractions=("ml",), n_epochs=2, channel="sionna", nuisance=nuis)  # fmt: skip
    assert jt.TRACED_COLUMN[0] in rep.columns and jtr.LOS_COLUMN[0] in rep.columns
    row = next(r for r in rep.rows if r[0] == "JAVELIN-L" and r[1] == "rmse_2d_m")
    drives = simulate_traced("italiano2026-slalom", spawn_rngs(0, 1)[0], n_epochs=2,
                             channel="sionna", nuisance=nuis)  # fmt: skip
    col = rep.columns.index(jt.TRACED_COLUMN[0])
    ev = evaluate(drives["ml-traced"], traced_design())
    assert row[col] == pytest.approx(ev.metrics["rmse_2d_m"], rel=1e-12)
    col = rep.columns.index(jtr.LOS_COLUMN[0])
    los = jtr.los_drive(drives["ml-all"], straight[0])
    assert sum(ep is not None and len(ep) == 1 for ep in los.epochs) >= 1
    told = evaluate(los, jtr.los_design(), sigma_p0_ue=jtr.LOS_START_M).metrics["rmse_2d_m"]
    assert row[col] == pytest.approx(told, rel=1e-12)
    assert told != pytest.approx(evaluate(los, jtr.los_design()).metrics["rmse_2d_m"], rel=1e-9)
    assert any("traced design" in n for n in rep.notes)
    assert any("line of sight told by elevation" in n and "0.1 m" in n for n in rep.notes)
    assert rep.meta["los_survey"]["path"] == straight[1]["path"]
    # dead reckoning has no update for the told start to weigh: the column's row is the others'
    dr = next(r for r in rep.rows if r[0] == "dead reckoning-L" and r[1] == "rmse_2d_m")
    assert dr[rep.columns.index(jtr.LOS_COLUMN[0])] == dr[rep.columns.index(jt.TRACED_COLUMN[0])]
    assert rep.meta["epochs"][jtr.LOS_COLUMN[1]] == rep.meta["epochs"]["ml"] == 2
    # the direct column: its own drive from a generator spawned from the trial's, its dead
    # reckoning that drive's own (the slalom ships its table)
    from tunnelkit.reproduce import javelin_direct as jd

    col = rep.columns.index(jd.DIRECT_COLUMN[0])
    own, (n_drop, n_ep) = jd.direct_scores(
        "italiano2026-slalom", 2, spawn_rngs(0, 1)[0].spawn(1)[0]
    )
    assert row[col] == own["JAVELIN"]["rmse_2d_m"] and dr[col] == own["dead reckoning"]["rmse_2d_m"]
    assert rep.meta["epochs"][jd.DIRECT_COLUMN[1]] == n_ep == 2
    assert rep.meta["extraction_failures"][jd.DIRECT_COLUMN[1]] == n_drop
    assert any(n.startswith(f"Column '{jd.DIRECT_COLUMN[0]}'") for n in rep.notes)
    assert rep.meta["radio_gain"]["JAVELIN-L"][jd.DIRECT_COLUMN[0]] == pytest.approx(
        dr[col] / row[col]
    )
    img = jt.javelin_table("italiano2026-slalom", "italiano2026_table2", ("L",), 1, 0, False,
                           extractions=("ml",), n_epochs=2)  # fmt: skip
    assert jt.TRACED_COLUMN[0] not in img.columns and jtr.LOS_COLUMN[0] not in img.columns
    assert jd.DIRECT_COLUMN[0] not in img.columns


def test_the_traced_pcrlb_is_the_kalman_covariance_of_its_linear_model(monkeypatch):
    """traced_pcrlb: the covariance recursion of the linear model (F = I) it states, written out
    (P_k = ((P_{k-1} + Q_k)^-1 + I_k)^-1), gives the same bound; tighter sigmas a tighter bound;
    sigmas so large the paths carry nothing: the dead reckoning's bound; bad rows named."""
    import tunnelkit.studies.traced_bound as traced_bound
    from tunnelkit.design import DesignSetup, drive_pcrlb
    from tunnelkit.design.drivebound import drive_motion
    from tunnelkit.simulation.drives import SIGMA_HEADING, SIGMA_SPEED
    from tunnelkit.studies.traced_bound import traced_pcrlb

    rows = [["all", 9, 9.0, 8.0, 33.0, 1.1, 1]]
    seen = {}
    real = traced_bound.position_information

    def spy(model, geometry, weights=None):
        seen["info"] = real(model, geometry, weights)
        return seen["info"]

    monkeypatch.setattr(traced_bound, "position_information", spy)
    b = traced_pcrlb(rows=rows, sigma_p0=0.5)
    info = seen["info"]
    assert info.shape == (len(b), 2, 2) and np.all(np.linalg.eigvalsh(info) > 0)
    setup = DesignSetup.from_scenario("italiano2026-straight")
    G, Qn, _ = drive_motion(setup, len(b), SIGMA_SPEED, SIGMA_HEADING)
    P = np.linalg.inv(np.eye(2) / 0.25 + info[0])
    want = [np.sqrt(np.trace(P))]
    for k in range(1, len(b)):
        Q = G[k] @ Qn @ G[k].T + 1e-12 * np.eye(2)
        P = np.linalg.inv(np.linalg.inv(P + Q) + info[k])
        want.append(np.sqrt(np.trace(P)))
    np.testing.assert_allclose(b, want, rtol=1e-9)
    tight = traced_pcrlb(rows=[["all", 9, 0.9, 0.8, 3.3, 0.11, 1]], sigma_p0=0.5)
    assert np.all(tight <= b + 1e-12) and tight.mean() < b.mean()
    huge = traced_pcrlb(rows=[["all", 9, 1e6, 1e6, 1e9, 1e9, 1]], sigma_p0=0.5)
    dr = drive_pcrlb(setup, np.zeros((len(b), 2, 2)), sigma_p0=0.5)
    np.testing.assert_allclose(huge, dr, rtol=1e-6)
    with pytest.raises(ValueError, match="rows"):
        traced_pcrlb(rows=[["los", 9, 9.0, 8.0, 33.0, 1.1, 1]])
    with pytest.raises(ValueError, match="rows"):
        traced_pcrlb(rows=[["all", 9, 0.0, 8.0, 33.0, 1.1, 1]])
    with pytest.raises(TypeError, match="scenario"):
        traced_pcrlb(3)
    with pytest.raises(TypeError, match="array"):
        traced_pcrlb(array=4)
    with pytest.raises(ValueError, match="array"):
        traced_pcrlb(array="4y4")


def test_the_traced_pcrlb_with_a_cars_odometry():
    """With the odometry's repeating errors as states the traced bound is the design's drive
    bound with that model, and a car's odometry allows less than the paper's white messages
    (the same sigmas, a known start); without paths it is dead reckoning's bound."""
    from tunnelkit.design import DesignSetup, drive_pcrlb
    from tunnelkit.odometry import AUTOMOTIVE
    from tunnelkit.studies.traced_bound import traced_pcrlb

    rows = [["all", 9, 9.0, 8.0, 33.0, 1.1, 1]]
    white = traced_pcrlb(rows=rows, sigma_p0=1e-3)
    car = traced_pcrlb(rows=rows, sigma_p0=1e-3, odometry=AUTOMOTIVE)
    assert np.all(car >= white - 1e-12) and car.mean() > 1.5 * white.mean()
    setup = DesignSetup.from_scenario("italiano2026-straight")
    huge = traced_pcrlb(
        rows=[["all", 9, 1e6, 1e6, 1e9, 1e9, 1]], sigma_p0=1e-3, odometry=AUTOMOTIVE
    )
    dr = drive_pcrlb(setup, np.zeros((len(car), 2, 2)), sigma_p0=1e-3, odometry=AUTOMOTIVE)
    np.testing.assert_allclose(huge, dr, rtol=1e-6)
    with pytest.raises(TypeError, match="odometry"):
        traced_pcrlb(rows=rows, odometry="automotive")


def test_the_line_of_sight_study_picks_without_truth_and_its_information_is_the_angles():
    """:mod:`tunnelkit.studies.los_only`: the path taken for the line of sight is the lowest in
    elevation among the arrivals within the window of the earliest (the ceiling's image lies
    above it); a drive keeps one path per epoch and nothing else changes; the angles' position
    information equals J^T J / sigma^2 with J by central differences."""
    from dataclasses import replace as dc_replace

    from tunnelkit.design.los import los_angle_information, los_only, los_path

    d = np.array([10.40, 10.12, 10.05, 14.0])
    psi = np.array([-0.30, 0.20, 0.10, -0.50])
    assert los_path(d, psi) == 2  # within 0.3 m of the earliest: 10.05 and 10.12; 10.40 is not
    assert los_path(d, psi, window=0.0) == 2 and los_path(d, psi, window=0.3) == 2
    assert los_path(d, psi, window=0.4) == 0 and los_path(d, psi, window=5.0) == 3
    with pytest.raises(ValueError, match="d"):
        los_path([], [])
    with pytest.raises(ValueError, match="psi"):
        los_path(d, psi[:2])
    # a drive: one path per epoch, the chosen one, everything else the same
    from tunnelkit.simulation import simulate_drive

    drive = simulate_drive("italiano2026-straight", np.random.default_rng(2), extraction="ml",
                           n_epochs=4)  # fmt: skip
    one = los_only(drive)
    for a, b in zip(drive.epochs, one.epochs, strict=True):
        assert (a is None) == (b is None)
        if a is not None:
            assert len(b) == 1 and b.d[0] == a.d[los_path(a.d, a.psi)]
    np.testing.assert_array_equal(one.speed, drive.speed)
    assert los_only(dc_replace(drive, epochs=[None] * len(drive.epochs))).epochs[0] is None
    with pytest.raises(ValueError, match="window"):
        los_only(drive, window=-1.0)
    # the information against central differences of the two angles
    bs = np.array([0.0, 0.0, 6.0])
    ue = np.array([[20.0, -1.5, 1.5], [5.0, 2.0, 1.5], [-40.0, 0.5, 1.5]])
    sigma = np.radians(1.0)

    def angles(p):
        v = p - bs
        return np.array([np.arctan2(v[1], v[0]), np.arctan2(v[2], np.hypot(v[0], v[1]))])

    info = los_angle_information(ue, bs, sigma)
    for k, p in enumerate(ue):
        J = np.empty((2, 2))
        for j in range(2):
            h = np.zeros(3)
            h[j] = 1e-6
            J[:, j] = (angles(p + h) - angles(p - h)) / 2e-6
        np.testing.assert_allclose(info[k], J.T @ J / sigma**2, rtol=1e-6)
        # separate sigmas: J^T R^-1 J with R = diag(sigma_az^2, sigma_el^2)
        R = np.diag([sigma**2, (1.8 * sigma) ** 2])
        two = los_angle_information(ue, bs, sigma, 1.8 * sigma)[k]
        np.testing.assert_allclose(two, J.T @ np.linalg.inv(R) @ J, rtol=1e-6)
    with pytest.raises(ValueError, match="ue"):
        los_angle_information(np.array([[0.0, 0.0, 1.0]]), bs, sigma)
    with pytest.raises(ValueError, match="sigma_elevation"):
        los_angle_information(ue, bs, sigma, 4.0)


def test_the_flagged_line_of_sight_is_the_picked_path_unless_the_fit_flags_it():
    """``flagged_los``: the path ``los_path`` takes among the epoch's ML measurements, or none
    where the fit puts that path in its threshold region (its own verdict, no truth)."""
    from dataclasses import replace as dc_replace

    from tunnelkit.design.los import los_path
    from tunnelkit.simulation.drives import scenario_route
    from tunnelkit.studies.los_only import flagged_los

    route = scenario_route("italiano2026-straight")
    ep = route.epoch(10, np.random.default_rng(0), refine="ml")
    m = ep.measurements
    keep, why = flagged_los(ep, route)
    j = los_path(m.d, m.psi)
    flags = ep.estimates.below_threshold
    if flags is not None and flags[m.source[j]]:
        assert keep is None and "threshold" in why
    else:
        assert why is None and len(keep) == 1 and keep.d[0] == m.d[j] and keep.psi[0] == m.psi[j]
    flagged = np.zeros(len(ep.estimates.d), bool)
    flagged[m.source[j]] = True
    ep2 = dc_replace(ep, estimates=dc_replace(ep.estimates, below_threshold=flagged))
    none, why = flagged_los(ep2, route)
    assert none is None and "threshold region" in why
    with pytest.raises(TypeError, match=r"^ep"):
        flagged_los("an epoch", route)
    with pytest.raises(ValueError, match="window"):
        flagged_los(ep, route, window=-1.0)


def test_the_line_of_sight_columns_survey_is_the_designs_record_of_the_scenes_array(tmp_path):
    """los_survey reads the array design's record of the preset's array (the shipped 10 x 10 of
    the straight tunnel) and makes the design's table of it; a scene of two array shapes is
    refused naming the scenario; los_note quotes the table and the start;
    a summary without its keys and a table of another type are refused by name."""
    from tunnelkit.design import DesignSetup
    from tunnelkit.design.traced import design_errors
    from tunnelkit.design.tracedlos import los_table
    from tunnelkit.reproduce import javelin_traced as jtr
    from tunnelkit.scenarios import data_dir

    table, summary = jtr.los_survey("italiano2026-straight")
    rec = design_errors(DesignSetup.from_scenario("italiano2026-straight", channel="sionna"),
                        "10x10", measure=False)  # fmt: skip
    want = los_table(rec)
    for k in ("elevation", "sigma_azimuth", "sigma_elevation"):
        np.testing.assert_array_equal(getattr(table, k), getattr(want, k))
    assert summary["path"].endswith("data/rt/design/italiano2026-straight-10x10.json")
    note = jtr.los_note(summary)
    assert "data/rt/design/italiano2026-straight-10x10.json" in note and "0.1 m" in note
    assert f"{summary['table_deg']['sigma_azimuth'][0]:.2f}" in note
    src = (data_dir() / "scenarios" / "italiano2026-straight.toml").read_text()
    two = src.replace("shape = [10, 10]\nazimuth_deg = 0.0", "shape = [8, 8]\nazimuth_deg = 0.0")
    assert two != src
    (tmp_path / "two.toml").write_text(two)
    with pytest.raises(ValueError, match=r"^scenario: .* 2 shapes"):
        jtr.los_survey(str(tmp_path / "two.toml"))
    with pytest.raises(ValueError, match=r"^summary: .*missing"):
        jtr.los_note({"path": "x"})
    with pytest.raises(TypeError, match=r"^table: "):
        jtr.los_drive(None, table.as_dict())
