"""Valid arguments for the generated contracts, recorded rather than listed.

:func:`capture` runs a few short workflows (the ones the notebooks teach: Jiang's 2-D stations,
the signal route, JAVELIN, the Doppler drive, Mmax, the design) under a profiler and keeps, for
every public callable they reach, the arguments of its first call. A callable no workflow reaches
gets its arguments from its own defaults plus :data:`BY_NAME` / its annotations
(:func:`fill_arguments`). The contract suite perturbs one argument of such a valid call at a time.
"""

from __future__ import annotations

import contextlib
import copy
import inspect
import io
import sys
import warnings

import numpy as np
from contract_design import DRIVERS as DESIGN_DRIVERS
from contract_routes import DRIVERS as ROUTE_DRIVERS
from contracts import Target, function_of, hints, parameters
from contracts_baselines import DRIVERS as BASELINE_DRIVERS


def _code_of(target: Target):
    fn = function_of(target)
    if target.kind == "class":
        init = vars(fn).get("__init__")
        if init is None:  # a dataclass or an inherited constructor
            init = fn.__init__
        return getattr(init, "__code__", None)
    if target.kind in ("classmethod", "staticmethod"):
        raw = vars(target.owner)[target.name.rsplit(".", 1)[1]]
        return raw.__func__.__code__
    return getattr(fn, "__code__", None)


def _keep(value):
    if type(value).__name__ == "_HAS_DEFAULT_FACTORY_CLASS":
        return value  # a dataclass's "use the default factory" marker: only the object itself works
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, np.random.Generator):
        return value  # copied per case
    try:
        return copy.deepcopy(value)
    except Exception:
        return value


def _star_parameters(target: Target) -> list[tuple[str, str]]:
    """[("*", name) / ("**", name)] of the variadic parameters of ``target``'s signature."""
    try:
        sig = inspect.signature(function_of(target))
    except (TypeError, ValueError):
        return []
    kinds = {inspect.Parameter.VAR_POSITIONAL: "*", inspect.Parameter.VAR_KEYWORD: "**"}
    return [(kinds[p.kind], p.name) for p in sig.parameters.values() if p.kind in kinds]


def capture(targets: list[Target], drivers) -> dict[str, tuple[object, dict]]:
    """{target name: (self or None, {parameter: value})} of the first call each driver makes."""
    by_code = {}
    for t in targets:
        code = _code_of(t)
        if (code is not None and code.co_filename != "<string>") or t.kind == "class":
            if code is not None:
                by_code.setdefault(code, []).append(t)
    got: dict[str, tuple[object, dict]] = {}

    def hook(frame, event, arg):
        if event != "call":
            return
        ts = by_code.get(frame.f_code)
        if not ts:
            return
        for t in ts:
            if t.name in got:
                continue
            loc = frame.f_locals
            params = parameters(t)
            if t.kind == "class":
                owner_ok = isinstance(loc.get("self"), t.obj) and type(loc.get("self")) is t.obj
                if not owner_ok:
                    continue
            kw = {p.name: _keep(loc[p.name]) for p in params if p.name in loc}
            for star, name in _star_parameters(t):  # *args / **kwargs as called
                if loc.get(name):
                    kw[star + name] = _keep(loc[name])
            this = None
            if t.kind in ("method", "classmethod"):
                # a method on its instance; a classmethod on the class it was called through
                # (a base's classmethod reached from a concrete subclass)
                this = loc.get(next(iter(frame.f_code.co_varnames), "self"))
                ok = (
                    isinstance(this, t.owner)
                    if t.kind == "method"
                    else isinstance(this, type) and issubclass(this, t.owner)
                )
                if not ok:
                    continue
                this = _keep(this)
            got[t.name] = (this, kw)

    for drive in drivers:
        old = sys.getprofile()
        sys.setprofile(hook)
        try:
            with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
                warnings.simplefilter("ignore")
                drive()
        finally:
            sys.setprofile(old)
    return got


# --- the workflows -------------------------------------------------------------------------------


def _jiang():
    import tunnelkit as tk
    from tunnelkit import crlb, metrics, positioning, tunnel2d
    from tunnelkit.tracking import virtual_station as vs

    sc = tk.load_scenario("jiang2023-straight")
    tunnel = sc.tunnel()
    bs = sc.base_station()
    st = tunnel.virtual_stations(bs)
    tunnel2d.virtual_stations(bs, list(tunnel.walls))
    p = np.array([30.0, 2.0])
    crlb.crlb_rmse(p, st, 0.01, 0.5)
    crlb.toa_doa(p, st)
    rng = np.random.default_rng(0)
    d, th = positioning.simulate_toa_doa(p, st, 0.01, 0.5, rng)
    positioning.ls_toa_doa(st, d, th)
    positioning.tswls(st, d, th, 0.5, 0.01)
    positioning.toa_only_candidates(st, d)
    exp = vs.experiment("jiang2023-straight")
    est = vs.monte_carlo(exp, 1, 0, names=["EKF", "TSWLS"])
    e = metrics.position_errors(est["EKF"][0], exp.truth)
    metrics.rmse(est["EKF"][0], exp.truth)
    metrics.error_stats(e)
    metrics.ecdf(e)


def _signal_route():
    from tunnelkit import signal_route
    from tunnelkit.extraction import extract_paths, ml_truth, path_crlb

    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    rng = np.random.default_rng(0)
    ep = route.epoch(10, rng)
    route.draw(10, np.random.default_rng(1))
    arr, paths = route.paths(10)
    snap = route.snapshot(paths, arr, rng)
    route.ml_noise_power(10, snap)
    extract_paths(snap.H, len(paths), arr, route.config, refine="joint")
    path_crlb(paths, arr, route.config)
    ml_truth(paths, arr, route.config)
    from tunnelkit.studies.misspecified import misspecified_bound, parameter_vector, pseudo_true

    small = snap.H[:, :8, :4]
    pt = pseudo_true(
        small,
        arr.local,
        route.config.fc,
        ml_truth(paths, arr, route.config),
        noise_power=route.config.noise_power,
    )
    misspecified_bound(
        small,
        arr.local,
        route.config.fc,
        pt["theta"],
        pt["mu_f"],
        pt["mu_t"],
        pt["c"],
        route.config.noise_power,
    )
    parameter_vector(pt["theta"], pt["mu_f"], pt["mu_t"], pt["c"])
    from tunnelkit.signal_route.judging import model_error_test

    n0 = route.config.noise_power
    model_error_test(
        pt["residual"],
        len(paths),
        float(np.vdot(small, small).real),
        arr.local,
        route.config.fc,
        n0,
        0.1,
    )
    from tunnelkit.propagation.second_order import second_order_paths

    traj = route.trajectory
    second_order_paths(route.tunnel, arr, traj.position[10], traj.velocity[10], fc=route.config.fc)
    # called directly: calibrated_threshold reaches it only when its per-process cache misses,
    # which depends on what ran before in the same process
    from tunnelkit.extraction.ml.residual import peak_null

    peak_null(arr.local, route.config.fc, (arr.M, 8, 4), rng, n_draws=10)
    # the resolution limit at a fit (fit_problem calls only separations)
    from tunnelkit.extraction import ml

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extract_paths(snap.H[:, :8, :4], 2, arr, route.config)
    prob = ml.Problem(snap.H[:, :8, :4], arr.local, route.config.fc)
    f = est.fit
    ml.pair_separation(prob, f.theta, f.mu_f, f.mu_t, f.noise_power)
    ml.closest_pair(prob, f.theta, f.mu_f, f.mu_t, f.noise_power)
    ml.resolvable(prob, f.theta, f.mu_f, f.mu_t, f.noise_power, f.peak_max)
    ml.below_threshold(est.significance, est.resolution, prob.N)
    ml.outlier_probability(est.significance, prob.N)
    ml.snr_threshold(prob.N, 0.01)
    ml.pair_test(prob, f.theta, f.mu_f, f.mu_t, f.noise_power, z_max=float("inf"))
    # the fits call the numerics' unchecked twins: the checked public forms called directly
    from tunnelkit.extraction import linalg as la
    from tunnelkit.extraction import numerics as nm

    ev = prob.evaluate(f.theta, f.mu_f, f.mu_t)
    held = np.zeros(ev["g"].size, bool)
    free, _ = la.free_newton(ev["A"], ev["g"], held, held)
    la.damped_step(ev["A"], ev["g"], free, 1e-3)
    la.solve(ev["G"], ev["b"])
    nm.spatial_phase(f.theta, arr.local, prob.k0)
    F = np.exp(1j * np.arange(prob.nf)[:, None] * f.mu_f[None, :])
    T = np.exp(1j * np.arange(prob.nt)[:, None] * f.mu_t[None, :])
    nm.contract(prob.H, F, T)
    del ep


def _studies():
    from tunnelkit import simulation

    drives = simulation.simulate_routes(
        "italiano2026-straight",
        np.random.default_rng(0),
        extractions=("paper",),
        n_epochs=3,
    )
    from tunnelkit.design.los import los_only

    los_only(drives["paper"], 0.3)
    from tunnelkit.simulation.variants import drive_variant

    drive_variant("italiano2026-straight", 120.0)
    # the attribution study's record (its measurement traces the scene: tests/test_attribution.py)
    from tunnelkit.studies.attribution import Attribution, AttributionRow, ConfigSummary

    row = AttributionRow("scenario", "4x4", "los", 2, *[0.1] * 8, 0, 4, *[0.2] * 8)
    summ = ConfigSummary("scenario", "4x4", 0.04, "2 of 2", *[0.5] * 6, 1.0)
    Attribution([row], [summ], "italiano2026-straight", ("4x4",), (0, 5), 2, 0).markdown()
    from tunnelkit.rt import RTSettings
    from tunnelkit.studies.attribution import config_settings, scenario_with_array

    config_settings(RTSettings(), "depth-1")
    scenario_with_array("italiano2026-straight", (4, 4))
    from tunnelkit.signal_route import SignalRoute
    from tunnelkit.studies.attribution import one_epoch_fix

    route = SignalRoute.from_scenario("italiano2026-straight")
    arr, paths = route.paths(10)
    rel = np.array([p.source for p in paths]) - arr.origin
    rng_ = np.linalg.norm(rel, axis=1)
    phi, psi = np.arctan2(rel[:, 1], rel[:, 0]), np.arcsin(rel[:, 2] / rng_)
    one_epoch_fix(phi, psi, rng_, paths, route.trajectory.position[10], arr.origin)
    # paths against their truth, the amplitude profile and its study (the traced part of the
    # study traces the scene: tests/test_aperture.py)
    from tunnelkit.extraction.direct import aperture
    from tunnelkit.studies import nuisance, truth

    tru = truth.path_truth(paths, arr)
    truth.world_angles(np.stack([p.direction for p in paths]))
    from tunnelkit.extraction import ml_truth

    th, mf, mt = ml_truth(paths, arr, route.config)
    est = truth.angles_of_theta(th, mf, arr, route.config)
    idx = np.arange(len(paths))
    truth.path_differences(est, tru, idx, idx, 0.0)
    aperture.taper_basis(arr.local, 1)
    from tunnelkit.channel import channel_tensor

    H = channel_tensor(paths, route.config)[:, :40, :4]
    prob = aperture.ApertureProblem(H, arr.local, route.config.fc, 1)
    beta = np.zeros((len(paths), prob.K))
    prob.profile(beta)
    prob.evaluate_profile(th, mf, mt, beta, derivatives=True)
    prob.fit(th, mf, mt, route.config.noise_power, beta=beta, max_iter=2)
    from tunnelkit.extraction.direct import visibility

    ue, vel = route.trajectory.position[10], route.trajectory.velocity[10]
    visibility.element_visibility(route.tunnel, route.tunnel.surfaces[0], ue, arr.world)
    _, mask = visibility.visible_paths(route.tunnel, arr, paths, ue, vel, route.config.fc, 0.25)
    masked = visibility.MaskedProblem(H, arr.local, route.config.fc, mask[:, : len(paths)])
    masked.fit(th, mf, mt, route.config.noise_power, max_iter=2)
    visibility.predicted_model(route, arr, ue, vel, 1)
    visibility.predicted_model(route, arr, ue, vel, 1, element_second_order=True)
    visibility.visible_second_order(route.tunnel, arr, ue, vel, route.config.fc, 2, 0.25)
    nuisance.ModelRow("eq1", "error", "all", 3, *[0.1] * 6, 0.05, 1.0, 2.0, 0.5)
    nuisance.CostRow(1, 5, 0.0, 0.0, 1.2, 1.3, 1.4, 1.0, 1.0, 1.1, 1.1)
    nuisance.eq1_cost(
        "italiano2026-straight", array=(4, 4), epochs=(10,), orders=(1,), draws=1,
        rng=np.random.default_rng(0),
    )  # fmt: skip


def _direct():
    from tunnelkit.design import directsurvey, traceddirect
    from tunnelkit.design.los import ElevationSigmas
    from tunnelkit.extraction.direct import fit as direct
    from tunnelkit.extraction.direct.visibility import predicted_model
    from tunnelkit.reproduce.javelin_traced import los_design
    from tunnelkit.signal_route import SignalRoute

    route = SignalRoute.from_scenario("italiano2026-straight")
    arr, _, snap = route.draw(12, np.random.default_rng(3))
    ue, vel = route.trajectory.position[12], route.trajectory.velocity[12]
    paths, masks, _ = predicted_model(route, arr, ue, vel, 2)
    maps = direct.image_maps(route.tunnel, paths)
    H = snap.H[:, :40, :4]
    prob = direct.DirectProblem(H, arr, route.config, masks, maps, ue[2], vel)
    prob.atoms(np.r_[ue[:2], 0.0])
    prob.cost(np.r_[ue[:2], 0.0, 4.0])
    prob.residual(np.r_[ue[:2], 0.0])
    prob.fit_tied(np.r_[ue[:2], 0.0], max_evaluations=5)
    prob.model(np.r_[ue[:2], 0.0])
    prob.with_diffuse(1).cost(np.r_[ue[:2], 0.0, -0.1, 0.0])
    direct.diffuse_start(H)
    direct.diffuse_threshold(arr.M, 40, 4)
    direct.diffuse_share(0.01, 1)
    direct.direct_fix(route, arr, H, ue, vel, second_order=2, speed=True, gate=5.0,
                      element_second_order=True, diffuse=1, noise_power=snap.noise_power,
                      diffuse_above=0.01)  # fmt: skip
    los = traceddirect.eq1_los(route, 12, arr, 3, snap)
    traceddirect.repointed(los, arr.origin, ue + np.array([0.5, 0.3, 0.0]))
    traceddirect.unmodelled_share(0.01, snap)
    table = ElevationSigmas(np.zeros(1), np.radians([1.0]), np.radians([1.0]))
    table.scaled(2.0)
    directsurvey.design_table("italiano2026-straight", "8x8")
    directsurvey.direct_summary("italiano2026-straight", "8x8", {"diffuse": 1})
    directsurvey.surveyed_table(directsurvey.survey_record("italiano2026-straight"))
    directsurvey.survey_path("italiano2026-straight", "8x8")
    traceddirect.direct_drive(route, np.random.default_rng(0), los_design(), table,
                                      table, speed_sigma=0.1, second_order=2, n_epochs=2,
                                      start_sigma=0.1, start_height_sigma=0.05,
                                      element_second_order=True, max_unmodelled=0.5, diffuse=1,
                                      diffuse_above=0.01, start=route.trajectory.position[0] + 0.1,
                                      second_start=True)  # fmt: skip


def _doppler():
    from tunnelkit import doppler_drive as dv
    from tunnelkit.tracking import doppler as dp

    d = dv.make_drive(duration=8.0, pass_time=4.0)
    meas = dv.measure(d, np.random.default_rng(0))
    fix = dv.gnss_fix(d, np.random.default_rng(1))
    dp.run_approaches(d, meas, fix)
    # the filters' own protocol (tracking.protocol): predict, then update
    setup = dp.DopplerSetup.from_drive(d)
    for f in (dp.DopplerEKF(setup, fix), dp.SpeedKF(setup, 5.0)):
        f.predict()
        f.update(meas.doppler[1])
    rkf = dp.RangeKF(setup, 30.0)
    rkf.predict(5.0)
    rkf.update(meas.toa[1])


def _fresnel():
    from tunnelkit import fresnel

    s = fresnel.mmax_summary(R=100.0, W=10.0, y_u=2.0, fc=5.9e9, eps_phi=np.pi / 8)
    fresnel.design_report([dict(R=100.0, W=10.0, y_u=2.0, fc=5.9e9, eps_phi=np.pi / 8)])
    del s


def _design():
    from tunnelkit import design

    setup = design.DesignSetup.from_scenario("italiano2026-straight")
    design.route_bounds(setup, "4x4", epochs=[5, 10])
    design.predicted_error(setup, "4x4", design.DesignImpairments(), epochs=[5, 10])


def _javelin():
    from javelin_geometric import geometric_stream, toy_drive, toy_reflectors

    from tunnelkit.tracking.javelin import JavelinConfig, JavelinDesign, run_javelin

    rng = np.random.default_rng(0)
    bs = (0.0, 0.0, 4.8)
    P, V = toy_drive(12, 0.1, amplitude=0.5, speed=4.0)
    eps = geometric_stream(
        P,
        V,
        toy_reflectors(),
        rng,
        los_probability=0.8,
        clock_bias=lambda r: r.normal(0.0, 3.0),
        bs=bs,
        sigma_phi=0.02,
        sigma_psi=0.02,
        sigma_kappa=1.0,
        sigma_d=0.3,
        sigma_v=0.2,
    )
    spd = np.linalg.norm(V, axis=1)
    hdg = np.arctan2(V[:, 1], V[:, 0])
    run_javelin(
        eps,
        spd,
        hdg,
        0.1,
        P[0],
        JavelinDesign(JavelinConfig(base_station=bs, sigma_p0_ue=1.0)),
        keep_reports=True,
    )
    # the filter protocol (tracking.protocol): predict with the V2X message, update with paths
    from tunnelkit.tracking.javelin import Javelin

    trk = Javelin(P[0], JavelinDesign(JavelinConfig(base_station=bs, sigma_p0_ue=1.0)))
    trk.predict(float(spd[0]), float(hdg[0]), 0.1)
    trk.update(eps[1])
    # the bias-aware design: reported covariances with a repeating share (consider parameters)
    from tunnelkit.tracking.javelin import ConsiderNoise, PathMeasurements

    def reported(pm):
        if pm is None:
            return None
        n = len(pm)
        cov = np.broadcast_to(np.diag([0.02**2, 0.02**2, 1.0]), (n, 3, 3)).copy()
        rep = np.zeros((n, 4, 4))
        rep[:, :3, :3] = 0.5 * cov
        rep[:, 3, 3] = 0.5 * 0.3**2
        return PathMeasurements.from_arrays(
            pm.phi, pm.psi, pm.kappa, pm.d, pm.v, cov=cov, sigma_d=np.full(n, 0.3), bias_cov=rep
        )

    run_javelin(
        [reported(pm) for pm in eps],
        spd,
        hdg,
        0.1,
        P[0],
        JavelinDesign(JavelinConfig(base_station=bs, sigma_p0_ue=1.0), noise=ConsiderNoise()),
    )


def _widgets():
    from tunnelkit import widgets

    widgets.mmax_figure()
    widgets.crlb_figure()
    widgets.upf_figure(n_particles=20)
    widgets.curvature_figure(side=4)


def _baselines():
    """Short valid calls of callables the teaching workflows do not reach (so their contracts
    are tested at all): geometry, propagation, channel pieces, bounds, verdicts, plots."""
    import tunnelkit as tk
    from tunnelkit import budget, crlb, geometry, metrics, propagation, reflection, sizes
    from tunnelkit.channel import DiffuseSpec, diffuse_tensor
    from tunnelkit.design import errordraws, intervals, mcrb, render, units, verdict
    from tunnelkit.design.arrayjob import javelin_config
    from tunnelkit.design.drivebound import drive_bound
    from tunnelkit.extraction.krank import kruskal_rank
    from tunnelkit.fresnel.bounds import fraunhofer_distance
    from tunnelkit.plots import common, tables, topview
    from tunnelkit.tracking import cv, gating
    from tunnelkit.tracking.javelin.measurement import measurement_model

    rng = np.random.default_rng(0)
    budget.set_memory_budget(budget.memory_budget())
    sizes.format_bytes(1536)
    spec = DiffuseSpec(0.1)
    spec.power(1.0)
    spec.taps(240e3, 16)
    spec.tone_covariance(240e3, 16)
    diffuse_tensor(spec, (4, 16, 2), 240e3, 1e-7, 1.0, rng)
    h = lambda p: np.array([p[0] + p[1], p[0] * p[1]])  # noqa: E731
    crlb.numeric_jacobian(h, np.array([1.0, 2.0]))
    crlb.numeric_fim(h, np.array([1.0, 2.0]), np.eye(2))
    sc = tk.load_scenario("jiang2023-straight")
    tunnel, bs = sc.tunnel(), sc.base_station()
    wall = tunnel.walls[0]
    p = np.asarray(sc.trajectory().position[5], float)
    wall.project(p)
    tunnel.require_inside("p", p)
    tunnel.wall_distances(p)
    wall.mirror(p)
    reflection.specular_point(bs, p, wall)
    geometry.spherical(np.array([1.0, 2.0, 3.0]))
    metrics.settled(np.arange(0.0, 30.0, 0.5))
    propagation.fresnel_te(5.0 - 0.5j, np.array([0.3, 0.9]))
    propagation.arrival_angles(np.array([0.0, 0.6, 0.8]))
    box = propagation.Box(np.array([0.0, -1.0, 0.0]), np.array([10.0, 1.0, 4.0]))
    box.blocks(np.array([-5.0, 0.0, 1.0]), np.array([15.0, 0.0, 1.0]))
    fraunhofer_distance(0.25, 28e9)
    kruskal_rank(rng.standard_normal((6, 3)))
    errordraws.psd_sqrt(np.array([[2.0, 0.5], [0.5, 1.0]]))
    mcrb.scaled_inverse(np.array([[[2.0, 0.5], [0.5, 1.0]]]))
    e = np.abs(rng.standard_normal(50))
    verdict.share_quantile(e, 0.9)
    intervals.bootstrap_quantile_ci(e[None, :].repeat(3, 0), 0.9, rng, n_boot=200)
    intervals.cluster_quantile_ci(e[None, :].repeat(3, 0), 0.9)
    intervals.paired_rmse_ratio(e[:6], e[6:12])
    intervals.rmse_ci(e[:6])
    units.unit_rmse(e.reshape(5, 10), 5, np.arange(10))
    verdict.counted_epochs(np.arange(0.0, 30.0, 0.5))
    verdict.gate(e, np.ones(50, bool), "achievable")
    verdict.judge(0.1, units=20, yield_=0.9, ci=[0.7, 0.97], cap=200)
    verdict.recommend([], 0.1, 0.9, 20)
    from tunnelkit.design import units

    units.wilson_interval(3, 20)
    units.unit_quantiles(np.abs(rng.standard_normal((4, 30))), 2, np.arange(10, 30), 0.9)
    units.unit_yield(np.array([0.05, 0.2, 0.08]), 0.1)
    units.unit_seeds(3, 2, 2)
    units.drive_streams(2, 3, 2)
    render.over_target(np.arange(5.0), np.array([0.1, 0.3, 0.25, 0.1, 0.4]), 0.2)
    drive_bound(np.full(5, 0.1), np.full(5, 0.02))
    javelin_config({"d": 0.05, "direction": 0.01, "kappa": 2.0})
    cv.simulate_cv(np.array([0.0, 0.0, 10.0, 0.0]), 0.1, 0.5, 20, rng)
    gating.ChiSquareGate(0.99).accepts(np.array([1.0, 30.0]), 2)
    gating.squared_distances(np.array([1.0, 30.0]))
    measurement_model(np.array([0.0, 1.0, 1.5, 2.0, 3.0]), (0.0, 0.0, 4.8))
    common.cdf_figure({"a": e})
    tables.table(["x", "y"], [[1, 2.5], [2, 3.5]])
    topview.tunnel_topview(tunnel, bs)
    setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    tk.design.path_bounds(setup, "4x4", epochs=[5, 10])
    tk.scenarios.with_values(tk.load_scenario("italiano2026-straight"), {"radio.fc": 28e9})


def _baselines_tracking():
    """More valid calls: the JAVELIN containers, a random scene, the route's impairments and a
    template (callables the workflows reach only through their results)."""
    from tunnelkit import evaluation, signal_route
    from tunnelkit.channel import Impairments
    from tunnelkit.scenarios import template
    from tunnelkit.tracking.javelin.measurement import PathMeasurements
    from tunnelkit.tracking.javelin.motion import RandomWalk
    from tunnelkit.tracking.javelin.state import JavelinState

    rng = np.random.default_rng(0)
    pm = PathMeasurements.from_arrays(
        np.array([0.1, 0.5]), np.array([0.2, 0.3]), np.array([5.0, np.nan]), np.array([4.0, 6.0])
    )
    pm.subset([0])
    st = JavelinState(np.array([0.0, 1.0, 1.5, 2.0, 3.0]), np.eye(5), [1], [0], [False], next_id=2)
    st.position(0)
    RandomWalk().increment(st, 10.0, 0.0, 0.1)
    scene = evaluation.random_scene(rng, 2)
    scene.crlb()
    scene.tensor(rng)
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    route.with_impairments(Impairments(phase_sigma_deg=1.0), rng)
    template("my-tunnel", "italiano2026-straight")


def _known_surfaces():
    """The design's tracker pieces: an honest start, VUEs from known planes and the batch form
    of the bound over the drive."""
    from javelin_geometric import geometric_paths, toy_reflectors

    from tunnelkit import design
    from tunnelkit.design.arrayjob import design_planes
    from tunnelkit.tracking.javelin import JavelinState, draw_start
    from tunnelkit.tracking.javelin.config import JavelinConfig
    from tunnelkit.tracking.javelin.noise import ReportedNoise
    from tunnelkit.tracking.javelin.surfaces import GeometricBirth, mirror_vue

    rng = np.random.default_rng(0)
    bs = (0.0, 0.0, 4.8)
    planes = toy_reflectors()[:2]
    truth = np.array([-30.0, 1.5, 1.0])
    meas, _ = geometric_paths(truth, np.zeros(3), planes, rng, bs=bs, shuffle=False)
    n = len(meas)
    meas = type(meas).from_arrays(
        meas.phi,
        meas.psi,
        meas.d,
        meas.d,
        meas.v,
        cov=np.repeat(np.diag([1e-6, 1e-6, 0.01])[None], n, 0),
        sigma_d=np.full(n, 0.01),
    )
    st = JavelinState.initial(draw_start(truth, 0.1, rng, 0.05), 0.1, 0.05)
    birth = GeometricBirth.from_planes(planes)
    cfg = JavelinConfig(base_station=bs)
    birth.match(st, meas, 1, cfg, ReportedNoise(), 0)
    birth.match_distance(st, meas, 1, cfg, ReportedNoise(), 0)
    birth.place(st, meas, 1, cfg, ReportedNoise(), 0)
    birth.inside(truth, bs)
    mirror_vue(st, planes[0].normal, planes[0].offset)
    setup = design.DesignSetup.from_scenario("italiano2026-straight")
    design_planes(setup)
    from tunnelkit.design.drivebound import drive_motion

    drive_motion(setup, 5, 0.2, 0.0175)


def _baselines_checks():
    """Valid calls of callables that had none: the Fresnel figures at a real design point (the
    filled defaults put the UE on the wall), widgets' controls, tables, schema keys."""
    from tunnelkit import fresnel, schema
    from tunnelkit.arrays import make_array
    from tunnelkit.plots import fresnel as pf
    from tunnelkit.plots import javelin as pj
    from tunnelkit.plots import tables, tracking
    from tunnelkit.report import Report
    from tunnelkit.scenarios.registry import Registry
    from tunnelkit.simulation.drives import Condition
    from tunnelkit.widgets import base

    point = dict(R=10.0, W=5.0, y_u=2.0, fc=5.9e9)
    fresnel.phase_mismatch_ura(4, **point)
    pf.mismatch_figure(8, **point, eps_phi=0.15)
    pf.mmax_range_figure(**point, eps_phi=0.15, M=8, R_grid=np.array([5.0, 10.0, 20.0]))
    prof = fresnel.aperture_profile(8, **point)
    pf.derivation_figure(prof, lam=0.05)
    pf.ratio_map_figure(np.array([5.0, 10.0]), np.array([1.0, 2.0]), np.ones((2, 2)))
    Condition("L", 1.0)
    make_array(2, 2, fc=28e9, azimuth=0.0, elevation=0.0, name="a").to_world(np.zeros((2, 3)))
    base.checkbox("wideband", True)
    base.float_slider("x", 0.5, 0.0, 1.0, 0.1)
    base.int_slider("n", 2, 1, 4)
    base.slider_value("x", 0.5, 0.0, 1.0)
    tables.report_table(Report("t", ["a", "b"], [[1, 2.5]]))
    t = np.arange(4) * 0.1
    tracking.bound_ratio_figure(t, {"a": ({"EKF": np.ones(4)}, np.ones(4))})
    tracking.table_figure([{"a": 1, "b": 2.0}], ["a", "b"])
    pj.tracks_count_figure(t, np.array([1, 2, 2, 3]))
    pj.javelin_table_figure(["a", "b"], [[1, 2.5]])
    key = schema.Key("fc", "float", "carrier [Hz]")
    schema.Table((key,))
    Registry("tunnel", "a tunnel builder")
    pf.fresnel_topview(8, **point)
    from tunnelkit import doppler_drive as dv
    from tunnelkit import runner as mc
    from tunnelkit.tracking import doppler as dp
    from tunnelkit.tracking import virtual_station as vs
    from tunnelkit.tracking.doppler import bounds as dpb

    setup = dp.DopplerSetup(np.array([0.0, 0.0]), 5.0, 5.9e9, 0.1)
    s = np.array([-20.0, 1.5, 10.0, 0.0])
    dp.doppler_model(s, setup)
    dp.doppler_jacobian(s, setup)
    dpb.snapshot_fim(s[:2], s[2:], setup, sigma_hz=30.0)
    dpb.posterior_crlb(dv.make_drive(duration=2.0, pass_time=1.0))
    vs.experiment("jiang2023-straight").model.position_fim(np.array([30.0, 2.0]))
    pool = mc.TrialPool(None)
    pool.gather(pool.prepare(abs, [1, -2]))
    pool.map(abs, [1, -2])
    mc.run_trials(_trial, 2, 0)
    from tunnelkit.plots import doppler as pd
    from tunnelkit.plots import tunnel3d as t3

    drv = dv.make_drive(duration=2.0, pass_time=1.0)
    pd.doppler_delay_figure(drv)
    pd.drive_topview(drv)
    truth = np.column_stack([np.linspace(0.0, 10.0, 5), np.zeros(5), np.zeros(5)])
    pj.trajectories_figure(truth, {"JAVELIN": truth + 0.1})
    t3.paths_table_figure([{"a": 1, "b": 2.0}])
    t3.wave_origins_figure({"x": np.array([[1.0, 2.0, 3.0]])})


def _consistency():
    """The geometry-consistency test (after the route drivers: their first calls of the
    extraction's bounds stay the recorded ones)."""
    from tunnelkit.consistency import consistent_paths, geometry_consistency, tunnel_planes
    from tunnelkit.path_consistency import bound_sigmas, epoch_consistency
    from tunnelkit.signal_route import SignalRoute

    route = SignalRoute.from_scenario("italiano2026-straight")
    ep = route.epoch(10, np.random.default_rng(0))
    m = ep.measurements
    planes = tunnel_planes(route.tunnel)
    geometry_consistency(m.direction, m.d, m.origin, planes, 1e-3, 1e-3, 0.05)
    consistent_paths(m, route.tunnel, sigma_phi=1e-3, sigma_psi=1e-3, sigma_d=0.05)
    bound_sigmas(ep.estimates, ep.array, route.config, ep.measurements.source)
    epoch_consistency(ep, route, bound=False, floor_angle=1e-2, floor_range=0.3)


def _traced():
    """The traced design's pieces and the joint bound of the geometry test (image channel, one
    epoch; the stored traced errors)."""
    import tempfile

    from tunnelkit.path_consistency import joint_bound, joint_fisher, rate_interval
    from tunnelkit.simulation import prefilter as pre
    from tunnelkit.simulation.drives import scenario_route
    from tunnelkit.studies import traced as tr

    route = scenario_route("italiano2026-straight")
    ep = route.epoch(10, np.random.default_rng(0), refine="ml")
    joint_bound(ep.estimates, ep.array, route.config, ep.measurements.source)
    pos = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0]])
    src = np.array([[0.3, 0.2, 4.0], [-0.5, 0.4, 6.0]])
    joint_fisher([1.0 + 0.5j, 0.5j], src, pos, [-0.7, -1.1], [0.05, -0.02], 4, 3, 0.3, 3.5e9)
    rate_interval(3, 50)
    pre.geometry_labels(ep, route)
    pre.geometry_keep(ep, route)
    pre.traced_measurements(ep, route)
    from tunnelkit.studies.los_only import flagged_los

    flagged_los(ep, route)
    from tunnelkit.studies.robust_update import HuberUpdater, huber_weights
    from tunnelkit.tracking.javelin.update import StackedMeasurement

    m = StackedMeasurement(
        np.array([0.1, 3.0]), np.zeros(2), np.eye(2), np.diag([0.01, 0.01]),
        np.array([True, False]), [("phi", 0, 0), ("psi", 0, 0)], None,
    )  # fmt: skip
    HuberUpdater(1.345).update(np.zeros(2), np.eye(2), m)
    huber_weights(m.z, m.H, np.eye(2), m.R, 1.345)
    from tunnelkit.consistency import plane_kinds

    plane_kinds(route.tunnel)
    every = tr.simulate_traced("italiano2026-straight", np.random.default_rng(0), n_epochs=3)
    from tunnelkit.design.los import (
        ElevationSigmas,
        elevation_sigmas,
        los_error_rows,
        los_errors,
        told_by_elevation,
    )

    err = los_errors([every["ml-all"]])
    los_error_rows(np.array([0.1]), np.array([-0.2]), np.array([[10.0, 1.0, -4.0]]))
    table = elevation_sigmas(np.vstack([err, err]), 2)
    ElevationSigmas.from_dict(table.as_dict()).at(np.array([-0.1]))
    table.describe()
    told_by_elevation(every["ml-all"], table, 1.5, 1.0)
    tr.write_traced_errors(tr.traced_errors(), tempfile.mkdtemp() + "/traced_errors.json")
    tr.traced_design()
    cur = pre.scene_provenance()
    pre.check_provenance({"rows": [], **cur}, cur)
    from tunnelkit.studies.traced_bound import traced_pcrlb

    traced_pcrlb("italiano2026-straight")
    from tunnelkit.reproduce import javelin_traced as jtr

    los_table, summary = jtr.los_survey("italiano2026-straight")
    jtr.los_drive(every["ml-all"], los_table)
    jtr.los_note(summary)
    jtr.traced_note({"diffuse_floor": True}, {"rt_settings": cur.get("rt_settings")})
    from tunnelkit.reproduce import javelin_direct as jd

    jd.direct_table("italiano2026-straight")
    jd.direct_note("italiano2026-straight")
    jd.direct_scores("italiano2026-straight", 1, np.random.default_rng(0))


def _odometry():
    """The odometry model, dead reckoning and its bound on a 46-epoch drive (and with a radio's
    information); a tracker's state told the model; the drift study on four drives of 100 m."""
    from tunnelkit.odometry import Odometry
    from tunnelkit.reckoning import dead_reckoning, dead_reckoning_bound, posterior_bound
    from tunnelkit.studies.odometry import drift, drift_rows, drift_table
    from tunnelkit.tracking.javelin import JavelinConfig, JavelinState
    from tunnelkit.tracking.javelin.motion import odometry_transition
    from tunnelkit.tracking.javelin.odometrystates import kinematic, odometry_columns
    from tunnelkit.tracking.javelin.state import first_vue

    t = np.arange(46) * 0.1
    v, th = np.full(46, 22.0), 0.01 * t
    odo = Odometry(
        speed_scale=0.01, heading_bias=0.02, heading_drift=1e-4, yaw_rate_bias=5e-5, rate=10.0,
        dropout=0.1,
    )  # fmt: skip
    Odometry.white(0.2, 0.02)
    odo.schedule(t)
    s, h = odo.draw(t, v, th, np.random.default_rng(0))
    dead_reckoning(t, s, h, np.zeros(2))
    from tunnelkit.tracking.javelin.motion import midpoint_messages

    midpoint_messages(s, h)
    dead_reckoning_bound(t, v, th, odo, 0.5, np.isfinite(s))
    posterior_bound(t, v, th, odo, np.tile(np.eye(2), (46, 1, 1)), 0.5, np.isfinite(s))
    cfg = JavelinConfig().told(odo)
    st = JavelinState.initial([-30.0, 1.0, 1.0], 1.0, odometry=cfg.odometry_sigmas)
    st.append([2.0, 1.0], np.eye(2))
    first_vue(3), kinematic(st.x, 3), odometry_columns(np.zeros((2, 4, 5)), 3)
    odometry_transition(st, 10.0, 0.1, 0.1)
    d = drift(odo, n_drives=4, seed=0, length=100.0, speed=22.0, epoch_rate=10.0)
    d.at([40.0, 100.0])
    drift_table(drift_rows(4, 0, (40.0, 100.0)))
    # a scenario's [odometry] (the Mont Blanc preset declares a car's), and a design told it
    from tunnelkit.design.arrayjob import javelin_config
    from tunnelkit.design.los import los_angle_information, los_path
    from tunnelkit.scenarios import load_scenario
    from tunnelkit.scenarios.odometry import odometry_from_scenario

    los_angle_information(np.array([[20.0, -1.5, 1.5]]), np.array([0.0, 0.0, 6.0]), 0.02)
    from tunnelkit.design.los import angle_sigma

    angle_sigma("sigma", 0.02)
    los_path(np.array([10.4, 10.1]), np.array([0.1, -0.1]), 0.3)
    car = odometry_from_scenario(load_scenario("mont-blanc-28ghz"))
    assert car.label == "automotive"
    javelin_config({"d": 0.01, "direction": 0.001, "kappa": 1.0}, 0.0, None, car)


def _trial(rng):
    """A Monte-Carlo trial for the runner's contract (module level: picklable)."""
    return float(rng.random())


DRIVERS = (
    _jiang,
    _javelin,
    _widgets,
    _signal_route,
    _studies,
    _direct,
    _odometry,
    _doppler,
    _fresnel,
    _design,
    _baselines,
    _baselines_tracking,
    _known_surfaces,
    _baselines_checks,
    *ROUTE_DRIVERS,
    _consistency,
    _traced,
    *DESIGN_DRIVERS,
    *BASELINE_DRIVERS,
)


def _safe(fn):
    def run():
        try:
            fn()
        except Exception as exc:  # a workflow that broke: the callables it misses show
            print(f"workflow {fn.__name__} stopped: {type(exc).__name__}: {exc}", file=sys.stderr)

    return run


# --- filling the rest ------------------------------------------------------------------------

BY_NAME: dict[str, object] = {
    "fc": 5.9e9,
    "rng": None,  # a fresh generator per case
    "seed": 0,
}


class NoValue(Exception):
    pass


def neutral(p: inspect.Parameter, tp) -> object:
    """A valid-looking value for a parameter no workflow reached: default, name, annotation."""
    if p.default is not inspect.Parameter.empty:
        return p.default
    if p.name in BY_NAME:
        v = BY_NAME[p.name]
        return np.random.default_rng(0) if p.name == "rng" else v
    if tp is np.random.Generator:
        return np.random.default_rng(0)
    if tp is float:
        return 1.0
    if tp is int:
        return 2
    if tp is bool:
        return False
    raise NoValue(p.name)


def fill_arguments(target: Target, recorded: dict | None) -> tuple[dict, list[str]]:
    """({parameter: valid value}, [parameters with no known valid value])."""
    import dataclasses

    h = hints(target)
    out, missing = {}, []
    factories = {}
    if target.kind == "class" and dataclasses.is_dataclass(target.obj):
        factories = {
            f.name: f.default_factory
            for f in dataclasses.fields(target.obj)
            if f.default_factory is not dataclasses.MISSING
        }
    for p in parameters(target):
        if recorded is not None and p.name in recorded:
            out[p.name] = recorded[p.name]
            continue
        if p.name in factories:
            out[p.name] = factories[p.name]()
            continue
        try:
            out[p.name] = neutral(p, h.get(p.name, inspect.Parameter.empty))
        except NoValue:
            missing.append(p.name)
    if recorded is not None:  # the recorded *args / **kwargs, as called
        out.update({k: v for k, v in recorded.items() if k.startswith("*")})
    return out, missing


DRIVERS = tuple(_safe(d) for d in DRIVERS)


def fresh(value):
    """A copy of a valid value for one call (a generator restarts, arrays are copied)."""
    if isinstance(value, np.random.Generator):
        return np.random.default_rng(0)
    return _keep(value)


def invoke(target: Target, this, kwargs: dict):
    """Call ``target`` with ``kwargs`` (positional-only parameters passed by position)."""
    params = parameters(target)
    kw = {k: v for k, v in kwargs.items() if not k.startswith("*")}
    var_pos = next((v for k, v in kwargs.items() if k[:1] == "*" and k[:2] != "**"), ())
    var_kw = next((v for k, v in kwargs.items() if k[:2] == "**"), {})
    # positional-only parameters by position; with recorded *args, every parameter before them
    P = inspect.Parameter
    by_position = (P.POSITIONAL_ONLY, P.POSITIONAL_OR_KEYWORD) if var_pos else (P.POSITIONAL_ONLY,)
    pos = [kw.pop(p.name) for p in params if p.kind in by_position and p.name in kw]
    pos += list(var_pos)
    kw = {**var_kw, **kw}
    short = target.name.rsplit(".", 1)[1]
    if target.kind == "class":
        return target.obj(*pos, **kw)
    if target.kind == "classmethod" and this is not None:
        return getattr(this, short)(*pos, **kw)
    if target.kind in ("classmethod", "staticmethod"):
        return getattr(target.owner, short)(*pos, **kw)
    if target.kind == "method":
        return getattr(this, short)(*pos, **kw)
    return target.obj(*pos, **kw)
