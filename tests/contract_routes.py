"""More recorded valid calls for the contract suite (:mod:`contract_values`): the signal route's
lower layers no teaching workflow reaches on its own (the maximum-likelihood fit's pieces, the
ray tracer's containers and comparisons, the drive's profiles). The ray tracer is reached through
its image engine and hand-built element paths only: no Sionna scene is loaded (a forked case
must never start Dr.Jit)."""

from __future__ import annotations

import tempfile
from pathlib import Path as FsPath

import numpy as np


def _small_epoch():
    """A small tensor (all antennas, 8 tones, 4 symbols: the shape whose residual threshold the
    signal-route workflow calibrates already) of the straight preset at epoch 10."""
    from tunnelkit import signal_route

    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    arr, paths = route.paths(10)
    snap = route.snapshot(paths, arr, np.random.default_rng(0))
    return route, arr, paths, snap, snap.H[:, :8, :4]


def route_fit():
    """The ML fit's pieces on a small tensor, an epoch with other estimates, one-call epochs."""
    from tunnelkit import signal_route
    from tunnelkit.extraction import estimate_crlb, extract_paths
    from tunnelkit.extraction.ml import given_start, model, order, rank_one, wideband

    route, arr, trace, _, H = _small_epoch()
    cfg = route.config
    L = len(trace)
    est = extract_paths(H, L, arr, cfg)
    estimate_crlb(est, arr, cfg)
    start = (np.column_stack([est.direction[:, :2], np.zeros(L)]), est.mu_f, est.mu_t)
    fit = given_start.fit_ml(H, start, arr, cfg, max_iter=3, n_reseed=0)
    model.noise_floor(H, L)
    order.ml_order(H, arr, cfg, max_paths=2, max_iter=3)
    prob = model.Problem(H, arr.local, cfg.fc)
    rank_one.search_path(H, prob)
    rank_one.complete_paths(prob, (fit.theta[:1], fit.mu_f[:1], fit.mu_t[:1]), 2)
    wb = wideband.WidebandProblem(H, arr.local, cfg.fc, cfg.tone_spacing)
    ev = wb.evaluate(fit.theta, fit.mu_f, fit.mu_t)
    wb.model(fit.theta, fit.mu_f, fit.mu_t, ev["c"])
    ep = signal_route.simulate_epoch("italiano2026-straight", 10, np.random.default_rng(1),
                                     refine="none")  # fmt: skip
    ep.with_estimates(ep.estimates)


def route_rt():
    """The ray tracer's containers, comparisons, settings and scene files (no Sionna)."""
    import tunnelkit as tk
    from tunnelkit import rt
    from tunnelkit.constants import C
    from tunnelkit.doppler_drive import delay_doppler_profiles, make_drive
    from tunnelkit.rt import mitsuba

    sc = tk.load_scenario("italiano2026-straight")
    route = tk.signal_route.SignalRoute.from_scenario(sc)
    tun, (arr, paths) = route.tunnel, route.paths(10)
    ue = route.trajectory.position[10]
    image = rt.compute_paths(tun, arr, ue, route.trajectory.velocity[10], fc=route.config.fc)
    rows = rt.compare_paths(image, paths)
    import dataclasses

    from tunnelkit import propagation

    path = propagation.Path(
        **{f.name: getattr(paths[1], f.name) for f in dataclasses.fields(paths[1])}
    )
    path.kappa("srnf"), path.wave_origin("srnf"), path.delta("srnf")  # the tracer builds unchecked
    rt.worst_errors(rows)
    rt.plate_occluders(tun, paths[-1], ue, arr.origin)
    rt.lower_into_tunnel(tun, arr)
    settings = rt.RTSettings.from_scenario(sc)
    settings.material_for("wall")
    d = FsPath(tempfile.gettempdir()) / "tunnelkit-contract-scene"  # reused by every case
    scene = rt.export_tunnel(tun, d)
    rt.read_scene(scene.xml)
    mitsuba.SurfaceInfo("wall-left", "wall", "concrete")
    rt.time_engines(tun, arr, ue, route.trajectory.velocity[10], fc=route.config.fc, repeat=1,
                    engines=("image",))  # fmt: skip
    chan = rt.RayTracedChannel(tun, route.arrays, route.trajectory, route.config, settings,
                               label="contract", cache_dir=d / "cache")  # fmt: skip
    chan.key()
    chan.directory()
    rt.RayTracedChannel.variant(tun)
    rng = np.random.default_rng(0)
    pos = np.c_[np.stack(np.meshgrid(np.arange(3), np.arange(3)), -1).reshape(-1, 2) * 0.025,
                np.zeros(9)]  # fmt: skip
    src = np.array([[20.0, 3.0, 1.0], [21.0, -4.0, 2.0]])
    dist = np.linalg.norm(src[:, None] - pos[None], axis=2).T
    tau = np.c_[dist / C, 30 / C + rng.uniform(0, 1e-8, (9, 2))]
    gain = np.c_[1 / dist, rng.uniform(1e-3, 2e-3, (9, 2))] * np.exp(-2j * np.pi * 5.9e9 * tau)
    ep = rt.ElementPaths(
        tau=tau,
        gain=gain,
        doppler=rng.uniform(-500, 500, (9, 4)),
        valid=np.ones((9, 4), bool),
        order=np.tile([0, 1, 2, 1], (9, 1)),
        diffuse=np.tile([False, False, False, True], (9, 1)),
        first_object=np.tile([-1, 7, 8, 9], (9, 1)),
    )
    ep.mask("los"), ep.power("all"), ep.count("all")
    rt.element_tensor(ep, 240e3, 16, 35.7e-6, 4)
    rt.tensor_components(ep, 5.9e9, 240e3, 16, 35.7e-6, 4)
    rt.first_order_groups(ep)
    delay_doppler_profiles(make_drive(duration=2.0, pass_time=1.0), every=4)


DRIVERS = (route_fit, route_rt)
