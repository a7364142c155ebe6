"""Each bad input of the fifth round of outside probes, exactly as reported: refused with the
parameter named (or a documented, physically right result: an infinite bound, a capped
count)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import tunnelkit as tk

NAN, INF = float("nan"), float("inf")


def _raises(exc, match, fn, *a, **kw):
    with pytest.raises(exc, match=match):
        fn(*a, **kw)


# --- physically impossible results --------------------------------------------------------------


def test_extract_paths_with_fc_in_ghz():
    _raises(ValueError, r"^fc: .*did you mean 28e9", tk.channel.SRSConfig, fc=28.0)


def test_symbol_period_far_below_physical():
    # the symbol period is 1/scs: a 1e-300 s period is a subcarrier spacing of 1e300 Hz
    _raises(ValueError, r"^(scs|n_rb)", tk.channel.SRSConfig, scs=1e300)


@pytest.mark.parametrize("bw_fc", [(200e6, 100e6), (100e6, 50e6)])
def test_a_band_reaching_zero_hz_in_designsetup(bw_fc):
    bw, fc = bw_fc
    setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    with pytest.raises(ValueError, match=r"bandwidth|fc"):
        setup.variant(fc=fc, bandwidth=bw)


def test_a_band_reaching_zero_hz_in_a_scenario_file():
    sc = tk.load_scenario("italiano2026-straight")
    with pytest.raises((ValueError, tk.scenarios.ScenarioError), match=r"bandwidth|fc"):
        bad = tk.scenarios.with_values(sc, {"radio.fc": 100e6, "radio.bandwidth": 400e6})
        tk.channel.SRSConfig.from_scenario(bad)


# --- silent acceptance at the lower layers ------------------------------------------------------


def test_virtual_stations_with_the_base_station_outside(jiang):
    tunnel = jiang["tunnel"]
    outside = tunnel.from_tunnel_frame(np.array([10.0, tunnel.width + 5.0]))
    _raises(ValueError, r"^base_station", tunnel.virtual_stations, outside)


def test_toa_only_candidates_with_negative_ranges():
    st = np.array([[0.0, 0.0], [0.0, 10.0]])
    _raises(ValueError, r"^d_hat", tk.positioning.toa_only_candidates, st, np.array([-5.0, 8.0]))


def test_vsmodel_los_not_a_bool():
    import dataclasses

    from tunnelkit.tracking.virtual_station import model_from_scenario

    model = model_from_scenario("jiang2023-straight")
    with pytest.raises(TypeError, match=r"^los"):
        dataclasses.replace(model, los="no")


def test_toy_drive_negative_count():
    from javelin_geometric import toy_drive

    _raises(ValueError, r"^n", toy_drive, -5, 0.1)


def test_numeric_jacobian_of_a_nan_function():
    _raises(ValueError, r"^h", tk.crlb.numeric_jacobian, lambda x: x * NAN, np.array([1.0, 2.0]))


@pytest.mark.parametrize(
    "call",
    [
        lambda: tk.extraction.crlb_paths(
            np.array([1.0 + 0j]),
            np.array([[0.1, 0.1, 0.2]]),
            np.zeros((4, 3)) + np.arange(4)[:, None] * [0.025, 0, 0],
            mu_f=np.array([0.1]),
            mu_t=np.array([0.0]),
            fc=5.9e9,
            n_tones=0,
            n_symbols=2,
            noise_power=1.0,
        ),
    ],
)
def test_crlb_with_no_tones(call):
    with pytest.raises(ValueError, match=r"^n_tones"):
        call()


def test_vandermonde_roots_of_an_empty_or_zero_factor():
    from tunnelkit.extraction import vandermonde_roots

    _raises(ValueError, r"^B", vandermonde_roots, np.zeros((0, 2), complex))
    _raises(ValueError, r"^B", vandermonde_roots, np.zeros((4, 2), complex))


@pytest.mark.parametrize("shape", [(-4, 3, 2), ((4, 3), (2, 2))])
def test_rank_checks_on_negative_or_2d_shapes(shape):
    from tunnelkit.extraction import check_rank, max_identifiable_rank

    _raises((ValueError, TypeError), r"^shape", max_identifiable_rank, shape)
    _raises((ValueError, TypeError), r"^shape", check_rank, shape, 2)


def test_split_component_with_no_sources():
    from tunnelkit.extraction.coherent import split_component

    p = np.arange(4)[:, None] * np.array([0.025, 0.0, 0.0])
    b = np.ones(4, complex)
    _raises(
        ValueError, r"^max_sources", split_component, b, (0.1, 0.1, 0.1), p, 5.9e9, max_sources=0
    )


def test_spherical_steering_at_zero_carrier():
    from tunnelkit.extraction.coherent import spherical_steering

    p = np.arange(4)[:, None] * np.array([0.025, 0.0, 0.0])
    _raises(ValueError, r"^fc", spherical_steering, np.array([[1.0, 2.0, 5.0]]), p, 0.0)


def test_plots_refuse_series_of_different_lengths():
    _raises(
        ValueError,
        r"series|x",
        tk.plots.line_figure,
        np.arange(5.0),
        {"a": np.arange(4.0)},
    )


def test_smallest_meeting_with_a_nan_target():
    setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    _raises(ValueError, r"^target", tk.design.smallest_meeting, setup, ["4x4"], target=NAN)


def test_format_bytes_of_nan():
    _raises(ValueError, r"^n", tk.sizes.format_bytes, NAN)


@pytest.mark.parametrize(
    "gain_db",
    [200.0, INF],
)
def test_calibration_gains_out_of_range(gain_db):
    _raises(
        ValueError,
        r"^gain_sigma_db",
        tk.calibration.draw_calibration,
        np.random.default_rng(0),
        4,
        gain_sigma_db=gain_db,
    )


# --- crashes, hangs, memory ---------------------------------------------------------------------


def test_draw_calibration_beyond_the_memory_budget():
    _raises(ValueError, r"^m", tk.calibration.draw_calibration, np.random.default_rng(0), 10**12)


def test_drive_config_beyond_the_memory_budget():
    _raises(
        ValueError, r"duration|spacing", tk.doppler_drive.DriveConfig, duration=1e6, spacing=1e-3
    )


def test_crlb_map_beyond_the_memory_budget(jiang):
    from tunnelkit.widgets.crlb import crlb_map

    _raises(
        ValueError,
        r"n_along|n_across",
        crlb_map,
        jiang["tunnel"],
        jiang["vs"],
        0.01,
        0.5,
        n_along=10**5,
        n_across=10**4,
    )


def test_ml_paths_iteration_cap(epoch):
    H, L, array, srs = epoch
    _raises(ValueError, r"^max_iter", tk.extraction.ml.ml_paths, H, L, array, srs, max_iter=10**7)


def test_polish_sweeps_cap(epoch):
    H, L, array, srs = epoch
    _raises(ValueError, r"^polish", tk.extraction.extract_paths, H, L, array, srs, polish=10**7)


def test_kruskal_rank_of_40_columns_is_bounded():
    from tunnelkit.extraction import kruskal_rank

    B = np.random.default_rng(0).standard_normal((50, 40))
    assert kruskal_rank(B) == 40  # generic columns: full k-rank, found without 2^40 subsets


def test_design_monte_carlo_with_no_epochs():
    setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    # n_epochs=0 is refused at the boundary, before any bound or drive is computed
    _raises(ValueError, r"^n_epochs", tk.design.sweep_montecarlo, setup, "4x4", 2, 0, n_epochs=0)


def test_route_bounds_with_an_epoch_past_the_route():
    setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    _raises(ValueError, r"^epochs", tk.design.route_bounds, setup, "4x4", epochs=[10**6])


def test_memory_budget_beyond_float_range():
    _raises(ValueError, r"^nbytes", tk.budget.set_memory_budget, 10**400)


def test_deep_dict_is_a_clear_error():
    d: dict = {}
    cur = d
    for _ in range(5000):
        cur["a"] = {}
        cur = cur["a"]
    with pytest.raises((ValueError, tk.scenarios.ScenarioError), match=r"deep|depth|nest"):
        tk.scenarios.scenario_from_dict(d)


def test_deep_toml_is_a_clear_error(tmp_path):
    text = "a = " + "[" * 3000 + "]" * 3000 + "\n"
    f = tmp_path / "deep.toml"
    f.write_text(text)
    with pytest.raises((ValueError, tk.scenarios.ScenarioError), match=r"deep|depth|nest"):
        tk.load_scenario(f)


def test_huge_toml_is_a_clear_error(tmp_path):
    f = tmp_path / "big.toml"
    f.write_text("a = [" + "1," * (20 * 1024 * 1024) + "]\n")
    with pytest.raises((ValueError, tk.scenarios.ScenarioError), match=r"size|large|bytes|MiB"):
        tk.load_scenario(f)


# workers=1000 capped to the machine: tests/test_montecarlo_dask.py (available_cores patched)


def test_crlb_paths_arguments_checked_at_the_boundary():
    p = np.zeros((4, 3)) + np.arange(4)[:, None] * [0.025, 0, 0]
    square = np.array([[0.0, 0.0, 0.0], [0.025, 0.0, 0.0], [0.0, 0.025, 0.0], [0.025, 0.025, 0.0]])
    kw = dict(mu_f=np.array([0.1]), mu_t=np.array([0.0]), fc=5.9e9, n_symbols=2, noise_power=1.0)
    src, alpha = np.array([[0.1, 0.1, 0.2]]), np.array([1.0 + 0j])
    # sources and alpha swapped: the gains' shape is named, not a broadcast error
    _raises(ValueError, r"^alpha", tk.extraction.crlb_paths, src, alpha, p, n_tones=4, **kw)
    # one tone: the delay is unidentifiable (the bound would be NaN)
    _raises(ValueError, r"^n_tones", tk.extraction.crlb_paths, alpha, src, p, n_tones=1, **kw)
    # a line array cannot place a wave origin in 3-D, a zero gain carries no information: the
    # bound is infinite (it was a LinAlgError and NaN)
    for pos, a in ((p, alpha), (square, 0.0 * alpha)):
        out = tk.extraction.crlb_paths(a, src, pos, n_tones=4, **kw)
        assert np.all(np.isinf(out["mu_f"])) and np.all(np.isinf(out["source_cov"]))
    out = tk.extraction.crlb_paths(alpha, src, square, n_tones=4, **kw)
    assert np.all(np.isfinite(out["mu_f"])) and np.all(out["mu_f"] > 0)
    assert np.all(np.linalg.eigvalsh(out["source_cov"]) > 0)


# --- the items without a test in round two ------------------------------------------------------


@pytest.fixture(scope="module")
def javelin_tunnel():
    from tunnelkit.propagation import semicircular_tunnel

    return semicircular_tunnel(length=100.0, width=10.0, height=5.0)


def _array(origin, fc=5.9e9):
    return tk.arrays.make_array(
        4, 4, fc=fc, azimuth=0.0, elevation=-np.pi / 2, origin=np.asarray(origin, float)
    )


@pytest.mark.parametrize(
    "origin",
    [
        [0.0, 6.0, 2.0],  # inside the wall (|y| > 5)
        [0.0, 0.0, -0.5],  # below the road
        [80.0, 0.0, 2.0],  # beyond the tunnel's end
    ],
)
def test_trace_paths_with_the_array_outside_the_tunnel(javelin_tunnel, origin):
    from tunnelkit.propagation import trace_paths

    _raises(
        ValueError,
        r"^array",
        trace_paths,
        javelin_tunnel,
        _array(origin),
        [10.0, 1.0, 1.5],
        fc=5.9e9,
    )


def test_trace_paths_with_the_array_at_the_ue(javelin_tunnel):
    from tunnelkit.propagation import trace_paths

    arr = _array([10.0, 1.0, 1.5])
    _raises(ValueError, r"^ue", trace_paths, javelin_tunnel, arr, [10.0, 1.0, 1.5], fc=5.9e9)
    # a wavelength away is fine: paths come back
    paths = trace_paths(javelin_tunnel, _array([0.0, 0.0, 4.5]), [10.0, 1.0, 1.5], fc=5.9e9)
    assert paths and paths[0].kind == "los"


def test_trace_paths_with_a_blocker_enclosing_the_array(javelin_tunnel):
    from tunnelkit.propagation import Box, trace_paths

    tun = javelin_tunnel.with_blockers(Box(np.array([-1.0, -1, 4]), np.array([1.0, 1, 4.9])))
    _raises(
        ValueError, r"^array", trace_paths, tun, _array([0.0, 0.0, 4.5]), [10.0, 1, 1.5], fc=5.9e9
    )


def test_scenario_with_a_blocker_enclosing_the_base_station():
    sc = tk.load_scenario("italiano2026-straight")
    bs = np.asarray(sc.get("base_station.position"), float)
    box = {"lo": (bs - 0.5).tolist(), "hi": (bs + 0.2).tolist(), "name": "crate"}
    with pytest.raises(tk.scenarios.ScenarioError, match=r"blockers\[0\].*base_station"):
        tk.scenarios.with_values(sc, {"tunnel.blockers": [box]})


def test_scenario_with_two_arrays_of_the_same_name():
    sc = tk.load_scenario("italiano2026-straight")
    arr = dict(sc.raw["base_station"]["arrays"][0], name="north")
    with pytest.raises(tk.scenarios.ScenarioError, match=r"arrays\[1\]\.name.*distinct"):
        tk.scenarios.with_values(sc, {"base_station.arrays": [arr, dict(arr)]})


def test_signal_route_with_two_arrays_of_the_same_name():
    import dataclasses

    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight")
    a = route.arrays[0]
    with pytest.raises(ValueError, match=r"^arrays: .*both named"):
        dataclasses.replace(route, arrays=[a, a])


@pytest.mark.parametrize(
    "profile",
    [
        [(5, 0), (5, 5), (0, 2), (-5, 5), (-5, 0)],  # concave: the roof folds down
        [(5, 0), (-5, 5), (5, 5), (-5, 0)],  # self-intersecting: the roof crosses itself
        [(5, 0), (5, 5), (-5, 5), (-5, 2), (-4, 3), (-5, 0)],  # a dent in the left wall
    ],
)
def test_extruded_tunnel_refuses_a_concave_or_crossed_profile(profile):
    from tunnelkit.tunnels import extruded_tunnel

    names = [f"f{i}" for i in range(len(profile) - 1)]
    _raises(ValueError, r"^profile: .*convex", extruded_tunnel, profile, names, length=100.0)


def test_extruded_tunnel_keeps_convex_profiles():
    from tunnelkit.tunnels import extruded_tunnel, make_tunnel

    tun = extruded_tunnel([(5, 0), (5, 3), (5, 5), (-5, 5), (-5, 0)], list("abcd"), length=50.0)
    assert len(tun.facets) == 5  # collinear wall edges allowed, plus the road
    for shape in ("rectangular", "horseshoe", "semicircular"):
        make_tunnel(shape, width=8.0, height=6.0, length=100.0)


def test_design_cli_bandwidth_beyond_the_memory_budget(capsys):
    from tunnelkit import cli

    argv = ["design", "italiano2026-straight", "--arrays", "16x16", "--fc", "100GHz"]
    rc = cli.main([*argv, "--bandwidth", "100GHz", "--runs", "2", "--mode", "channel"])
    assert rc != 0
    assert re.search(r"bandwidth: would need .* memory budget", capsys.readouterr().err)
    # and below 0 Hz: refused with the band named
    rc = cli.main(["design", "italiano2026-straight", "--arrays", "4x4", "--bandwidth", "100GHz"])
    assert rc != 0
    assert "bandwidth" in capsys.readouterr().err


def test_scenarios_new_with_a_300_character_name(tmp_path, capsys):
    from tunnelkit import cli

    rc = cli.main(
        ["scenarios", "new", "a" * 300, "--from", "italiano2026-straight", "--out", str(tmp_path)]
    )
    assert rc != 0
    assert re.search(r"name: 300 characters", capsys.readouterr().err)
    assert not list(tmp_path.iterdir())
    _raises(tk.scenarios.ScenarioError, r"^name: 300", tk.load_scenario, "a" * 300)


# --- the callables that had no valid call in the generated suite --------------------------------


def _joint_fisher_args():
    pos = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0]])
    src = np.array([[0.3, 0.2, 4.0], [-0.5, 0.4, 6.0]])
    return [np.array([1.0 + 0.5j, 0.5j]), src, pos, [-0.7, -1.1], [0.05, -0.02], 4, 3, 0.3, 3.5e9]


def test_joint_fisher_refuses_gains_with_an_extra_axis():
    from tunnelkit.path_consistency import joint_fisher

    args = _joint_fisher_args()
    F = joint_fisher(*args)
    assert F.shape == (14, 14) and np.allclose(F, F.T)
    args[0] = args[0][None, None]
    _raises(ValueError, r"^alpha: expected one complex gain per path", joint_fisher, *args)


@pytest.mark.parametrize(
    "i, value, match",
    [(5, 10**12, r"^n_tones: .*memory budget"), (6, 10**12, r"^n_symbols: .*memory budget"),
     (8, 28.0, r"^fc: .*did you mean 28e9"), (8, 1e300, r"^fc: expected 1e\+08 to 3e\+11 Hz")],
)  # fmt: skip
def test_joint_fisher_bounded_work_and_carrier(i, value, match):
    from tunnelkit.path_consistency import joint_fisher

    args = _joint_fisher_args()
    args[i] = value
    _raises(ValueError, match, joint_fisher, *args)


@pytest.fixture(scope="module")
def ml_epoch():
    import dataclasses

    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight", kinds=("los",))
    cfg = dataclasses.replace(route.config, bandwidth=10e6, n_rb=27, n_symbols=2)
    route = dataclasses.replace(route, config=cfg)
    return route, route.epoch(5, np.random.default_rng(3), refine="ml")


def test_rejudge_refuses_real_tensors_bad_carriers_and_shares(ml_epoch):
    from tunnelkit.signal_route.judging import rejudge

    route, ep = ml_epoch
    H, pos, fc = ep.snapshot.H, ep.array.local, route.config.fc
    assert rejudge(ep.estimates, H, pos, fc, 0.01)["share"] == 0.01
    _raises(TypeError, r"^H: expected a complex", rejudge, ep.estimates, np.abs(H), pos, fc, 0.01)
    _raises(ValueError, r"^fc: .*did you mean 28e9", rejudge, ep.estimates, H, pos, 28.0, 0.01)
    _raises(ValueError, r"^share: .*at most 1", rejudge, ep.estimates, H, pos, fc, 2.0)
    _raises(ValueError, r"^element_positions", rejudge, ep.estimates, H, pos[None], fc, 0.01)
    _raises(ValueError, r"^element_positions", rejudge, ep.estimates, H, pos[:, :2], fc, 0.01)


def test_subset_of_route_measurements_and_apply_budget_check_their_arguments():
    """A row subset of an epoch's measurements keeps the array's position and re-references the
    delay differences to its first row (eq. 52); bad rows are refused naming ``idx``."""
    from tunnelkit.signal_route.judging import apply_budget

    m = tk.signal_route.simulate_epoch("italiano2026-straight", 10, np.random.default_rng(0))
    m = m.measurements
    assert len(m) >= 3
    assert len(m.subset(np.arange(len(m)))) == len(m)
    assert len(m.subset([])) == 0
    tail = m.subset(np.arange(1, len(m)))
    np.testing.assert_array_equal(tail.origin, m.origin)
    np.testing.assert_array_equal(tail.source, m.source[1:])
    assert tail.delta_d[0] == 0.0
    np.testing.assert_allclose(tail.delta_d, m.delta_d[1:] - m.delta_d[1], rtol=0, atol=1e-9)
    _raises(TypeError, r"^idx", m.subset, np.array([0.5]))
    _raises(ValueError, r"^idx", m.subset, [len(m)])
    _raises(TypeError, r"^meas: expected", apply_budget, None, None, 0)


def test_bias_budget_refuses_complex_blocks_and_a_real_mask():
    from tunnelkit.signal_route.judging import BiasBudget

    T, P = 2, 3
    ok = dict(
        source=np.ones((T, P, 3)),
        exists=np.ones((T, P), bool),
        origin=np.zeros((T, 3)),
        extra=np.zeros((T, P, 4, 4)),
        repeating=np.zeros((T, P, 4, 4)),
    )
    b = BiasBudget(**ok)
    assert (b.match(0, np.zeros(0), np.zeros((0, 3))) == -1).all()
    _raises(ValueError, r"d, direction", b.match, 0, np.zeros(0), np.zeros((1, 3)))
    for name in ("source", "origin", "extra", "repeating"):
        _raises(TypeError, rf"^{name}", BiasBudget, **{**ok, name: ok[name] + 0j})
    _raises((TypeError, ValueError), r"^exists", BiasBudget, **{**ok, "exists": np.ones((T, P))})


# --- the items that still passed through at the start of round three ----------------------------


@pytest.mark.parametrize("across", [-3.0, 25.0])
def test_geometry_virtual_stations_with_the_base_station_outside(jiang, across):
    tunnel = jiang["tunnel"]
    inside = tunnel.from_tunnel_frame(np.array([10.0, 0.5 * tunnel.width]))
    vs = tk.tunnel2d.virtual_stations(inside, list(tunnel.walls))
    np.testing.assert_allclose(vs, tunnel.virtual_stations(inside))
    outside = tunnel.from_tunnel_frame(np.array([10.0, across]))
    _raises(ValueError, r"^base_station: .* outside", tk.tunnel2d.virtual_stations, outside,
            list(tunnel.walls))  # fmt: skip


@pytest.mark.parametrize(
    "gains, match",
    [(1e20, r"dB"), (INF, r"NaN or infinite"), (0.0, r"dB"), ("short", r"shape"),
     ("unknown", r"not one of the arrays")],
)  # fmt: skip
def test_signal_route_calibration_gains_out_of_range(gains, match):
    import dataclasses

    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight", kinds=("los",))
    a = route.arrays[0]
    if gains == "short":
        cal = {a.name: np.ones(a.M - 1, complex)}
    elif gains == "unknown":
        cal = {"not-an-array": np.ones(a.M, complex)}
    else:
        cal = {a.name: np.full(a.M, gains, complex)}
    _raises(ValueError, rf"^calibration.*{match}", dataclasses.replace, route, calibration=cal)
    drawn = route.with_impairments(tk.channel.Impairments(1.0, 3.0), np.random.default_rng(0))
    assert set(drawn.calibration) == {x.name for x in route.arrays}


def test_javelin_with_a_vanishing_gate_probability_runs_finite():
    # reported as JavelinConfig(update_gate=1e-300) -> ZeroDivisionError later: the field is
    # gate_probability (eq. 59's p); a gate that small admits almost nothing, and the tracker
    # predicts through it with finite estimates
    from javelin_geometric import geometric_stream, toy_drive, toy_reflectors

    from tunnelkit.tracking.javelin import JavelinConfig, JavelinDesign, run_javelin

    bs = (0.0, 0.0, 4.8)
    P, V = toy_drive(12, 0.1, amplitude=0.5, speed=4.0)
    eps = geometric_stream(P, V, toy_reflectors(), np.random.default_rng(0), bs=bs)
    spd, hdg = np.linalg.norm(V, axis=1), np.arctan2(V[:, 1], V[:, 0])
    cfg = JavelinConfig(base_station=bs, sigma_p0_ue=1.0, gate_probability=1e-300)
    run = run_javelin(eps, spd, hdg, 0.1, P[0], JavelinDesign(cfg))
    assert np.all(np.isfinite(run.estimates))
    _raises(ValueError, r"^gate_probability", JavelinConfig, gate_probability=0.0)


def test_path_crlb_with_one_tone():
    route = tk.signal_route.SignalRoute.from_scenario("italiano2026-straight", kinds=("los",))
    arr, paths = route.paths(10)
    _raises(ValueError, r"^n_tones", tk.extraction.path_crlb, paths, arr, route.config, n_tones=1)
    out = tk.extraction.path_crlb(paths, arr, route.config, n_tones=2)
    assert np.all(np.isfinite(out["d"])) and np.all(out["d"] > 0)


def test_design_cli_with_a_scheduler_that_accepts_and_never_answers(capsys, silent_server):
    import time

    from tunnelkit import cli

    addr, held = silent_server
    argv = ["design", "italiano2026-straight", "--arrays", "4x4", "--runs", "2"]
    t0 = time.perf_counter()
    rc = cli.main([*argv, "--scheduler", f"tcp://{addr}", "--connect-timeout", "2"])
    assert rc != 0 and time.perf_counter() - t0 < 60.0  # it hung past 120 s before
    assert held  # the connection was accepted: the handshake, not the connect, timed out
    assert re.search(r"no Dask scheduler answered .* within 2 s", capsys.readouterr().err)
