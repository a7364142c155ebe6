"""More recorded valid calls for the contract suite (:mod:`contract_values`): the design's error
model, bounds over the drive, fast route and sweep on a few epochs of a 4 x 4 array, and the
tracking pieces no teaching workflow hands a valid argument to (a costs matrix, a drive, a UPF
cloud). Kept short: every generated case repeats its callable's call."""

from __future__ import annotations

import warnings

import numpy as np

SCENARIO = "italiano2026-straight"


def design_models():
    """Path error model, bounds over the drive, the fast route and its drive, the mode vectors of
    the misspecified bound."""
    from tunnelkit import design
    from tunnelkit.design import drivebound, errordraws, errormodel, fastroute, mcrb, trackerfix

    setup = design.DesignSetup.from_scenario(SCENARIO)
    imp = design.DesignImpairments(phase_error_deg=0.5, gain_error_db=0.2)
    design.path_error_model(setup, "4x4", imp, epochs=[5, 10])  # the recorded (short) call
    g = design.route_geometry(setup, "4x4")
    m = design.path_error_model(setup, "4x4", imp, geometry=g)
    n = m.n_elements
    errordraws.calibration_bias(m, np.zeros(n), np.zeros(n))
    errordraws.draw(m, np.random.default_rng(0))
    info = drivebound.position_information(m, g)
    trackerfix.position_error_parts(m, g)
    drivebound.position_bias_rms(m, g)
    drivebound.drive_pcrlb(setup, info)
    fastroute.model_truth(g, setup.fc)
    route = fastroute.bound_route(m, setup, "4x4")
    trackerfix.tracker_weights(route)
    fastroute.bound_drive(route, setup, "4x4", np.random.default_rng(0), n_epochs=5)
    del errormodel, mcrb


def design_modes():
    """:class:`~tunnelkit.design.mcrb.EtaModes` of two epochs (its assembly and scores)."""
    from tunnelkit import design
    from tunnelkit.channel import DiffuseSpec
    from tunnelkit.constants import C
    from tunnelkit.design.mcrb import EtaModes
    from tunnelkit.design.wideband import wideband_score, wideband_terms

    setup = design.DesignSetup.from_scenario(SCENARIO)
    cfg = setup.config
    g = design.route_geometry(setup, "4x4", epochs=[5, 10])
    spec = design.parse_array("4x4")
    pos = spec.local(cfg.fc)
    T = len(g.ue)
    idx = np.argsort(~g.exists, axis=1, kind="stable")[:, :2]
    mask = np.take_along_axis(g.exists, idx, axis=1)
    src = np.take_along_axis(g.source, idx[..., None], axis=1)
    s_loc = np.einsum("tlj,tjk->tlk", src - g.origin[:, None, :], g.rotation)
    d0 = np.linalg.norm(s_loc, axis=-1)
    alpha = np.sqrt(cfg.tx_power) * np.take_along_axis(g.gain, idx, axis=1)
    mu_f = -2 * np.pi * cfg.tone_spacing * d0 / C
    mu_t = 2 * np.pi * cfg.symbol_period * np.take_along_axis(g.doppler, idx, axis=1)
    modes = EtaModes(s_loc, pos, alpha, mu_f, mu_t, mask, cfg.fc, 16, 4)
    modes.fim(cfg.noise_power)
    modes.assemble(*modes.grams)
    wideband_score(modes, cfg.tone_spacing, wideband_terms(modes, cfg.tone_spacing))
    modes.diffuse_gram(DiffuseSpec(0.1), cfg.tone_spacing, np.zeros(T))


def design_sweep():
    """The Monte-Carlo and the sweep on a few epochs, one run (a channel-route
    Monte-Carlo of at least two drives, takes seconds)."""
    from tunnelkit import design
    from tunnelkit.design import explore, montecarlo

    setup = design.DesignSetup.from_scenario(SCENARIO)
    res = montecarlo.sweep_montecarlo(
        setup, ["4x4"], 1, 0, n_epochs=12, start_sigma=0.5, dead_reckoning=True
    )
    r = next(iter(res.values()))
    r.settled_rms(np.full(len(r.t), 0.1))
    explore.smallest_meeting(setup, ["4x4"], epochs=[5, 10])
    setup.signal_route("4x4")


def design_traced():
    """The design's traced route on one epoch of a 4 x 4 array: its drive (design_drive drives
    it through traced_route and traced_drive; drive_record records one to a temporary file that
    stored_drive reads back), the errors measured on one run into a temporary record (read back
    by design_errors, which checks it), the tracker told them, the summary the JSON carries."""
    import json
    import tempfile

    from tunnelkit import design
    from tunnelkit.design import traced

    setup = design.DesignSetup.from_scenario(SCENARIO, channel="sionna")
    traced.traced_route(setup, "4x4")
    traced.design_drive(setup, "4x4", np.random.default_rng(0), n_epochs=1)
    traced.stored_drive_path(setup, "4x4", n_epochs=1)
    traced.drive_key(setup, "4x4", np.random.default_rng(0), n_epochs=1)
    stored = tempfile.mkdtemp() + "/drive.json"
    with open(stored, "w") as f:
        json.dump(traced.drive_record(setup, "4x4", np.random.default_rng(0), n_epochs=1), f)
    traced.stored_drive(setup, "4x4", np.random.default_rng(0), n_epochs=1, path=stored)
    traced.stored_drive(
        setup, "4x4", np.random.default_rng(0), n_epochs=1, path=stored, kind="ml-all"
    )
    traced.keep_drives(setup, traced.kept_drives(setup))
    traced.design_errors_path(setup, "4x4", n_epochs=1)
    rec = traced.measure_design_errors(setup, "4x4", 1, 0, n_epochs=2)
    path = tempfile.mkdtemp() + "/errors.json"
    with open(path, "w") as fh:
        json.dump(rec, fh, default=str)
    rec = traced.design_errors(setup, "4x4", n_epochs=2, path=path)
    d = traced.traced_javelin(setup, "4x4", rec)
    traced.error_model_summary(rec, d.config)
    sig = {"phi": 0.1, "psi": 0.1, "kappa": 30.0, "d": 1.0}
    from tunnelkit.design import tracedbounds, tracedlos
    from tunnelkit.design.tracedtracker import checked_tracker

    tracedbounds.sigma_error_model(setup, "4x4", sig, epochs=[0, 1])
    tracedbounds.traced_bounds(setup, "4x4", d.config, 2)
    tracedbounds.config_sigmas(d.config)
    # the line-of-sight tracker: its table from the record's survey, the tracker, a drive told
    # it, the told model's figure and what the report says
    table = tracedlos.los_table(rec, 1)
    los = tracedlos.los_javelin(d)
    every = traced.design_drive(setup, "4x4", np.random.default_rng(0), n_epochs=1, kind="ml-all")
    tracedlos.told_los(every, table, los.config)
    tracedbounds.los_bounds(setup, "4x4", table, 2, sigma_p0=0.5)
    traced.error_model_summary(rec, los.config, tracedlos.los_summary(rec, table))
    checked_tracker("los", "channel", "sionna")


def tracking_pieces():
    """A costs matrix, a measured birth, TeNFiLoc and JAVELIN on a short simulated drive, the
    UPF's pieces and the joint innovation test."""
    from tunnelkit import simulation
    from tunnelkit.tracking import upf
    from tunnelkit.tracking import virtual_station as vs
    from tunnelkit.tracking.javelin import (
        Javelin,
        JavelinConfig,
        JavelinState,
        PathMeasurements,
        TeNFiLoc,
    )
    from tunnelkit.tracking.javelin.associate import AssociationCosts, global_nearest_neighbour
    from tunnelkit.tracking.javelin.measuredbirth import MeasuredBirth
    from tunnelkit.tracking.javelin.measurement import track_model
    from tunnelkit.tracking.javelin.update import JointTestUpdater

    rng = np.random.default_rng(0)
    eta2 = np.array([[1.0, 5.0], [4.0, 0.5]])
    global_nearest_neighbour(AssociationCosts(eta2, np.array([2, 2]), eta2 < 4.0, np.full(2, 4.0)))
    st = JavelinState(np.array([0.0, 1.0, 1.5, 2.0, 3.0]), np.eye(5), [1], [0], [False], next_id=2)
    pm = PathMeasurements.from_arrays(
        np.array([0.1, 0.5]), np.array([0.2, 0.3]), np.array([5.0, 6.0]), np.array([4.0, 6.0])
    )
    cfg = JavelinConfig(base_station=(0.0, 0.0, 4.8))
    MeasuredBirth().covariance(st, pm, 1, cfg, None)
    pred, J = track_model(st.x, cfg.bs)
    JointTestUpdater().stack(st.x, st.P, pred, J, pm, [(0, 0), (1, 1)], cfg, 0, None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        drive = simulation.simulate_drive("italiano2026-straight", rng, n_epochs=4)
        TeNFiLoc.for_drive(drive).track(drive)
        Javelin.for_drive(drive).track(drive)
    exp = vs.experiment("jiang2023-straight")
    Z = exp.model.simulate(exp.truth[:3, :2], rng, size=1)
    x0, P0 = exp.truth[0], exp.P0
    upf.one_epoch_ess(exp.model, Z[0], x0, P0, rng=rng, n_particles=20, epochs=2)
    upf.effective_sample_size(np.full((2, 5), 0.2))
    upf.ukf_proposal(exp.model, np.tile(x0, (3, 1)), np.tile(P0, (3, 1, 1)), Z[0, 0])
    vs.VsTSWLS(exp.model, x0, P0).update(Z[0, 0])


def design_sites():
    """A row of sites along a short long-tunnel drive, its route and drive, the study on one
    array and spacing with one run, and JAVELIN on a drive whose epochs name their site."""
    from tunnelkit import design
    from tunnelkit.design import longtunnel, sites
    from tunnelkit.odometry import AUTOMOTIVE

    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    row = sites.SiteRow.along(setup, 100.0, 150.0, speed=sites.LONG_DRIVE_SPEED)
    sites.SiteRow(row.setup, 100.0, count=1, max_range=60.0)
    row.serving(row.setup.trajectory.position[:3])
    route = sites.site_route(row, "4x4", report="auto")
    sites.SiteRoute(route.route, route.rows, route.site, route.origin, route.served, route.offset)
    drive = sites.site_drive(row, route, np.random.default_rng(0), n_epochs=5)
    sites.row_pcrlb(row, route, AUTOMOTIVE, 1.0)
    res = longtunnel.long_tunnel_study(
        setup, ("4x4",), (100.0,), length=150.0, runs=1, seed=0, target=1.0, bin_m=10.0
    )
    res.table(), res.meeting()
    longtunnel.LongTunnelResult(res.rows, 1.0, 150.0, 1, 0, 1.0)
    trial = longtunnel.LongTunnelTrial((row,), (route,), (None,))
    trial(0, np.random.default_rng(0))
    del drive


DRIVERS = (design_models, design_modes, design_sweep, design_traced, design_sites, tracking_pieces)
