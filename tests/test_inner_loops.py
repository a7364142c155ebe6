"""The filters' inner loops are bit for bit the checked public functions they stand in for.

The Monte-Carlo filters call their measurement models once per sigma point, particle cloud or
epoch; there the model's own input checks cost more than its arithmetic, so the filters call
unchecked twins (and ``wrap_angle`` skips its floating-point ``mod`` where it changes nothing).
Each twin must return exactly the bytes of the checked form, or the reproduced tables move.
"""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit import crlb
from tunnelkit import doppler_drive as dv
from tunnelkit.tracking import doppler as dp
from tunnelkit.tracking import virtual_station as vs
from tunnelkit.tracking.doppler import approaches


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def _angles(rng, shape):
    """Angles inside (-pi, pi], far outside, and on the edges of the wrap."""
    a = rng.uniform(-np.pi, np.pi, shape)
    flat = a.reshape(-1)
    flat[::7] *= 40.0
    edges = [np.pi, -np.pi, 0.0, -0.0, 3 * np.pi, -3 * np.pi, 2 * np.pi, np.nextafter(np.pi, 0)]
    k = min(len(edges), flat.size - 1)
    flat[1 : 1 + k] = edges[:k]
    return a


@pytest.mark.parametrize("shape", [(5,), (9, 2), (8, 50, 9, 2), ()])
def test_wrap_angle_equals_the_plain_formula(shape):
    rng = np.random.default_rng(3)
    a = _angles(rng, shape) if shape else np.float64(7.5)
    plain = np.pi - np.mod(np.pi - a, 2.0 * np.pi)
    assert _same(crlb.wrap_angle(a), plain)
    w = crlb.wrap_angle(a)
    assert np.all((w > -np.pi) & (w <= np.pi))


@pytest.mark.parametrize("los", [False, True])
def test_the_model_s_unchecked_twins_equal_hx_and_residual_z(los):
    m = vs.model_from_scenario("jiang2023-straight", level=2, los=los)
    rng = np.random.default_rng(4)
    for shape in [(4,), (9, 4), (8, 40, 9, 4)]:
        x = rng.normal(size=shape) * 30.0 + np.array([40.0, 1.0, 10.0, 0.0])
        assert _same(m._h(x), m.hx(x))
        z = m.hx(x)
        b = z + rng.normal(size=z.shape) * 4.0  # bearings well outside (-pi, pi]
        assert _same(m._residual(z, b), m.residual_z(z, b))
        if z.ndim > 1:  # broadcasting against one reference row, as z_mean does
            assert _same(m._residual(z, b[..., :1, :]), m.residual_z(z, b[..., :1, :]))


def test_the_doppler_ekf_s_measurement_functions_equal_the_checked_model():
    drive = dv.make_drive(dv.load_drive_config("halili2022-drive"))
    setup = dp.DopplerSetup.from_drive(drive)
    fix = dv.gnss_fix(drive, np.random.default_rng(0))
    ekf = dp.DopplerEKF(setup, fix)
    s = np.concatenate([drive.position, drive.velocity], axis=1)[::37]
    s = np.vstack([s, [[setup.tx[0], setup.tx[1], 20.0, 0.5]]])  # under the transmitter
    for row in s:
        col = row.reshape(4, 1)
        assert _same(ekf._h(col), dp.doppler_model(row, setup).reshape(1, 1))
        assert _same(ekf._H(col), dp.doppler_jacobian(row, setup))


def test_the_phase_median_is_numpy_s():
    rng = np.random.default_rng(5)
    for n in range(1, 6):
        for _ in range(50):
            v = list(rng.normal(size=n) * 100)
            assert approaches._median(v) == float(np.median(v))


@pytest.mark.parametrize("order", [1, 2])
def test_traced_paths_are_what_the_checked_path_record_accepts(order):
    """The tracer builds its paths unchecked (several per epoch); each one, rebuilt through the
    checked constructor, passes every field check and equals the traced one."""
    import dataclasses

    from tunnelkit import propagation, signal_route

    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    for k in (0, 10, len(route.trajectory) - 1):
        ue, vel = route.trajectory.position[k], route.trajectory.velocity[k]
        arr = propagation.select_array(route.arrays, ue)
        paths = propagation.trace_paths(route.tunnel, arr, ue, vel, fc=route.config.fc, order=order)
        assert paths
        for p in paths:
            q = propagation.Path(*(getattr(p, f.name) for f in dataclasses.fields(p)))
            for f in dataclasses.fields(p):
                assert _same(getattr(p, f.name), getattr(q, f.name)), f.name


def test_the_tracer_s_unchecked_surface_tests_equal_the_checked_ones():
    from tunnelkit import signal_route
    from tunnelkit.propagation import truck_box

    tun = signal_route.SignalRoute.from_scenario("italiano2026-straight").tunnel
    tun = tun.with_blockers(truck_box(20.0, 0.0), truck_box(60.0, -2.0))
    rng = np.random.default_rng(6)
    a = rng.uniform([-10.0, -5.0, 0.0], [110.0, 5.0, 5.0], (200, 3))
    b = rng.uniform([-10.0, -5.0, 0.0], [110.0, 5.0, 5.0], (200, 3))
    assert _same(tun._blocked(a, b), tun.blocked(a, b))
    for box in tun.blockers:
        assert _same(box._blocks(a, b), box.blocks(a, b))
    for f in tun.surfaces:
        for tol in (1e-9, 0.0, -1e-4):
            assert _same(f._contains(a, tol), f.contains(a, tol=tol))


def test_the_extraction_numerics_unchecked_twins_equal_the_checked_functions():
    """The fits (ml.fitting, ml.model, coherent, joint.refine_joint) call the unchecked twins of
    ``extraction.numerics``: same bytes as the checked public forms, including the singular
    fall-back of ``solve``, the held coordinates of ``free_newton`` and ``damped_step``'s None."""
    from tunnelkit.extraction import linalg as la
    from tunnelkit.extraction import numerics as nm

    rng = np.random.default_rng(6)
    for n in (1, 4, 10):
        J = rng.normal(size=(3 * n, n)) + 1j * rng.normal(size=(3 * n, n))
        G = J.conj().T @ J
        B = rng.normal(size=(n, 2)) + 1j * rng.normal(size=(n, 2))
        assert _same(nm.solve_unchecked(G, B), la.solve(G, B))
        assert _same(nm.solve_unchecked(G, B[:, 0]), la.solve(G, B[:, 0]))
        S = np.outer(J[0], J[0].conj())  # rank one: the least-squares fall-back
        assert _same(nm.solve_unchecked(S, B), la.solve(S, B))
        A = (J.conj().T @ J).real
        g = rng.normal(size=n)
        lower, upper = rng.random(n) < 0.3, rng.random(n) < 0.3
        upper &= ~lower
        f1, d1 = nm.free_newton_unchecked(A, g, lower, upper)
        f2, d2 = la.free_newton(A, g, lower, upper)
        assert _same(f1, f2) and d1 == d2
        for lam in (1e-9, 1e-3, 10.0):
            assert _same(nm.damped_step_unchecked(A, g, f2, lam), la.damped_step(A, g, f2, lam))
    Z = np.zeros((3, 3))
    assert nm.damped_step_unchecked(Z, np.ones(3), np.ones(3, bool), 0.0) is None
    p = np.column_stack([rng.normal(size=(16, 2)) * 0.02, np.zeros(16)])
    th = np.column_stack([rng.uniform(-0.7, 0.7, (5, 2)), rng.uniform(0, 0.5, 5)])
    th[0] = (0.0, 0.0, 0.0)  # far field, broadside
    for a, b in zip(nm.spatial_phase_unchecked(th, p, 587.0), nm.spatial_phase(th, p, 587.0)):
        assert _same(a, b)
    H = rng.normal(size=(4, 7, 3)) + 1j * rng.normal(size=(4, 7, 3))
    F = np.exp(1j * rng.normal(size=(7, 2)))
    T = np.exp(1j * rng.normal(size=(3, 2)))
    assert _same(nm.contract_unchecked(H, F, T), nm.contract(H, F, T))


def _same_field(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return _same(a, b)
    return type(a) is type(b) and a == b


def _rebuilt_equal(rec) -> None:
    """``rec`` (built unchecked) passes its checked constructor and equals what it builds."""
    import dataclasses

    fs = [f for f in dataclasses.fields(rec) if f.init]
    again = type(rec)(*(getattr(rec, f.name) for f in fs))
    for f in dataclasses.fields(rec):
        assert _same_field(getattr(rec, f.name), getattr(again, f.name)), (type(rec), f.name)


@pytest.mark.parametrize("design", ["paper", "ours", "consider"])
def test_javelin_step_records_built_unchecked_are_what_the_checked_records_accept(design):
    """One JAVELIN step builds its report, association costs, management result, stacked
    measurement and sanitised paths unchecked (from what the step has checked or computed):
    over a drive with outliers, clutter and dropped epochs each one, rebuilt through the checked
    constructor, passes every field check and equals the unchecked one, byte for byte."""
    import warnings

    from javelin_geometric import geometric_stream, toy_drive, toy_reflectors

    from tunnelkit.tracking.javelin import (
        ConsiderNoise,
        Javelin,
        JavelinDesign,
        JavelinWarning,
        PathMeasurements,
        designs,
    )
    from tunnelkit.tracking.javelin.measurement import track_model
    from tunnelkit.tracking.javelin.update import stack_measurement

    bs = (0.0, 0.0, 4.8)
    rng = np.random.default_rng(7)
    P, V = toy_drive(120, 0.1, amplitude=1.0, speed=4.0)
    eps = geometric_stream(
        P, V, toy_reflectors(), rng, los_probability=0.8, bs=bs, sigma_phi=0.02,
        sigma_psi=0.02, sigma_kappa=1.0, sigma_d=0.3, sigma_v=0.05,
        clock_bias=lambda r: r.normal(0.0, 3.0),
    )  # fmt: skip
    eps = list(eps)
    for k in range(5, len(eps), 17):  # an outlier path, a NaN angle, a negative delay
        pm = eps[k]
        n = len(pm)
        phi, d = pm.phi.copy(), pm.d.copy()
        phi[0] += 1.0
        if n > 1:
            phi[1], d[-1] = np.nan, -5.0
        cov = np.broadcast_to(np.diag([0.02**2, 0.02**2, 1.0]), (n, 3, 3)).copy()
        rep = np.zeros((n, 4, 4))
        rep[:, :3, :3], rep[:, 3, 3] = 0.5 * cov, 0.5 * 0.3**2
        eps[k] = PathMeasurements(phi, pm.psi, pm.kappa, d, pm.v, pm.source, cov,
                                  np.full(n, 0.3), rep)  # fmt: skip
    eps[9] = None
    if design == "consider":
        cfg = JavelinDesign(designs.ours().config, noise=ConsiderNoise())
    else:
        cfg = getattr(designs, design)()
    trk = Javelin(P[0], cfg.with_(base_station=bs, sigma_p0_ue=1.0))
    spd, hdg = np.linalg.norm(V[:, :2], axis=1), np.arctan2(V[:, 1], V[:, 0])
    seen = set()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", JavelinWarning)
        for k in range(1, len(eps)):
            if eps[k] is not None:
                clean, _ = eps[k].sanitised(-10.0)
                _rebuilt_equal(clean)
            x, Pk, C = trk.state.x.copy(), trk.state.P.copy(), trk.state.C
            rep = trk.step(eps[k], spd[k - 1], hdg[k - 1], 0.1)
            for r in (rep, rep.costs, rep.manage, rep.paths):
                if r is not None:
                    _rebuilt_equal(r)
                    seen.add(type(r).__name__)
            if rep.manage is not None and rep.manage.pairs:
                pred, J = track_model(x, bs)
                if J.shape[-1] == x.size and rep.paths is not None:
                    pairs = [(i, j) for i, j in rep.manage.pairs if i < len(pred)]
                    m = stack_measurement(
                        pred, J, rep.paths, pairs, trk.config, None, cfg.noise,
                        C if getattr(cfg.noise, "consider", False) else None,
                    )  # fmt: skip
                    _rebuilt_equal(m)
                    seen.add(type(m).__name__)
            del Pk
    assert {"StepReport", "AssociationCosts", "ManageResult", "PathMeasurements"} <= seen
    assert "StackedMeasurement" in seen


def test_damped_system_and_solve_are_damped_step_in_two_parts():
    """A fit that raises the damping at the same point builds the scaled system once
    (linalg.damped_system) and solves it per damping (damped_solve): bit for bit the step."""
    from tunnelkit.extraction import linalg as la

    rng = np.random.default_rng(3)
    J = rng.normal(size=(9, 5))
    A, g = J.T @ J, rng.normal(size=5)
    for free in (np.ones(5, bool), np.array([True, False, True, True, False])):
        system = la.damped_system(A, g, free)
        for lam in (1e-3, 0.1, 10.0):
            np.testing.assert_array_equal(
                la.damped_solve(system, lam), la.damped_step(A, g, free, lam)
            )
    with pytest.raises(ValueError, match="lam"):
        la.damped_solve(system, -1.0)
    with pytest.raises(TypeError, match="system"):
        la.damped_solve((A, g), 0.1)


def test_free_newton_holds_a_negative_curvature_of_a_degenerate_fit():
    """Two paths merging make the Gram matrix of the fit's atoms near singular and its Schur
    complement ``A`` lose its positive diagonal to rounding (seen on the ray-traced slalom: -1.3e16
    beside 9e17). Such a coordinate is held: the decrement stays finite and LAPACK is never handed
    an overflowed matrix (it printed "DLASCL parameter number 4 had an illegal value")."""
    import warnings

    from tunnelkit.extraction import linalg as la

    rng = np.random.default_rng(11)
    n = 10
    J = rng.normal(size=(3 * n, n))
    A = J.T @ J
    bad = [3, 7]
    for i in bad:  # a rounding-ruined row: a negative diagonal, huge entries around it
        A[i, :] = A[:, i] = 1e16 * rng.normal(size=n)
        A[i, i] = -1.3e16
    A[3, 7] = A[7, 3] = 1.4e16
    g = rng.normal(size=n)
    none = np.zeros(n, bool)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow, no invalid value
        free, dec = la.free_newton(A, g, none, none)
        step = la.damped_step(A, g, free, 1e-3)
    assert not free[bad].any() and free.sum() == n - len(bad)
    assert np.isfinite(dec) and dec > 0 and np.all(np.isfinite(step)) and not step[bad].any()
    # the held coordinates aside, it is the Newton step of the rest
    keep = np.setdiff1d(np.arange(n), bad)
    want = g[keep] @ np.linalg.solve(A[np.ix_(keep, keep)], g[keep])
    assert dec == pytest.approx(want, rel=1e-9)
    # a zero curvature beside a coupling is held too; a zero row (a path of zero gain) is free
    Z = np.array([[0.0, 1e16, 0.0], [1e16, 0.0, 0.0], [0.0, 0.0, 0.0]])
    Z[2, 2] = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fz, dz = la.free_newton(np.pad(Z, ((0, 1), (0, 1))) + np.diag([0, 0, 0, 2.0]),
                                np.ones(4), np.zeros(4, bool), np.zeros(4, bool))  # fmt: skip
    assert fz.tolist() == [False, False, True, True] and dz == pytest.approx(0.5)
    # a positive semi-definite A is untouched: every coordinate free, as before
    f2, d2 = la.free_newton(J.T @ J, g, none, none)
    assert f2.all() and np.isfinite(d2)
