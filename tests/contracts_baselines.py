"""Recorded valid calls of the callables no teaching workflow reaches with tiny inputs (the
contract suite, :mod:`contract_values`): the design's sweep, confirmation and channel-route
Monte-Carlo on a two-epoch, 41-tone, LoS-plus-walls setup; the studies and the reproduction
tables on one-epoch drives; the efficiency and RMSE studies on one snapshot; figures, widgets,
tunnels, registries and the ray tracer's engine on small scenes.

Each baseline call is kept well under a second (the suite replays it for every generated case,
in a time box of one second); the first call of each callable is the one recorded, so a driver
calls the inner pieces with their smallest arguments before the workflows that reach them.
"""

from __future__ import annotations

import dataclasses
import importlib
import warnings

import numpy as np

SCENARIO = "italiano2026-straight"
CRLB = {"d": 0.05, "direction": 0.01, "kappa": 2.0}


def tiny_setup():
    """The design setup cut down: 10 MHz (41 tones), two symbols, LoS and wall paths."""
    from tunnelkit import design

    setup = design.DesignSetup.from_scenario(SCENARIO, bandwidth=10e6)
    cfg = dataclasses.replace(setup.config, n_symbols=2)
    return dataclasses.replace(setup, config=cfg, kinds=("los", "wall"))


def tiny_route():
    """The signal route on LoS and road paths (two well-separated paths), 10 MHz, two symbols."""
    from tunnelkit import signal_route

    route = signal_route.SignalRoute.from_scenario(SCENARIO, kinds=("los", "road"))
    return dataclasses.replace(route, config=small_config(route.config))


def tiny_scenario():
    """The scenario with 4 x 4 arrays, 10 MHz (41 tones) and two symbols."""
    from tunnelkit import load_scenario
    from tunnelkit.scenarios import with_values

    changes = {
        "base_station.arrays[*].shape": [4, 4],
        "radio.bandwidth": 10e6,
        "radio.n_rb": 27,
        "radio.n_symbols": 2,
    }
    return with_values(load_scenario(SCENARIO), changes)


def small_config(cfg):
    """``cfg`` on 10 MHz (41 tones) and two symbols."""
    return dataclasses.replace(cfg, bandwidth=10e6, n_rb=27, n_symbols=2)


def design_confirm():
    """A bound-route sweep with two one-epoch runs, its confirmation on the channel, the
    channel-route Monte-Carlo, the design's figures and its explorer."""
    from tunnelkit import design
    from tunnelkit.design import confirm, report, verdict
    from tunnelkit.plots import design as pdz
    from tunnelkit.widgets import design as wd

    setup = tiny_setup()
    few = {"units": 2, "max_units": 2, "drives_per_unit": 1, "settle": 0.0}
    rep = report.design_sweep(setup, ["4x4"], n_epochs=1, **few)
    verdict.recommend(rep.rows, 0.2, 0.9, 2)
    confirm.confirmation_candidates(rep)
    confirm.next_candidate(rep, [])
    confirm.confirm_on_channel(rep, setup, units=2)
    pdz.size_figure(rep.rows)
    pdz.design_answer_figure(rep)
    full = design.DesignSetup.from_scenario(SCENARIO)
    b = design.route_bounds(full, "4x4", epochs=[5, 10])
    pdz.route_traces(b, target=0.2)
    pdz.route_figure(b, target=0.2)
    wd.DesignExplorer(
        lambda x: pdz.route_figure(b, target=x),
        {"x": _slider()},
        scenario=SCENARIO,
        units=2,
        seed=0,
    )


def _slider():
    from tunnelkit.widgets.base import float_slider

    return float_slider("target", 0.2, 0.05, 1.0, 0.05)


def route_studies():
    """The efficiency and RMSE studies on one snapshot of one epoch, the evaluation tables, a
    snapshot from a given noiseless tensor, the 3-D figures."""
    from tunnelkit import channel, efficiency, evaluation
    from tunnelkit.extraction import extract_paths
    from tunnelkit.plots import efficiency as pef
    from tunnelkit.plots import tunnel3d as t3
    from tunnelkit.signal_route.raytraced import tensor_snapshot

    route = tiny_route()
    rng = np.random.default_rng(0)
    arr, paths = route.paths(6)
    H0 = channel.channel_tensor(paths, route.config)
    snap = tensor_snapshot(H0, route.config, rng, paths=paths)
    evaluation.path_rows(paths)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extract_paths(snap.H, len(paths), arr, route.config, refine="joint")
    evaluation.comparison_rows(est, paths, arr, snap.clock_bias)
    t3.factors_figure(est.factors)
    rows = efficiency.drive_efficiency(route, [6], 1, 0, refines=("ml",))
    efficiency.efficiency_rows(rows, "los")
    pef.efficiency_figure(rows, "los")
    efficiency.threshold_study(route, [6], [0.0], 1, 0)
    evaluation.rmse_study(route, 6, 1, 0, refine="ml")
    t3.tunnel3d_figure(route.tunnel, [arr], paths, route.trajectory.position[6])


def evaluation_tables():
    """The extraction's errors against the truth and the bound of a small random scene."""
    from tunnelkit import evaluation
    from tunnelkit.arrays import make_array
    from tunnelkit.channel import SRSConfig
    from tunnelkit.extraction import extract_paths

    rng = np.random.default_rng(0)
    cfg = small_config(SRSConfig())
    arr = make_array(4, 4, fc=cfg.fc, azimuth=0.0, elevation=0.0)
    sc = evaluation.random_scene(rng, 2, element_positions=arr.local, config=cfg)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extract_paths(sc.tensor(rng), 2, arr, cfg, refine="joint")
    b = sc.crlb()
    evaluation.bound_errors(est, sc.d, sc.v, sc.sources, b)
    evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, b)
    from tunnelkit.extraction.bounds import merged_crlb, merged_path

    merged_path(sc.alpha, sc.sources, sc.mu_f, sc.mu_t, (0, 1))
    args = (sc.alpha, sc.sources, sc.element_positions, sc.mu_f, sc.mu_t, cfg.fc)
    merged_crlb(*args, cfg.n_tones, cfg.n_symbols, cfg.noise_power, (0, 1))


def javelin_studies():
    """The studies on one-epoch drives: collection through the runner, the JAVELIN tables and
    their reproduction target, the ablation and error tables, the epoch figure and explorer."""
    from tunnelkit import reproduce, simulation
    from tunnelkit.plots import javelin as pjv
    from tunnelkit.reproduce import javelin_tables as jt
    from tunnelkit.signal_route import SignalRoute
    from tunnelkit.tracking.javelin import designs
    from tunnelkit.tracking.javelin.measured import design_from_errors
    from tunnelkit.widgets import javelin as wj

    rng = np.random.default_rng(0)
    route = SignalRoute.from_scenario(tiny_scenario())
    ep = dataclasses.replace(route, kinds=("los", "road")).epoch(6, rng)
    simulation.ml_epoch(ep, route.config)
    simulation.separate_epoch(ep, route.config)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulation.simulate_condition(route, 1, ("paper",), "L", rng)
        routes = simulation.simulate_routes(
            route, rng, extractions=("paper", "coherent", "ml"), n_epochs=2
        )
    drive = routes["paper"]
    ev = simulation.evaluate(drive, designs.ours(), keep_reports=True)
    simulation.settled_errors(ev, drive)
    simulation.tenfiloc_track(drive)
    simulation.without_radio(drive)
    simulation.vue_prediction_errors(drive, "mirror")
    simulation.path_errors([drive])
    simulation.extraction_errors([routes["ml"]])
    simulation.error_correlations([routes["ml"]])
    samples = simulation.error_samples([routes["ml"]])
    from tunnelkit.studies import robust_errors

    robust_errors.robust_rows(samples)
    robust_errors.robust_design(samples)
    simulation.ablation({"L": [drive]}, separated={"L": [routes["coherent"]]})
    pjv.epoch_figure(ev.run.reports[0], truth=drive.truth[0])
    wj.epoch_view(drive, ev, 0)
    wj.epoch_explorer(drive, ev)
    _, erows = simulation.extraction_errors([routes["ml"]])
    design_from_errors(erows)
    by_route = {"paper": {"L": [drive]}}
    jt.table_columns(by_route)
    jt.table_rows(by_route, "italiano2026_table1")
    simulation.collect_drives(SCENARIO, ("L",), 1, 0, n_epochs=1)
    simulation.collect_routes(SCENARIO, ("L",), 1, 0, n_epochs=1, extractions=("paper",))
    jt.javelin_table(SCENARIO, "italiano2026_table1", ("L",), 1, 0, False, ("paper",), 1)
    from tunnelkit.reproduce import javelin_notes as jn

    jn.seed_note(0)
    jn.odometry_note("automotive")
    jn.gain_note({"JAVELIN-L": {"our design, ML route": 1.5}})
    jn.nuisance_note({"second_order": 2})
    reproduce.Target("contract-target", "a target", 1, lambda **kw: None)
    reproduce.register("contract-target", help="a target", default_runs=1)
    reproduce.run("jiang-crlb", runs=2)


def doppler_figures():
    """Halili's error study and its regimes on a two-second drive, the Doppler figures."""
    from tunnelkit import doppler_drive as dv
    from tunnelkit.plots import doppler as pd
    from tunnelkit.tracking import doppler as dp

    drive = dv.make_drive(duration=2.0, pass_time=1.0)
    errs = dp.error_study(
        drive, np.random.default_rng(0), sigmas={"32.79 Hz": 32.79}, approaches=("EKF DS",)
    )
    means = dp.mean_errors(drive, range(2), approaches=("EKF DS",))
    pd.approach_cdfs(errs, approaches=("EKF DS",))
    track = np.zeros((len(drive.t), 2))
    pd.error_time_figure(drive, {"EKF DS": track})
    setup = dp.DopplerSetup(np.array([0.0, 0.0]), 5.0, 5.9e9, 0.1)
    pd.information_figure(drive, setup)
    pd.pcrlb_figure(drive, {"Doppler": dp.posterior_crlb(drive, sigma_hz=30.0)})
    pd.profiles_figure(dv.delay_doppler_profiles(drive, every=8))
    pd.regime_figure(["a", "b"], {"EKF DS": [means["EKF DS"], means["EKF DS"]]})


def tracking_figures():
    """The UPF's reference proposal and particle clouds, the four-estimator figure."""
    from tunnelkit import load_scenario
    from tunnelkit.plots import tracking as ptr
    from tunnelkit.tracking import upf
    from tunnelkit.tracking import virtual_station as vs

    rng = np.random.default_rng(0)
    exp = vs.experiment("jiang2023-straight")
    Z = exp.model.simulate(exp.truth[:3, :2], rng, size=1)
    x0, P0 = exp.truth[0], exp.P0
    upf.ukf_proposal_reference(exp.model, np.tile(x0, (3, 1)), np.tile(P0, (3, 1, 1)), Z[0, 0])
    f = upf.UnscentedParticleFilter(exp.model, x0, P0, rng=rng, n_particles=20)
    f.step(Z[0, 0], first=True)
    snap = {"t": 0.0, "particles": f.particles[0], "weights": f.weights, "truth": x0[:2]}
    ptr.particle_cloud_figure([{**snap, "estimate": f.position}])
    sc = load_scenario("jiang2023-straight")
    truth = exp.truth[:10]
    ptr.tracks_figure(sc.tunnel(), sc.base_station(), truth, {"EKF": truth[:, :2] + 0.1})


def tunnels_registries():
    """Tunnel shapes and their cross-sections, the registries' decorators and loader, the
    reference tables, the plain explorer."""
    from tunnelkit import reference, tunnels
    from tunnelkit.plots.common import cdf_figure
    from tunnelkit.scenarios import registry as sr
    from tunnelkit.tracking import registry as tr
    from tunnelkit.widgets.base import Explorer

    tun = tunnels.make_tunnel("rectangular", width=8.0, height=6.0, length=50.0)
    tunnels.cross_section(tun)
    tunnels.cross_section_area(tun)
    tunnels.cross_section_perimeter(tun)
    profile = [(4.0, 0.0), (4.0, 5.0), (-4.0, 5.0), (-4.0, 0.0)]
    tunnels.extruded_tunnel(profile, ["right", "ceiling", "left"], length=50.0)
    sr.register_tunnel("contract-kind")
    sr.register_trajectory("contract-kind")
    sr.set_loader(importlib.import_module)
    tr.register("contract-family", "contract-name")
    tr.provide("jiang2023", "tunnelkit.tracking.virtual_station")
    reference.load("halili2022_p90")
    Explorer(lambda x: cdf_figure({"a": np.arange(3.0) * x}), {"x": _slider()})


def ray_tracer():
    """Sionna RT on a 30 m rectangular tunnel (first order, 1,000 rays per source) and the
    route's ray-traced snapshot of one epoch (its tensor cached by the first call)."""
    import tempfile

    from tunnelkit import rt, tunnels
    from tunnelkit.arrays import make_array
    from tunnelkit.rt import RTSettings
    from tunnelkit.rt.sionna_engine import SionnaEngine, load_sionna_scene
    from tunnelkit.signal_route import SignalRoute

    settings = RTSettings(samples_per_src=1000, max_depth=1, scattering_coefficient=0.0)
    route = SignalRoute.from_scenario(
        tiny_scenario(), channel="sionna", rt_settings=settings, cache_dir=tempfile.mkdtemp()
    )
    rng = np.random.default_rng(0)
    a, paths = route.paths(6)
    route.raytraced_snapshot(6, a, paths, rng)
    # the engine last: the scene it loads stays the current one for the replayed calls
    tun = tunnels.make_tunnel("rectangular", width=8.0, height=6.0, length=30.0)
    arr = make_array(2, 2, fc=5.9e9, azimuth=0.0, elevation=0.0, origin=(-8.0, 3.0, 4.0))
    rt.engine_for(tun, fc=5.9e9)
    eng = SionnaEngine(tun, fc=5.9e9, samples_per_src=1000)
    load_sionna_scene(eng.mitsuba, fc=5.9e9)
    eng.apply_settings(settings)
    ue = np.array([8.0, 0.0, 1.5])
    eng.trace(arr, ue)
    eng.trace_elements(arr, ue)
    eng.surface_of(0)


def javelin_records():
    """The records one JAVELIN step builds unchecked (its inner loop), built here through their
    checked constructors from a short run's report."""
    import dataclasses as dc

    from javelin_geometric import geometric_stream, toy_drive, toy_reflectors

    from tunnelkit.tracking.javelin import JavelinConfig, JavelinDesign, run_javelin
    from tunnelkit.tracking.javelin.measurement import track_model
    from tunnelkit.tracking.javelin.update import stack_measurement

    bs = (0.0, 0.0, 4.8)
    P, V = toy_drive(6, 0.1, amplitude=0.5, speed=4.0)
    eps = geometric_stream(P, V, toy_reflectors(), np.random.default_rng(0), bs=bs)
    spd, hdg = np.linalg.norm(V, axis=1), np.arctan2(V[:, 1], V[:, 0])
    design = JavelinDesign(JavelinConfig(base_station=bs, sigma_p0_ue=1.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_javelin(eps, spd, hdg, 0.1, P[0], design, keep_reports=True)
    rep = next(r for r in run.reports[1:] if r.manage is not None and r.manage.pairs)
    for r in (rep.manage, rep):
        type(r)(*(getattr(r, f.name) for f in dc.fields(r) if f.init))
    x = np.concatenate([rep.estimate, rep.positions[1:, 1:].ravel()])
    pred, J = track_model(x, bs)
    pairs = [(i, j) for i, j in rep.manage.pairs if i < len(pred)]
    m = stack_measurement(pred, J, rep.paths, pairs, design.config)
    type(m)(*(getattr(m, f.name) for f in dc.fields(m) if f.init))


def short_setup():
    """:func:`tiny_setup` on three epochs of its route (a model over the whole route is cheap)."""
    from tunnelkit.scenarios import Trajectory

    setup = tiny_setup()
    tr, keep = setup.trajectory, slice(5, 8)
    short = Trajectory(tr.t[keep], tr.position[keep], tr.velocity[keep])
    return dataclasses.replace(setup, trajectory=short)


def channel_budgets():
    """The design's impairment budget on a three-epoch route at 1 deg of phase error, matched
    to an epoch's estimates and added to their covariances, the re-judged fit, a row subset."""
    from tunnelkit.channel import Impairments
    from tunnelkit.design.achievable import DesignImpairments, path_error_model
    from tunnelkit.design.channelbudget import channel_budget
    from tunnelkit.signal_route import judging

    setup = short_setup()
    model = path_error_model(setup, "4x4", DesignImpairments(phase_error_deg=1.0))
    budget = channel_budget(model, setup, "4x4")
    imp = Impairments(phase_sigma_deg=1.0)
    route = dataclasses.replace(setup.signal_route("4x4"), impairments=imp)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ep = route.epoch(1, np.random.default_rng(0), refine="ml")
    m = ep.measurements
    budget.match(1, m.d, m.direction)
    judging.apply_budget(m, budget, 1)
    judging.rejudge(
        ep.estimates, ep.snapshot.H, ep.array.local, route.config.fc, judging.impairment_share(imp)
    )
    judging.rejudge(
        ep.estimates, ep.snapshot.H, ep.array.local, route.config.fc, 0.0, calibration=(1.0, 0.0)
    )
    judging.calibration_floor(1.0, 0.2, np.abs(ep.snapshot.H).sum(axis=(1, 2)))
    m.subset(np.arange(len(m)))


DRIVERS = (
    channel_budgets,
    design_confirm,
    route_studies,
    evaluation_tables,
    javelin_studies,
    doppler_figures,
    tracking_figures,
    tunnels_registries,
    ray_tracer,
    javelin_records,
)
