import numpy as np
import pytest
from javelin_geometric import geometric_stream, toy_drive, toy_reflectors

from tunnelkit import simulation as ex
from tunnelkit.plots.javelin import (
    epoch_figure,
    javelin_table_figure,
    tracks_count_figure,
    trajectories_figure,
)
from tunnelkit.reproduce.javelin_tables import (
    COLUMNS,
    collect_routes,
    javelin_table,
    seed_note,
    table_rows,
)
from tunnelkit.tracking.javelin import designs
from tunnelkit.tracking.javelin.measured import design_from_errors
from tunnelkit.widgets.javelin import epoch_explorer, epoch_view

BS = np.array([0.0, 0.0, 4.8])


def _fake_drive(cond="L", n=40, seed=0):
    """A DriveData from the geometric test source (no signal route)."""
    rng = np.random.default_rng(seed)
    c = ex.CONDITIONS[cond]
    P, V = toy_drive(n, 0.1, amplitude=0.8, speed=5.0)
    eps = geometric_stream(
        P,
        V,
        toy_reflectors(),
        rng,
        los_probability=c.los_probability,
        bs=BS,
        sigma_phi=0.02,
        sigma_psi=0.02,
        sigma_kappa=1.0,
        sigma_d=0.3,
        sigma_v=0.05,
        clock_bias=lambda r: r.normal(0, 3.0),
    )
    planes = toy_reflectors()
    src = [np.vstack([p] + [pl.mirror(p) for pl in planes]) for p in P]
    return ex.DriveData(
        "toy",
        c,
        np.arange(n) * 0.1,
        P,
        V,
        np.linalg.norm(V[:, :2], axis=1),
        np.arctan2(V[:, 1], V[:, 0]),
        eps,
        np.full(n, c.los_probability == 1.0),
        np.full(n, 5),
        BS,
        sources=src,
    )


def test_error_metrics():
    est = np.array([[3.0, 4.0, 9.0], [0.0, -1.0, 0.0]])
    m = ex.error_metrics(est, np.zeros((2, 3)))
    assert m["rmse_2d_m"] == pytest.approx(np.sqrt((25 + 1) / 2))
    assert m["mae_2d_m"] == pytest.approx(3.0) and m["y_mae_m"] == pytest.approx(2.5)


def test_evaluate_tables_and_ablation_on_toy_drives():
    drives = {"L": [_fake_drive("L")], "N": [_fake_drive("N", seed=1)]}
    ev = ex.evaluate(drives["L"][0], designs.ours())
    assert ev.metrics["rmse_2d_m"] < 0.5
    tf = ex.evaluate(drives["L"][0], method="TeNFiLoc")
    assert np.all(np.isfinite(tf.estimates))
    # the table: one column per (route, design), the paper's number last
    routes = {"paper": drives, "ml": {c: [_fake_drive(c, seed=5)] for c in drives}}
    cols, rows = table_rows(routes, "italiano2026_table1")
    assert cols == ["configuration", "metric", *(c[0] for c in COLUMNS), "paper"]
    at = {(r[0], r[1]): r for r in rows}
    assert [r[0] for r in rows[::3]] == [
        "JAVELIN-L", "JAVELIN-N", "TeNFiLoc-L", "dead reckoning-L", "dead reckoning-N"
    ]  # the paper's order, then the baselines  # fmt: skip
    row = at[("JAVELIN-L", "rmse_2d_m")]
    assert row[-1] == pytest.approx(0.20)
    assert row[2] == pytest.approx(
        ev_paper := ex.evaluate(drives["L"][0], designs.paper()).metrics["rmse_2d_m"]
    )
    assert row[3] == pytest.approx(
        ex.evaluate(routes["ml"]["L"][0], designs.paper()).metrics["rmse_2d_m"]
    )
    ml0 = routes["ml"]["L"][0]
    assert row[4] == pytest.approx(ex.evaluate(ml0, designs.paper_vue()).metrics["rmse_2d_m"])
    assert row[5] == pytest.approx(ex.evaluate(ml0, designs.ours_ml()).metrics["rmse_2d_m"])
    assert ev_paper != row[3]
    tf = at[("TeNFiLoc-L", "y_mae_m")]
    assert tf[2] == pytest.approx(ex.evaluate(drives["L"][0], method="TeNFiLoc").metrics["y_mae_m"])
    assert tf[3] == pytest.approx(ex.evaluate(ml0, method="TeNFiLoc").metrics["y_mae_m"])
    assert tf[4] is None and tf[5] is None  # TeNFiLoc: in the paper design's columns only
    # a coherent route adds its column; a missing route drops its columns
    cols3, _ = table_rows({**routes, "coherent": drives}, "italiano2026_table1")
    assert cols3[-2] == "our design, coherent route"
    cols4, _ = table_rows({"paper": drives}, "italiano2026_table1")
    assert cols4 == ["configuration", "metric", "paper design, paper route", "paper"]
    with pytest.raises(ValueError, match=r"^routes"):
        table_rows({"x": drives}, "italiano2026_table1")
    acols, arows = ex.ablation(drives)
    assert acols == ["design", "L", "N"] and len(arows) == len(ex.ablation_path())
    _, arows2 = ex.ablation(drives, separated=drives, ml=routes["ml"])
    assert len(arows2) == len(ex.ablation_path()) + 5
    expect = ex.evaluate(drives["L"][0], designs.ours_coherent()).metrics["rmse_2d_m"]
    assert arows2[-5][1] == pytest.approx(arows[-1][1]) and arows2[-4][1] == pytest.approx(expect)
    assert [r[1] for r in arows2[-3:]] == pytest.approx(row[3:6])
    with pytest.raises(ValueError, match=r"^method"):
        ex.evaluate(drives["L"][0], method="UKF")


def test_dead_reckoning_rows_drop_every_measurement_and_give_the_radio_s_gain():
    """Each condition's baseline row: the column's JAVELIN on the same drive, start and V2X
    messages with every measurement dropped; it does not depend on what the radio measured,
    and the report's gain is its RMSE over JAVELIN's."""
    from dataclasses import replace

    from tunnelkit.reproduce.javelin_tables import DEAD_RECKONING, radio_gains

    drive = _fake_drive("L")
    routes = {"paper": {"L": [drive]}, "ml": {"L": [drive]}}
    cols, rows = table_rows(routes, "italiano2026_table1")
    at = {(r[0], r[1]): r for r in rows}
    dr = at[(f"{DEAD_RECKONING}-L", "rmse_2d_m")]
    alone = replace(drive, epochs=[None] * len(drive.epochs))
    assert dr[2] == pytest.approx(ex.evaluate(alone, designs.paper()).metrics["rmse_2d_m"])
    assert dr[-1] is None  # the paper shows no dead reckoning
    # the radio's measurements do not reach it: other measurements, the same baseline
    other = replace(drive, epochs=_fake_drive("L", seed=9).epochs)
    _, rows2 = table_rows({"paper": {"L": [other]}}, "italiano2026_table1")
    assert {(r[0], r[1]): r for r in rows2}[(f"{DEAD_RECKONING}-L", "rmse_2d_m")][2] == dr[2]
    gains = radio_gains(cols, rows)
    jav = at[("JAVELIN-L", "rmse_2d_m")]
    assert set(gains) == {"JAVELIN-L"}
    for label, v, b in zip(cols[2:-1], jav[2:-1], dr[2:-1], strict=True):
        assert gains["JAVELIN-L"][label] == pytest.approx(b / v)
    assert all(np.isfinite(g) and g > 0 for g in gains["JAVELIN-L"].values())


def test_mirror_prediction_is_exact_for_planar_vues():
    d = _fake_drive("L")
    assert (
        np.median(ex.vue_prediction_errors(d, "mirror")) < 0.01
    )  # only the O(a dt^2) of a curved path
    assert np.median(ex.vue_prediction_errors(d, "random_walk")) > 0.05


def test_figures_and_explorer():
    d = _fake_drive("L", n=15)
    ev = ex.evaluate(d, designs.ours(), keep_reports=True)
    fig = epoch_figure(ev.run.reports[5], truth=d.truth[5], base_station=BS, true_vues=d.sources[5])
    assert len(fig.data) > 5 and "epoch 5" in fig.layout.title.text
    assert len(epoch_figure(ev.run.reports[5], plane="xy").data) > 3
    assert len(trajectories_figure(d.truth, {"JAVELIN": ev.estimates}, base_station=BS).data) == 3
    assert len(tracks_count_figure(d.t, ev.run.n_tracks, d.los).data) == 2
    assert javelin_table_figure(["a", "b"], [["x", 1.234], ["y", None]]).data[0].cells.values[
        1
    ] == ["1.23", "-"]
    exp = epoch_explorer(d, ev, k=2)
    exp.set(k=7)
    assert "epoch 7" in exp.figure.layout.title.text
    with pytest.raises(ValueError, match=r"^evaluation"):
        epoch_view(d, ex.evaluate(d, designs.ours()), 0)


def test_signal_route_drive_two_epochs():
    d = ex.simulate_drive(
        "italiano2026-straight", np.random.default_rng(3), condition="N", n_epochs=2
    )
    assert len(d.epochs) == 2 and not d.los.any()
    assert all(e is None or np.all(np.isfinite(e.phi)) for e in d.epochs)
    assert np.allclose(d.base_station, [0.0, 0.0, 4.75])  # reference antenna, 5 cm below the BS
    with pytest.raises(ValueError, match=r"^condition"):
        ex.simulate_drive(
            "italiano2026-straight", np.random.default_rng(0), condition="X", n_epochs=1
        )
    with pytest.raises(ValueError, match=r"^extraction"):
        ex.simulate_drive(
            "italiano2026-straight", np.random.default_rng(0), condition="L", extraction="x"
        )


def test_separated_drive_uses_the_same_tensors():
    """Same seed, both routes: identical truth and V2X; where the CPD kept every path and the
    separation changes nothing, identical measurements; the separated route loses no path."""
    kw = {"n_epochs": 3}
    a = ex.simulate_drive("italiano2026-straight", np.random.default_rng(5), condition="L", **kw)
    b = ex.simulate_drive(
        "italiano2026-straight",
        np.random.default_rng(5),
        condition="L",
        extraction="separated",
        **kw,
    )
    assert a.extraction == "paper" and b.extraction == "coherent"  # the route's name now
    # one pass through both routes (one synthesis and CPD per epoch) gives the same drives
    both = ex.simulate_routes(
        "italiano2026-straight", np.random.default_rng(5), condition="L", **kw
    )
    assert list(both) == ["paper", "coherent", "ml"]
    for one, shared in ((a, both["paper"]), (b, both["coherent"])):
        assert shared.extraction == one.extraction
        np.testing.assert_array_equal(shared.speed, one.speed)
        for m1, m2 in zip(one.epochs, shared.epochs):
            np.testing.assert_array_equal(m1.phi, m2.phi)
            np.testing.assert_array_equal(m1.d, m2.d)
        assert [t.tolist() for t in one.truth_index] == [t.tolist() for t in shared.truth_index]
    np.testing.assert_array_equal(a.speed, b.speed)
    np.testing.assert_array_equal(a.los, b.los)
    matched = [int(np.sum(t >= 0)) for t in b.truth_index]
    assert matched == [len(s) for s in b.sources]  # every true path found in every epoch
    assert sum(matched) >= sum(int(np.sum(t >= 0)) for t in a.truth_index)
    cols, rows = ex.path_errors([a])
    found = {r[0]: r for r in rows}
    assert cols[:3] == ["path", "true", "found"] and found["los"][1] == 3
    _, rows_b = ex.path_errors([b])
    best = {r[0]: r for r in rows_b}
    assert best["los"][2] == 3 and best["los"][3] < found["los"][3]  # LoS: found, and sharper
    assert best["no true path"][2] == 0
    # the ML route on the same tensors: every path found, curvature usable (the UE/VUE range
    # within a metre at 44 m), the LoS direction sharper than the coherent split's
    ml = both["ml"]
    np.testing.assert_array_equal(ml.speed, a.speed)
    # the ML route alone (the paper route not run: the ML fit starts from its own CPD): the
    # same draws, tensors and measurements
    alone = ex.simulate_routes(
        "italiano2026-straight", np.random.default_rng(5), condition="L", extractions=("ml",), **kw
    )["ml"]
    for f in ("speed", "heading", "los", "n_true"):
        np.testing.assert_array_equal(getattr(alone, f), getattr(ml, f))
    assert alone.faults == ml.faults and len(alone.epochs) == len(ml.epochs)
    for m1, m2 in zip(alone.epochs, ml.epochs, strict=True):
        for f in ("phi", "psi", "kappa", "d", "v", "source"):
            np.testing.assert_array_equal(getattr(m1, f), getattr(m2, f))
    assert [t.tolist() for t in alone.truth_index] == [t.tolist() for t in ml.truth_index]
    assert [int(np.sum(t >= 0)) for t in ml.truth_index] == [len(s) for s in ml.sources]
    ecols, erows = ex.extraction_errors([ml])
    err = {r[0]: dict(zip(ecols, r)) for r in erows}
    assert err["all"]["matched"] == sum(len(s) for s in ml.sources)
    assert err["los"]["kappa [m]"] < 1.0 and err["all"]["no kappa"] == 0
    _, erows_b = ex.extraction_errors([b])
    los_b = {r[0]: r for r in erows_b}["los"]
    assert err["los"]["phi [deg]"] < los_b[2] and err["los"]["kappa [m]"] < los_b[4]
    cfg = design_from_errors(erows)
    assert cfg.config.sigma_kappa == pytest.approx(err["all"]["kappa [m]"])
    assert cfg.config.sigma_phi == pytest.approx(np.radians(err["all"]["phi [deg]"]))
    assert cfg.curvature == designs.ours_coherent().curvature
    assert cfg.associator == designs.ours_coherent().associator
    with pytest.raises(ValueError, match=r"^drives"):
        ex.extraction_errors([])


def test_collect_routes_runs_through_run_trials_with_the_condition_per_child():
    out = collect_routes(
        "italiano2026-straight", ("L", "N"), 1, 3, n_epochs=1, extractions=("paper",)
    )
    assert list(out) == ["paper"] and [len(v) for v in out["paper"].values()] == [1, 1]
    assert out["paper"]["L"][0].los.all() and not out["paper"]["N"][0].los.any()
    # drive i draws from child i of the seed: the N drive is child 1
    rng = np.random.default_rng(np.random.SeedSequence(3).spawn(2)[1])
    d = ex.simulate_drive("italiano2026-straight", rng, condition="N", n_epochs=1)
    np.testing.assert_array_equal(d.speed, out["paper"]["N"][0].speed)
    with pytest.raises(ValueError, match=r"^extraction"):
        collect_routes("italiano2026-straight", ("L",), 1, 0, n_epochs=1, extractions=("x",))
    rep = javelin_table(
        "italiano2026-straight", "italiano2026_table1", ("L",), 1, 3, False, ("paper",), 1
    )
    assert rep.columns == ["configuration", "metric", "paper design, paper route", "paper"]
    assert [r[0] for r in rep.rows] == ["JAVELIN-L"] * 3 + ["TeNFiLoc-L"] * 3 + [
        "dead reckoning-L"
    ] * 3
    assert rep.meta["extraction_failures"] == {"paper": 0} and rep.notes


def test_vue_prediction_skips_the_los_only_when_it_exists():
    # epoch k + 1 without LoS: its first source is a VUE and must stay among the candidates
    d = _fake_drive("L")
    full = ex.vue_prediction_errors(d, "mirror")
    odd = np.arange(d.t.size) % 2 == 1
    d.los = ~odd
    d.sources = [s[1:] if o else s for s, o in zip(d.sources, odd)]
    e = ex.vue_prediction_errors(d, "mirror")
    assert e.size == 4 * int(np.sum(d.los[:-1]))  # 4 VUEs per epoch k with a LoS
    assert np.max(e) < 0.05 and np.max(e) <= np.max(full) + 1e-12


def test_ablation_path_goes_from_the_paper_design_to_ours_one_change_at_a_time():
    cfgs = list(ex.ablation_path().values())
    assert cfgs[0] == designs.paper() and cfgs[-1] == designs.ours()
    assert len(set(map(repr, cfgs))) == len(cfgs)  # every step changes something


def test_table_and_ablation_progress_bars_change_no_number(capsys):
    """The bars over the scored drives leave every number as it is."""
    drives = {"L": [_fake_drive("L"), _fake_drive("L", seed=2)], "N": [_fake_drive("N", seed=1)]}
    routes = {"paper": drives, "ml": {c: [_fake_drive(c, seed=5)] for c in drives}}
    quiet = table_rows(routes, "italiano2026_table1")
    shown = table_rows(routes, "italiano2026_table1", progress=True)
    assert "scoring drives" in capsys.readouterr().err
    assert shown == quiet
    a_quiet = ex.ablation(drives, ml=routes["ml"])
    a_shown = ex.ablation(drives, ml=routes["ml"], progress=True)
    assert "ablation" in capsys.readouterr().err
    assert a_shown == a_quiet
    assert a_quiet[1][0][1] == pytest.approx(
        np.mean([ex.evaluate(d, designs.paper()).metrics["rmse_2d_m"] for d in drives["L"]])
    )


def test_table_scored_on_the_workers_equals_table_rows_on_the_drives():
    """javelin_table scores each drive inside its trial; the rows are those of table_rows on
    the same drives (same seed), in the same order, to the last bit."""
    args = ("italiano2026-straight", ("L", "N"), 2, 11)
    routes = collect_routes(*args, n_epochs=2, extractions=("paper", "ml"))
    cols, rows = table_rows(routes, "italiano2026_table1")
    rep = javelin_table(
        "italiano2026-straight", "italiano2026_table1", ("L", "N"), 2, 11, False, ("paper", "ml"), 2
    )
    assert rep.columns == cols and rep.rows == rows
    assert rep.meta["seed"] == 11 and seed_note(11) in rep.notes
    faults = {e: sum(len(d.faults) for lst in r.values() for d in lst) for e, r in routes.items()}
    assert rep.meta["extraction_failures"] == faults


def test_a_table_says_whether_its_seed_was_held_out():
    """The report names its seed's kind: our design scored on a tuning seed is not held out."""
    assert ex.HELD_OUT_SEED not in ex.TUNING_SEEDS
    assert "the held-out seed: no design choice" in seed_note(ex.HELD_OUT_SEED)
    for s in ex.TUNING_SEEDS:
        note = seed_note(s)
        assert "a tuning seed" in note and f"--seed {ex.HELD_OUT_SEED}" in note
    assert "neither a tuning seed" in seed_note(11)
    with pytest.raises(TypeError):
        seed_note("0")
