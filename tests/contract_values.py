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
from contracts import Target, function_of, hints, parameters


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
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, np.random.Generator):
        return value  # copied per case
    try:
        return copy.deepcopy(value)
    except Exception:
        return value


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
            this = None
            if t.kind == "method":
                this = loc.get(next(iter(frame.f_code.co_varnames), "self"))
                if not isinstance(this, t.owner):
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
    from tunnelkit import crlb, geometry, metrics, positioning
    from tunnelkit.tracking import virtual_station as vs

    sc = tk.load_scenario("jiang2023-straight")
    tunnel = sc.tunnel()
    bs = sc.base_station()
    st = tunnel.virtual_stations(bs)
    geometry.virtual_stations(bs, list(tunnel.walls))
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
    from tunnelkit.extraction import extract_paths, path_crlb

    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    rng = np.random.default_rng(0)
    ep = route.epoch(10, rng)
    arr, paths = route.paths(10)
    snap = route.snapshot(paths, arr, rng)
    route.ml_noise_power(10, snap)
    extract_paths(snap.H, len(paths), arr, route.config, refine="joint")
    path_crlb(paths, arr, route.config)
    from tunnelkit.propagation import second_order_paths

    traj = route.trajectory
    second_order_paths(route.tunnel, arr, traj.position[10], traj.velocity[10], fc=route.config.fc)
    del ep


def _studies():
    from tunnelkit import studies

    studies.simulate_routes(
        "italiano2026-straight",
        np.random.default_rng(0),
        extractions=("paper",),
        n_epochs=3,
    )


def _doppler():
    from tunnelkit import drive as dv
    from tunnelkit.tracking import doppler as dp

    d = dv.make_drive(duration=8.0, pass_time=4.0)
    meas = dv.measure(d, np.random.default_rng(0))
    dp.run_approaches(d, meas, dv.gnss_fix(d, np.random.default_rng(1)))


def _fresnel():
    from tunnelkit import fresnel

    s = fresnel.mmax_summary(R=100.0, W=10.0, y_u=2.0, fc=5.9e9, eps_phi=np.pi / 8)
    fresnel.design_report([dict(R=100.0, W=10.0, y_u=2.0, fc=5.9e9, eps_phi=np.pi / 8)])
    del s


def _design():
    from tunnelkit import design

    setup = design.DesignSetup.from_scenario("italiano2026-straight")
    design.route_bounds(setup, "4x4", epochs=[5, 10])
    design.achievable_bound(setup, "4x4", design.DesignImpairments(), epochs=[5, 10])


def _javelin():
    from tunnelkit.tracking.javelin import JavelinConfig, JavelinDesign, run_javelin
    from tunnelkit.tracking.javelin.geometric import geometric_stream, toy_drive, toy_reflectors

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


def _widgets():
    from tunnelkit import widgets

    widgets.mmax_figure()
    widgets.crlb_figure()
    widgets.upf_figure(n_particles=20)
    widgets.curvature_figure(side=4)


DRIVERS = (_jiang, _javelin, _widgets, _signal_route, _studies, _doppler, _fresnel, _design)


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
    pos = [kwargs[p.name] for p in params if p.kind is p.POSITIONAL_ONLY and p.name in kwargs]
    kw = {
        k: v
        for k, v in kwargs.items()
        if not any(p.name == k and p.kind is p.POSITIONAL_ONLY for p in params)
    }
    short = target.name.rsplit(".", 1)[1]
    if target.kind == "class":
        return target.obj(*pos, **kw)
    if target.kind in ("classmethod", "staticmethod"):
        return getattr(target.owner, short)(*pos, **kw)
    if target.kind == "method":
        return getattr(this, short)(*pos, **kw)
    return target.obj(*pos, **kw)
