"""The design's Monte-Carlo: one task set, the bound-driven measurement route, the posterior bound.

The bound route is tested on a model built here from the route geometry with a diagonal
covariance (no dependence on how the achievable model is filled); the position information is
checked against finite differences of the geometry and against the PEB it must reproduce.
"""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit.constants import C
from tunnelkit.design import DesignSetup
from tunnelkit.design.bounds import route_bounds, route_geometry
from tunnelkit.design.drivebound import (
    drive_bound,
    drive_pcrlb,
    position_bias_rms,
    position_information,
)
from tunnelkit.design.errordraws import (
    calibration_bias,
    draw,
    draw_calibration,
    noise_sqrt,
    split,
)
from tunnelkit.design.errormodel import PathErrorModel
from tunnelkit.design.fastroute import bound_drive, bound_route, model_truth
from tunnelkit.design.geometry import trace_route
from tunnelkit.design.montecarlo import MonteCarloResult, sweep_montecarlo
from tunnelkit.design.trackerfix import BoundRoute

SCENARIO = "example-rectangular-28ghz"


@pytest.fixture(scope="module")
def setup():
    return DesignSetup.from_scenario(SCENARIO)


def _diag_model(setup, spec, sig=(1e-3, 1e-3, 0.05, 0.01), scale=1.0):
    """Truth from the route geometry, diagonal covariance ``sig**2`` per path."""
    g = route_geometry(setup, spec)
    z, v = model_truth(g, setup.fc)
    T, P = g.exists.shape
    var = np.tile((scale * np.asarray(sig)) ** 2, P)
    crlb = np.broadcast_to(np.diag(var), (T, 4 * P, 4 * P)).copy()
    return PathErrorModel(
        t=setup.trajectory.t.copy(),
        exists=g.exists.copy(),
        kinds=tuple(g.kinds),
        truth=z,
        v=v,
        crlb=crlb,
        cov=crlb.copy(),
        bias=np.zeros((T, P, 4)),
    )


def test_bound_drive_hands_the_tracker_truth_plus_clock_bias_and_the_reported_bound(setup):
    m = _diag_model(setup, "8x8", scale=1e-6)  # errors far below what the test resolves
    drive = bound_drive(m, setup, "8x8", np.random.default_rng(0))
    assert drive.reports_covariance and drive.extraction == "bound"
    limit = C * setup.config.clock_bias_limit
    biases = []
    for k, pm in enumerate(drive.epochs):
        slots = drive.truth_index[k]
        assert len(pm) == m.exists[k].sum()  # every path kept (min_d = -c b_max)
        assert np.all(np.diff(pm.d) >= 0)  # ordered by measured delay, not by slot
        assert np.allclose(pm.phi, m.truth[k, slots, 0], atol=1e-8)
        assert np.allclose(pm.kappa, m.truth[k, slots, 2], atol=1e-6)
        b = pm.d - m.truth[k, slots, 3]
        assert np.ptp(b) < 1e-6 and abs(b[0]) <= limit  # one clock bias, within its support
        biases.append(b[0])
        assert np.allclose(pm.cov[:, 0, 0], 1e-18) and np.allclose(pm.sigma_d, 1e-8)
        assert np.allclose(pm.v, m.v[k, slots], atol=0.5)
    assert np.std(biases) > 0.1 * C * setup.config.clock_bias_sigma  # drawn per epoch
    assert drive.truth.shape == (len(setup.trajectory), 3)


def test_bound_drive_errors_follow_the_model_covariance(setup):
    m = _diag_model(setup, "4x4", sig=(2e-3, 3e-3, 0.2, 0.05))
    rng = np.random.default_rng(1)
    err = []
    for _ in range(40):
        dr = bound_drive(m, setup, "4x4", rng)
        for k, pm in enumerate(dr.epochs):
            err.append(pm.phi - m.truth[k, dr.truth_index[k], 0])
    s = np.std(np.concatenate(err))
    assert 0.9 * 2e-3 < s < 1.1 * 2e-3


def test_position_information_matches_finite_differences_of_the_geometry(setup):
    spec = "8x8"
    m = _diag_model(setup, spec)
    g = route_geometry(setup, spec)
    info = position_information(m, g)
    traj = setup.trajectory
    arrays = setup.arrays(spec)
    k = 12
    h = 1e-5

    def z_at(p):
        gg = trace_route(
            setup.tunnel, arrays, p[None], traj.velocity[k : k + 1], fc=setup.fc, kinds=setup.kinds
        )
        return model_truth(gg, setup.fc)[0][0]  # (P, 4)

    p0 = traj.position[k]
    ex = m.exists[k]
    H = np.zeros((ex.sum(), 4, 3))
    for i in range(2):
        dp = np.zeros(3)
        dp[i] = h
        H[:, :, i] = ((z_at(p0 + dp) - z_at(p0 - dp)) / (2 * h))[ex]
    H[:, 3, 2] = 1.0  # the clock bias
    H = H.reshape(-1, 3)
    var = np.tile(np.array([1e-3, 1e-3, 0.05, 0.01]) ** 2, ex.sum())
    J = H.T @ (H / var[:, None])
    want = J[:2, :2] - np.outer(J[:2, 2], J[2, :2]) / J[2, 2]
    assert np.allclose(info[k], want, rtol=1e-5)


def test_position_information_of_the_joint_model_reproduces_the_peb(setup):
    from tunnelkit.design.achievable import path_error_model

    for spec in ("4x4", "16x16"):
        m = path_error_model(setup, spec)
        info = position_information(m, route_geometry(setup, spec))
        snap = np.sqrt(np.trace(np.linalg.inv(info), axis1=1, axis2=2))
        assert np.allclose(snap, route_bounds(setup, spec).peb, rtol=1e-3)


def test_posterior_bound_is_below_the_snapshot_bound_and_reaches_it_without_motion_noise(setup):
    m = _diag_model(setup, "8x8", scale=20.0)  # snapshot bound of decimetres
    info = position_information(m, route_geometry(setup, "8x8"))
    snap = np.sqrt(np.trace(np.linalg.inv(info), axis1=1, axis2=2))
    pc = drive_pcrlb(setup, info)
    assert np.all(pc <= snap * (1 + 1e-9))
    assert pc[-1] < 0.7 * snap[-1]  # the motion model carries information over the drive
    loose = drive_pcrlb(setup, info, sigma_speed=1e3, sigma_heading=10.0)
    assert np.allclose(loose[1:], snap[1:], rtol=1e-3)


@pytest.mark.parametrize("mode", ["bound"])
def test_sweep_is_one_task_set_with_the_same_numbers_serially_and_on_two_workers(setup, mode):
    specs = ["4x4", "8x8"]
    models = {s: _diag_model(setup, s) for s in specs}
    kw = dict(mode=mode, error_models=models, n_epochs=14)
    serial = sweep_montecarlo(setup, specs, 2, 3, **kw)
    two = sweep_montecarlo(setup, specs, 2, 3, workers=2, **kw)
    assert list(serial) == specs
    for s in specs:
        r = serial[s]
        assert isinstance(r, MonteCarloResult) and r.mode == mode
        assert r.errors.shape == (2, 14) and np.all(np.isfinite(r.errors))
        assert np.array_equal(r.errors, two[s].errors)
        assert np.allclose(r.rmse_runs, np.sqrt(np.mean(r.errors[:, r.settled] ** 2, axis=1)))
        assert r.pcrlb.shape == (14,) and np.all(r.pcrlb > 0)
        # a model without bias or calibration: the prediction is the bound, pooled or not
        assert np.allclose(r.predicted, r.pcrlb) and np.allclose(r.hybrid, r.pcrlb)
        assert r.settled[0] == 10  # 1 s at 0.1 s
    # the runs of one array do not depend on which other arrays are swept with it
    alone = sweep_montecarlo(setup, ["8x8"], 2, 3, **kw)["8x8"]
    assert np.array_equal(alone.errors, serial["8x8"].errors)


def test_sweeps_sharing_one_cluster_give_the_serial_numbers(setup):
    from tunnelkit.runner import trial_pool

    specs = ["8x8", "4x4"]
    models = {s: _diag_model(setup, s) for s in specs}
    kw = dict(error_models=models, n_epochs=12)
    serial = sweep_montecarlo(setup, specs, 3, 5, **kw)
    with trial_pool(workers=2) as pool:
        first = sweep_montecarlo(setup, specs, 3, 5, pool=pool, **kw)
        again = sweep_montecarlo(setup, specs[::-1], 3, 5, pool=pool, **kw)  # the same cluster
    for s in specs:
        for other in (first[s], again[s]):
            assert np.array_equal(other.errors, serial[s].errors)
            assert np.array_equal(other.peb, serial[s].peb)
            assert np.array_equal(other.pcrlb, serial[s].pcrlb)
            assert other.sigmas == serial[s].sigmas
    with pytest.raises(TypeError, match="pool"):
        sweep_montecarlo(setup, specs, 2, 0, pool="cluster")
    with trial_pool() as pool, pytest.raises(ValueError, match="pool, workers"):
        sweep_montecarlo(setup, specs, 2, 0, pool=pool, workers=2)


def test_sweep_bad_input_is_refused_by_name(setup):
    with pytest.raises(ValueError, match="mode"):
        sweep_montecarlo(setup, ["4x4"], 2, 0, mode="fast")
    with pytest.raises(ValueError, match="specs"):
        sweep_montecarlo(setup, ["4x4", "4x4"], 2, 0)
    with pytest.raises(ValueError, match="error_models"):
        sweep_montecarlo(setup, ["4x4"], 2, 0, error_models={"8x8": None})
    with pytest.raises(ValueError, match="runs"):
        sweep_montecarlo(setup, ["4x4"], 0, 0)
    with pytest.raises(TypeError, match="setup"):
        sweep_montecarlo("x", ["4x4"], 2, 0)
    for bad in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(ValueError, match="start_sigma"):
            sweep_montecarlo(setup, ["4x4"], 2, 0, start_sigma=bad)


def test_the_entry_fix_sets_the_trackers_start_and_the_bounds_prior(setup):
    """start_sigma: the drawn start's spread and the prior of the bounds over the drive; the
    report's inputs carry it only when it is not the default (the default's JSON as before)."""
    from tunnelkit.design import design_sweep
    from tunnelkit.design.montecarlo import START_SIGMA_M

    kw = {"mode": "bound", "n_epochs": 8}
    wide = sweep_montecarlo(setup, ["4x4"], 6, 11, **kw)["4x4"]
    fine = sweep_montecarlo(setup, ["4x4"], 6, 11, start_sigma=0.01, **kw)["4x4"]
    assert START_SIGMA_M == 1.0
    # at the first epoch the bound and the tracker's error still carry the start: both shrink
    # with the entry fix (here by about 10x), and the bound never grows with a better one
    assert fine.predicted[0] < wide.predicted[0] / 5 and fine.pcrlb[0] < wide.pcrlb[0] / 5
    assert np.median(fine.errors[:, 0]) < np.median(wide.errors[:, 0]) / 5
    assert np.all(fine.pcrlb <= wide.pcrlb * (1 + 1e-9))
    few = {"units": 2, "max_units": 2, "n_epochs": 8, "settle": 0.5}
    rep = design_sweep(setup, ["4x4"], start_sigma=0.01, **few)
    assert rep.to_json()["inputs"]["start_sigma_m"] == 0.01
    assert "entry fix 0.01 m per axis" in rep.to_table()
    assert "start_sigma_m" not in design_sweep(setup, ["4x4"], **few).to_json()["inputs"]
    with pytest.raises(ValueError, match="start_sigma"):
        design_sweep(setup, ["4x4"], start_sigma=0.0, **few)


def test_a_prepared_route_gives_the_same_drive_and_is_checked(setup):
    m = _diag_model(setup, "4x4", sig=(2e-3, 3e-3, 0.2, 0.05))
    route = bound_route(m, setup, "4x4")
    assert isinstance(route, BoundRoute) and route.min_d == setup.signal_route("4x4").min_d
    a = bound_drive(m, setup, "4x4", np.random.default_rng(4), n_epochs=9)
    b = bound_drive(route, setup, "4x4", np.random.default_rng(4), n_epochs=9)
    for pa, pb in zip(a.epochs, b.epochs):
        assert np.array_equal(pa.phi, pb.phi) and np.array_equal(pa.d, pb.d)
        assert np.array_equal(pa.cov, pb.cov)
    assert np.array_equal(a.base_station, b.base_station)
    with pytest.raises(ValueError, match="spec"):
        bound_drive(route, setup, "8x8", np.random.default_rng(4))
    # the budget report hands the tracker its repeating share beside it
    from dataclasses import replace

    mb = replace(m, bias=np.where(m.exists[..., None], np.full(m.truth.shape, 0.01), 0.0))
    rb = bound_route(mb, setup, "4x4", report="budget")
    white, rep = split(mb)
    assert np.allclose(rb.blocks, white + rep) and np.allclose(rb.repeating, rep)
    drive = bound_drive(rb, setup, "4x4", np.random.default_rng(4), n_epochs=3)
    for pm in drive.epochs:
        assert pm.bias_cov is not None and pm.bias_cov.shape == (len(pm), 4, 4)
        assert np.all(
            pm.bias_cov[:, :3, :3].diagonal(axis1=1, axis2=2)
            <= pm.cov.diagonal(axis1=1, axis2=2) + 1e-15
        )


def test_position_bias_rms_is_the_rms_of_the_least_squares_fix_over_calibration_draws(setup):
    """Brute force: whitened least squares (lstsq) of the UE position and clock bias from the
    error ``bias + K_phase phi`` of many drawn calibration vectors; RMS of the position part."""
    from dataclasses import replace

    spec, M = "4x4", 5
    m0 = _diag_model(setup, spec)
    g = route_geometry(setup, spec)
    rng = np.random.default_rng(2)
    T, P = m0.exists.shape
    K = rng.standard_normal((T, P, 4, M)) * np.array([1e-3, 1e-3, 0.1, 0.01])[None, None, :, None]
    b = rng.standard_normal((T, P, 4)) * np.array([1e-3, 1e-3, 0.1, 0.01])
    m = replace(m0, bias=np.where(m0.exists[..., None], b, 0.0), k_phase=K, phase_sigma_rad=0.3)
    got = position_bias_rms(m, g)
    assert np.allclose(position_bias_rms(m0, g), 0.0)
    info = position_information(m, g)
    for k in (3, 20):
        j = np.flatnonzero(m.exists[k])
        eps = 1e-6
        H = np.zeros((j.size, 4, 3))
        for i in range(3):  # finite differences of the wave origins in the UE position
            dp = np.zeros(3)
            dp[i] = eps
            if i < 2:
                za = model_truth(_moved(g, k, dp), setup.fc)[0][0, j]
                zb = model_truth(_moved(g, k, -dp), setup.fc)[0][0, j]
                H[:, :, i] = (za - zb) / (2 * eps)
        H[:, 3, 2] = 1.0
        H = H.reshape(-1, 3)
        w = 1.0 / np.sqrt(np.diagonal(m.crlb[k]).reshape(P, 4)[j].ravel())
        phis = 0.3 * rng.standard_normal((M, 4000))
        e = (b[k, j][..., None] + np.einsum("pim,mn->pin", K[k, j], phis)).reshape(-1, 4000)
        sol = np.linalg.lstsq(H * w[:, None], e * w[:, None], rcond=None)[0]
        rms = np.sqrt(np.mean(np.sum(sol[:2] ** 2, axis=0)))
        assert abs(rms - got[k]) < 0.05 * got[k]
        assert np.all(np.linalg.eigvalsh(info[k]) > 0)
    pc = drive_pcrlb(setup, info)
    assert np.allclose(drive_bound(pc, got), np.hypot(pc, got))
    with pytest.raises(ValueError, match="bias_rms"):
        drive_bound(pc, got[:-1])


def _fd_jacobian(g, k, j, fc):
    """Central-difference Jacobian of paths ``j``'s measurements at epoch ``k`` in the UE's
    x and y (step 1 um), and the height column a known offset: (n, 4, 3)."""
    Hk = np.zeros((j.size, 4, 3))
    for i in range(2):
        dp = np.zeros(3)
        dp[i] = 1e-6
        za = model_truth(_moved(g, k, dp), fc)[0][0, j]
        zb = model_truth(_moved(g, k, -dp), fc)[0][0, j]
        Hk[:, :, i] = (za - zb) / 2e-6
    Hk[:, 3, 2] = 1.0
    return Hk


def _moved(g, k, dp):
    """Geometry of epoch ``k`` alone with the UE moved by ``dp``: every wave origin moves
    through its mirror (the known surface)."""
    from dataclasses import replace

    src = g.source[k : k + 1] + np.einsum("pij,j->pi", g.mirror, dp)[None]
    return replace(
        g,
        ue=g.ue[k : k + 1] + dp,
        exists=g.exists[k : k + 1],
        source=src,
        point=g.point[k : k + 1],
        gain=g.gain[k : k + 1],
        doppler=g.doppler[k : k + 1],
        array_index=g.array_index[k : k + 1],
        origin=g.origin[k : k + 1],
        rotation=g.rotation[k : k + 1],
    )


def test_position_bias_rms_with_the_trackers_weights_is_the_weighted_fix_over_draws(setup):
    """Brute force: per path a 4 x 4 covariance the tracker is told (one path's curvature not
    handed on: infinite variance), the fix whitened block by block (Cholesky of each block's
    inverse, the curvature row dropped), lstsq over many drawn calibration vectors."""
    from dataclasses import replace

    spec, M = "4x4", 5
    m0 = _diag_model(setup, spec)
    g = route_geometry(setup, spec)
    rng = np.random.default_rng(3)
    T, P = m0.exists.shape
    scale = np.array([1e-3, 1e-3, 0.1, 0.01])
    K = rng.standard_normal((T, P, 4, M)) * scale[None, None, :, None]
    b = rng.standard_normal((T, P, 4)) * scale
    m = replace(m0, bias=np.where(m0.exists[..., None], b, 0.0), k_phase=K, phase_sigma_rad=0.3)
    A = rng.standard_normal((T, P, 4, 4)) * scale[:, None]
    blocks = A @ np.swapaxes(A, -1, -2) + np.diag(scale**2)
    blocks[:, 1, 2, :] = blocks[:, 1, :, 2] = 0.0
    blocks[:, 1, 2, 2] = np.inf  # path 1's curvature: not handed to the tracker
    got = position_bias_rms(m, g, blocks)
    assert not np.allclose(got, position_bias_rms(m, g))  # the weights matter
    for k in (3, 20):
        j = np.flatnonzero(m.exists[k])
        rows, H = [], []
        Hk = _fd_jacobian(g, k, j, setup.fc)
        phis = 0.3 * rng.standard_normal((M, 4000))
        e = b[k, j][..., None] + np.einsum("pim,mn->pin", K[k, j], phis)  # (n, 4, draws)
        for i, p in enumerate(j):
            on = np.isfinite(np.diag(blocks[k, p]))
            Lw = np.linalg.cholesky(np.linalg.inv(blocks[k, p][np.ix_(on, on)]))
            rows.append(Lw.T @ e[i][on])
            H.append(Lw.T @ Hk[i][on])
        sol = np.linalg.lstsq(np.vstack(H), np.vstack(rows), rcond=None)[0]
        rms = np.sqrt(np.mean(np.sum(sol[:2] ** 2, axis=0)))
        assert abs(rms - got[k]) < 0.05 * got[k]
    with pytest.raises(ValueError, match="weights"):
        position_bias_rms(m, g, blocks[:-1])


def test_tracker_weights_drop_the_curvature_the_bound_route_does_not_hand_on(setup):
    from tunnelkit.design.trackerfix import KAPPA_RESOLVED, tracker_weights

    m = _diag_model(setup, "4x4", sig=(1e-3, 1e-3, 2.0, 0.01))
    rb = bound_route(m, setup, "4x4")
    w = tracker_weights(rb)
    far = np.sqrt(rb.blocks[..., 2, 2]) > KAPPA_RESOLVED * m.truth[..., 3]
    assert far.any() and (~far & m.exists).any()
    assert np.all(np.isinf(w[..., 2, 2][far]))
    assert np.allclose(w[..., 2, 2][~far], rb.blocks[..., 2, 2][~far])
    assert np.all(w[..., 2, :2][far] == 0) and np.allclose(w[..., :2, :2], rb.blocks[..., :2, :2])
    with pytest.raises(TypeError, match="route"):
        tracker_weights("m")


def test_the_bounds_lie_below_the_tracker_and_the_prediction_near_it_under_calibration(setup):
    """Monte-Carlo, 8 x 8 with 2 deg of phase error, 6 units of 2 drives: the tracker's settled
    RMSE is above the bound pooled over units (the calibration draw a fixed unknown) and every
    unit's RMSE above every unit's bound; the prediction (posterior CRLB of the tracker's
    weighting and the bias of a fix weighted as the tracker weighs) is near the RMSE, either
    side (a prediction, not a bound: 20 runs measured 0.89)."""
    from functools import partial

    from tunnelkit.design.achievable import DesignImpairments, path_error_model

    imp = DesignImpairments(phase_error_deg=2.0)
    r = sweep_montecarlo(
        setup,
        ["8x8"],
        12,
        0,
        error_models=partial(path_error_model, impairments=imp),
        impairments=imp,
        drives_per_unit=2,
    )["8x8"]
    ratio = r.rmse_settled / r.settled_rms(r.predicted)
    assert 0.6 < ratio < 1.7, ratio
    assert r.settled_rms(r.predicted) > 5 * r.settled_rms(r.pcrlb)  # the bias dominates
    assert r.rmse_settled > r.settled_rms(r.hybrid) > r.settled_rms(r.pcrlb)
    unit_rmse = np.sqrt(np.mean(r.errors[:, r.settled].reshape(6, -1) ** 2, axis=1))
    assert np.all(unit_rmse > r.settled_rms(r.pcrlb)), unit_rmse


def test_a_serial_sweep_prepares_an_array_once_for_the_same_job(setup, monkeypatch):
    """The sequential rule's next batch prepares the same arrays again: serially the first
    preparation is reused (the same setup and error-model objects), and the drives come out as
    from a fresh preparation; another setup object or other epochs prepare anew."""
    from tunnelkit.design import montecarlo
    from tunnelkit.design.arrayjob import ArrayJob

    calls = []
    real = ArrayJob.__call__

    def counted(self, spec):
        calls.append((spec.label, self.T))
        return real(self, spec)

    monkeypatch.setattr(ArrayJob, "__call__", counted)
    monkeypatch.setattr(montecarlo, "_PREPARED", montecarlo.OrderedDict())
    first = sweep_montecarlo(setup, ["4x4"], 2, 7, n_epochs=12)["4x4"]
    again = sweep_montecarlo(setup, ["4x4"], 2, 7, n_epochs=12, first_unit=2)["4x4"]
    assert calls == [("4x4", 12)]
    montecarlo._PREPARED.clear()
    fresh = sweep_montecarlo(setup, ["4x4"], 2, 7, n_epochs=12, first_unit=2)["4x4"]
    assert calls == [("4x4", 12)] * 2
    np.testing.assert_array_equal(again.errors, fresh.errors)
    np.testing.assert_array_equal(again.pcrlb, first.pcrlb)
    sweep_montecarlo(setup, ["4x4"], 2, 7, n_epochs=11)
    other = DesignSetup.from_scenario(SCENARIO)
    sweep_montecarlo(other, ["4x4"], 2, 7, n_epochs=12)
    assert calls == [("4x4", 12), ("4x4", 12), ("4x4", 11), ("4x4", 12)]
    # an array of the same label and another spacing is another array: prepared anew
    from tunnelkit.design import ArraySpec, design_sweep

    sweep_montecarlo(setup, [ArraySpec(4, 4, spacing_wl=0.7)], 2, 7, n_epochs=12)
    assert calls[-1] == ("4x4", 12) and len(calls) == 5
    # one sweep's rows and results go by label: two spacings of one size are refused there
    with pytest.raises(ValueError, match=r"^arrays: .*one spacing per size"):
        design_sweep(setup, [ArraySpec(4, 4), ArraySpec(4, 4, spacing_wl=0.7)], units=0)


def test_a_units_drives_share_its_calibration_and_later_units_extend_the_sweep(setup):
    """Drives of one unit see one calibration draw; a sweep of 4 units is the sweep of units
    0-1 followed by the sweep of units 2-3 (``first_unit``), and a unit's first drive does not
    depend on how many drives it has."""
    from functools import partial

    from tunnelkit.design.achievable import DesignImpairments, path_error_model

    imp = DesignImpairments(phase_error_deg=2.0)
    kw = dict(error_models=partial(path_error_model, impairments=imp), impairments=imp,
              n_epochs=12, drives_per_unit=2)  # fmt: skip
    whole = sweep_montecarlo(setup, ["4x4"], 8, 7, **kw)["4x4"]
    head = sweep_montecarlo(setup, ["4x4"], 4, 7, **kw)["4x4"]
    tail = sweep_montecarlo(setup, ["4x4"], 4, 7, first_unit=2, **kw)["4x4"]
    np.testing.assert_array_equal(whole.errors, np.concatenate([head.errors, tail.errors]))
    with pytest.raises(ValueError, match="runs"):
        sweep_montecarlo(setup, ["4x4"], 3, 7, **kw)
    # serially too, every drive of a unit draws the same calibration error, and the sweep is the
    # same on two workers (each drive makes its own generator from its unit's seed)
    from tunnelkit.design import arrayjob

    seen = []
    real = arrayjob.draw_calibration

    def spy(model, rng):
        cal = real(model, rng)
        seen.append(cal[0])
        return cal

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(arrayjob, "draw_calibration", spy)
        serial = sweep_montecarlo(setup, ["4x4"], 6, 7, **kw)["4x4"]
    assert len(seen) == 6 and not np.array_equal(seen[0], seen[2])
    for u in range(3):
        np.testing.assert_array_equal(seen[2 * u], seen[2 * u + 1])
    np.testing.assert_array_equal(serial.errors, whole.errors[:6])
    two = sweep_montecarlo(setup, ["4x4"], 6, 7, workers=2, **kw)["4x4"]
    np.testing.assert_array_equal(two.errors, serial.errors)
    m = path_error_model(setup, "4x4", impairments=imp)
    from tunnelkit.design.units import unit_seeds

    u = [np.random.default_rng(q) for q in unit_seeds(7, 0, 2)]
    first = np.random.default_rng(unit_seeds(7, 0, 1)[0])  # a unit's seed: the same in any batch
    assert np.array_equal(draw_calibration(m, u[0])[0],
                          first.standard_normal(16) * m.phase_sigma_rad)  # fmt: skip
    cal = draw_calibration(m, u[1])
    rng = np.random.default_rng(1)
    z1 = draw(m, np.random.default_rng(1), calibration=cal)
    z2 = draw(m, np.random.default_rng(2), calibration=cal)
    # the same unit: the calibration bias is common, only the noise differs
    bias = calibration_bias(m, *cal)
    assert np.nanmax(np.abs(bias)) > 0 and rng is not None
    noise1, noise2 = z1 - m.truth - m.bias - bias, z2 - m.truth - m.bias - bias
    ns = noise_sqrt(m)
    T, P = m.exists.shape
    g1 = np.random.default_rng(1).standard_normal((T, 4 * P, 1))
    np.testing.assert_allclose(
        np.where(m.exists[..., None], noise1, 0.0),
        np.where(m.exists[..., None], (ns @ g1)[..., 0].reshape(T, P, 4), 0.0),
        atol=1e-12,
    )
    assert not np.allclose(np.nan_to_num(noise1), np.nan_to_num(noise2))


def test_position_error_parts_diffuse_is_the_weighted_fix_of_the_excess_covariance(setup):
    """Brute force: errors drawn with the excess covariance ``cov - crlb`` (correlated across
    the paths), the fix weighted by the tracker's blocks, RMS of the position over the draws."""
    from dataclasses import replace

    from tunnelkit.design.trackerfix import position_error_parts

    spec = "4x4"
    m0 = _diag_model(setup, spec)
    g = route_geometry(setup, spec)
    rng = np.random.default_rng(5)
    T, P = m0.exists.shape
    scale = np.tile([1e-3, 1e-3, 0.1, 0.01], P)
    A = rng.standard_normal((T, 4 * P, 4 * P)) * scale[:, None] / np.sqrt(4 * P)
    E = A @ np.swapaxes(A, 1, 2)
    mask = np.repeat(m0.exists, 4, axis=1)
    E = np.where(mask[:, :, None] & mask[:, None, :], E, 0.0)
    m = replace(m0, cov=m0.crlb + E)
    blocks = np.moveaxis(
        m.cov.reshape(T, P, 4, P, 4)[:, np.arange(P), :, np.arange(P), :], 0, 1
    ).copy()
    parts = position_error_parts(m, g, blocks)
    assert np.allclose(parts[:, :2], 0.0) and np.all(parts[m0.exists.any(axis=1), 2] > 0)
    for k in (3, 20):
        j = np.flatnonzero(m.exists[k])
        rows = (4 * j[:, None] + np.arange(4)).ravel()
        Hk = _fd_jacobian(g, k, j, setup.fc)
        L = np.linalg.cholesky(E[k][np.ix_(rows, rows)] + 1e-30 * np.eye(rows.size))
        e = (L @ rng.standard_normal((rows.size, 4000))).reshape(j.size, 4, -1)
        Hs, es = [], []
        for i, p in enumerate(j):
            Lw = np.linalg.cholesky(np.linalg.inv(blocks[k, p]))
            es.append(Lw.T @ e[i])
            Hs.append(Lw.T @ Hk[i])
        sol = np.linalg.lstsq(np.vstack(Hs), np.vstack(es), rcond=None)[0]
        rms = np.sqrt(np.mean(np.sum(sol[:2] ** 2, axis=0)))
        assert abs(rms - parts[k, 2]) < 0.05 * parts[k, 2]


def test_position_noise_cov_is_the_block_weighted_fix_under_the_joint_crlb(setup):
    """Brute force: a joint CRLB correlating the paths (random, per epoch) and the tracker told
    only its per-path blocks (one curvature not handed on): the covariance of the block-weighted
    least-squares fix over many draws of the joint noise (finite-difference Jacobian, lstsq).
    It is never below the PEB's covariance, equals it for a CRLB without cross-path terms, and
    its inverse is the information ``position_information`` uses with the tracker's weights."""
    from dataclasses import replace

    from tunnelkit.design.trackerfix import position_noise_cov

    spec = "4x4"
    m0 = _diag_model(setup, spec)
    g = route_geometry(setup, spec)
    rng = np.random.default_rng(11)
    T, P = m0.exists.shape
    scale = np.tile(np.array([1e-3, 1e-3, 0.1, 0.01]), P)
    A = rng.standard_normal((T, 4 * P, 4 * P)) * scale[:, None]
    crlb = A @ np.swapaxes(A, -1, -2) / (4 * P) + np.diag(scale**2) * 0.1
    m = replace(m0, crlb=crlb, cov=crlb.copy())
    blocks = np.stack([crlb[:, 4 * p : 4 * p + 4, 4 * p : 4 * p + 4] for p in range(P)], axis=1)
    blocks[:, 1, 2, :] = blocks[:, 1, :, 2] = 0.0
    blocks[:, 1, 2, 2] = np.inf
    got = position_noise_cov(m, g, blocks)
    info = position_information(m, g, blocks)
    ideal = np.linalg.inv(position_information(m, g))
    for k in (3, 20):
        j = np.flatnonzero(m.exists[k])
        rows4 = (4 * j[:, None] + np.arange(4)).ravel()
        Hk = _fd_jacobian(g, k, j, setup.fc)
        e = rng.multivariate_normal(np.zeros(rows4.size), crlb[k][np.ix_(rows4, rows4)], 20_000)
        e = e.T.reshape(j.size, 4, -1)
        rows, H = [], []
        for i, p in enumerate(j):
            on = np.isfinite(np.diag(blocks[k, p]))
            Lw = np.linalg.cholesky(np.linalg.inv(blocks[k, p][np.ix_(on, on)]))
            rows.append(Lw.T @ e[i][on])
            H.append(Lw.T @ Hk[i][on])
        sol = np.linalg.lstsq(np.vstack(H), np.vstack(rows), rcond=None)[0][:2]
        emp = np.cov(sol)
        assert np.allclose(got[k], emp, rtol=0.05, atol=0.05 * np.abs(emp).max())
        assert np.trace(got[k]) > 1.05 * np.trace(ideal[k])  # the cross-path terms unused
        assert np.allclose(np.linalg.inv(info[k]), got[k], rtol=1e-6)
    w0 = np.stack([m0.crlb[:, 4 * p : 4 * p + 4, 4 * p : 4 * p + 4] for p in range(P)], axis=1)
    same = position_noise_cov(m0, g, w0)
    ref = np.linalg.inv(position_information(m0, g)[m0.exists.any(axis=1)])
    assert np.allclose(same[m0.exists.any(axis=1)], ref, rtol=1e-6)
    with pytest.raises(ValueError, match="weights"):
        position_noise_cov(m, g, blocks[:-1])


def test_dead_reckoning_drops_the_radio_and_leaves_the_tracker_run_unchanged(setup):
    """dead_reckoning: each drive run again with every measurement dropped. It does not depend
    on the measurements (the same drives with 1000x the noise give the same dead reckoning),
    it does not change the tracker's run (same errors as without it), and a tracker told
    measurements 1000x worse is dead reckoning to within a small fraction."""
    from tunnelkit.design import design_sweep

    kw = {"mode": "bound", "n_epochs": 8}
    models = {s: {"4x4": _diag_model(setup, "4x4", scale=s)} for s in (1.0, 1000.0)}
    r1 = sweep_montecarlo(setup, ["4x4"], 3, 5, error_models=models[1.0], dead_reckoning=True, **kw)
    rk = sweep_montecarlo(setup, ["4x4"], 3, 5, error_models=models[1000.0], dead_reckoning=True,
                          **kw)["4x4"]  # fmt: skip
    plain = sweep_montecarlo(setup, ["4x4"], 3, 5, error_models=models[1.0], **kw)["4x4"]
    r1 = r1["4x4"]
    assert plain.dead_reckoning is None and r1.dead_reckoning.shape == r1.errors.shape
    np.testing.assert_array_equal(r1.errors, plain.errors)
    np.testing.assert_allclose(r1.dead_reckoning, rk.dead_reckoning, rtol=1e-12)
    assert not np.allclose(r1.errors, r1.dead_reckoning)
    assert np.all(np.abs(rk.errors - rk.dead_reckoning) < 0.05 * rk.dead_reckoning + 1e-3)
    few = {"units": 2, "max_units": 2, "n_epochs": 8, "settle": 0.5}
    rep = design_sweep(setup, ["4x4"], dead_reckoning=True, **few)
    row = rep.to_json()["arrays"][0]
    assert rep.to_json()["inputs"]["dead_reckoning"] is True
    assert row["dead_reckoning_p90_m"] > 0 and row["dead_reckoning_rmse_m"] > 0
    assert "dead reckoning on the same drives" in rep.to_table()
    bare = design_sweep(setup, ["4x4"], **few).to_json()
    assert (
        "dead_reckoning" not in bare["inputs"] and "dead_reckoning_p90_m" not in bare["arrays"][0]
    )
    with pytest.raises(TypeError, match="dead_reckoning"):
        sweep_montecarlo(setup, ["4x4"], 2, 0, dead_reckoning="yes", **kw)


def test_a_sweep_pairs_its_arrays_and_dead_reckoning_unit_by_unit(setup):
    """Every row keeps its per-unit RMSEs (and dead reckoning's): the same drives in every row,
    so dead reckoning's are identical across arrays; they pool back to the row's RMSE, and the
    report's ``paired`` ratios are the ratios of those RMSEs (the radio's gain, an array over the
    next smaller), each with its interval over the units."""
    from tunnelkit.design import design_sweep, paired_rmse_ratio

    few = {"units": 3, "max_units": 3, "n_epochs": 8, "settle": 0.5, "seed": 4}
    rep = design_sweep(setup, ["8x8", "4x4"], dead_reckoning=True, **few)
    js = rep.to_json()
    rows = {r["array"]: r for r in js["arrays"]}
    for r in rows.values():
        assert len(r["unit_rmse_m"]) == len(r["dead_reckoning_unit_rmse_m"]) == 3
        assert np.sqrt(np.mean(np.square(r["unit_rmse_m"]))) == pytest.approx(r["rmse_m"])
        dr = np.sqrt(np.mean(np.square(r["dead_reckoning_unit_rmse_m"])))
        assert dr == pytest.approx(r["dead_reckoning_rmse_m"])
        gain = js["paired"][r["array"]]["radio_gain"]
        assert gain["ratio"] == pytest.approx(r["dead_reckoning_rmse_m"] / r["rmse_m"])
        want = paired_rmse_ratio(r["dead_reckoning_unit_rmse_m"], r["unit_rmse_m"])[1]
        assert gain["units"] == 3 and gain["ci95"] == pytest.approx(want)  # num over den
    assert rows["4x4"]["dead_reckoning_unit_rmse_m"] == rows["8x8"]["dead_reckoning_unit_rmse_m"]
    big = js["paired"]["8x8"]["against_smaller"]
    assert "against_smaller" not in js["paired"]["4x4"] and big["against"] == "4x4"
    assert big["ratio"] == pytest.approx(rows["8x8"]["rmse_m"] / rows["4x4"]["rmse_m"])
    want = paired_rmse_ratio(rows["8x8"]["unit_rmse_m"], rows["4x4"]["unit_rmse_m"])[1]
    assert big["ci95"] == pytest.approx(want)  # the larger over the smaller, not the reverse
    assert f"8x8: its RMSE over the 4x4's on the same drives {big['ratio']:.3g}x" in rep.to_table()
    assert "paired over 3 units" in rep.to_table()


def test_unit_pcrlb_is_the_drive_pcrlb_without_calibration_and_grows_with_it(setup):
    """Brute force: with the calibration known (or absent) the covariance recursion of
    ``unit_pcrlb`` is Tichavsky's recursion of ``drive_pcrlb`` on the same position
    information (an ideal model: ``cov`` is the reported ``crlb``); carrying the calibration as
    an unknown with its prior never lowers it, more prior spread never lowers it, and a tiny
    spread gives the known-calibration bound back."""
    from dataclasses import replace

    from tunnelkit.design.achievable import DesignImpairments, path_error_model
    from tunnelkit.design.drivebound import unit_pcrlb

    spec = "4x4"
    g = route_geometry(setup, spec)
    m = path_error_model(setup, spec, impairments=DesignImpairments(phase_error_deg=2.0))
    ref = drive_pcrlb(setup, position_information(m, g))
    known = unit_pcrlb(setup, m, g, calibration=False)
    np.testing.assert_allclose(known, ref, rtol=1e-9)
    pooled = unit_pcrlb(setup, m, g)
    assert np.all(pooled >= known * (1 - 1e-12)) and np.any(pooled > known * 1.01)
    wider = unit_pcrlb(setup, replace(m, phase_sigma_rad=2 * m.phase_sigma_rad), g)
    assert np.all(wider >= pooled * (1 - 1e-12))
    tiny = unit_pcrlb(setup, replace(m, phase_sigma_rad=1e-9), g)
    np.testing.assert_allclose(tiny, known, rtol=1e-9)
    fine = unit_pcrlb(setup, m, g, sigma_p0=0.1)
    assert fine[0] < pooled[0]  # the entry fix is the bound's prior
    with pytest.raises(TypeError, match="calibration"):
        unit_pcrlb(setup, m, g, calibration="yes")


def test_load_tracker_loads_the_tracker_modules_a_worker_unpickles():
    """A Dask worker runs ``load_tracker`` before a sweep's tasks, so that no task imports a tracker
    module while another thread unpickles one (the import locks deadlock): in a fresh process it
    must load the modules themselves, not only the lazy package shells."""
    import subprocess
    import sys

    code = (
        "import sys; from tunnelkit.design.arrayjob import load_tracker; load_tracker()\n"
        "need = ['tunnelkit.tracking.javelin.' + m for m in ('tracker', 'arraydesign', "
        "'designs', 'update', 'manage', 'surfaces')] + ['tunnelkit.simulation.drives']\n"
        "print([m for m in need if m not in sys.modules])\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_load_tracker_loads_the_direct_fit_only_for_a_direct_sweep():
    """The direct fit's modules are a ``direct`` sweep's alone: ``load_tracker()`` leaves them
    out, ``load_tracker(True)`` (what a ``traced_tracker="direct"`` sweep runs on its workers)
    loads the modules themselves."""
    import subprocess
    import sys

    direct = ["tunnelkit.design.traceddirect"] + [
        f"tunnelkit.extraction.direct.{m}" for m in ("fit", "visibility", "aperture")
    ]
    for flag, want in (("", direct), ("True", [])):
        code = (
            f"import sys; from tunnelkit.design.arrayjob import load_tracker; load_tracker({flag})\n"
            f"print([m for m in {direct!r} if m not in sys.modules])\n"
        )
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True)  # fmt: skip
        assert out.stdout.strip() == str(want)
