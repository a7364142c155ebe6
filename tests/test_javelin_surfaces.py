"""VUEs from known surfaces (GeometricBirth) and the honest start (draw_start)."""

import numpy as np
import pytest
from javelin_geometric import geometric_paths, geometric_stream, toy_drive

from tunnelkit.geometry import Plane
from tunnelkit.tracking.javelin import Javelin, JavelinState, draw_start
from tunnelkit.tracking.javelin.arraydesign import array_design
from tunnelkit.tracking.javelin.measurement import PathMeasurements
from tunnelkit.tracking.javelin.noise import ReportedNoise
from tunnelkit.tracking.javelin.surfaces import GeometricBirth, mirror_vue

BS = np.array([0.0, 0.0, 5.0])


def _planes():
    a = np.radians(55.0)
    n = np.array([0.0, -np.sin(a), np.cos(a)])
    return [
        Plane(np.array([0.0, -1.0, 0.0]), 4.0, name="left wall"),
        Plane(np.array([0.0, 1.0, 0.0]), 4.0, name="right wall"),
        Plane(np.array([0.0, 0.0, -1.0]), 6.0, name="ceiling"),
        Plane(np.array([0.0, 0.0, 1.0]), 0.0, name="road"),
        Plane(n, -(n @ [0.0, 3.5, 0.2]), name="left RRM"),
    ]


def _state(rng, D_vue=1):
    x = np.concatenate([[-30.0, 1.5, 1.2], rng.normal(size=2 * D_vue)])
    A = rng.normal(size=(x.size, x.size))
    return JavelinState(x, A @ A.T * 0.01 + 0.01 * np.eye(x.size), [1], [0], [False])


def test_mirror_vue_is_the_plane_mirror_and_its_jacobian_by_differences():
    rng = np.random.default_rng(1)
    st = _state(rng)
    for pl in _planes():
        yz, A = mirror_vue(st, pl.normal, pl.offset)
        np.testing.assert_allclose(yz, pl.mirror(st.x[:3])[1:], atol=1e-12)
        h = 1e-6
        for i in range(st.dim):
            s2 = st.copy()
            s2.x[i] += h
            fd = (mirror_vue(s2, pl.normal, pl.offset)[0] - yz) / h
            np.testing.assert_allclose(fd, A[:, i], atol=1e-6)


def test_mirror_vue_refuses_a_plane_along_the_tunnel():
    st = _state(np.random.default_rng(0))
    with pytest.raises(ValueError, match="normal"):
        mirror_vue(st, [1.0, 0.0, 0.0], 3.0)
    with pytest.raises(ValueError, match="normal"):
        GeometricBirth(normals=((0.0, 0.6, 0.6),), offsets=(1.0,))
    with pytest.raises(ValueError, match="offsets"):
        GeometricBirth(normals=((0.0, 1.0, 0.0),), offsets=(1.0, 2.0))


def test_placed_covariance_matches_mirrored_samples():
    """Brute force: sample the state, mirror each UE sample, compare the VUE's covariance and its
    cross-covariance with the state against what ``place`` appends."""
    rng = np.random.default_rng(2)
    st = _state(rng)
    pl = _planes()[4]
    birth = GeometricBirth.from_planes([pl])
    # a path from that plane, measured exactly: the match must pick it
    meas, _ = geometric_paths(st.x[:3], np.zeros(3), [pl], rng, bs=BS, los=False, shuffle=False)
    from tunnelkit.tracking.javelin.config import JavelinConfig

    cfg = JavelinConfig(base_station=tuple(BS))
    out = birth.place(st, meas, 0, cfg, ReportedNoise())
    assert out is not None
    yz, cov, cross, bias_cross = out
    assert bias_cross is None
    S = rng.multivariate_normal(st.x, st.P, size=200_000)
    V = np.array([pl.mirror(s[:3])[1:] for s in S[:2000]])  # spot check of the map
    M = np.eye(2) - 2.0 * np.outer(pl.normal[1:], pl.normal[1:])
    Vs = S[:, 1:3] @ M.T - 2.0 * pl.offset * pl.normal[1:]
    np.testing.assert_allclose(Vs[:2000], V, atol=1e-9)
    emp = np.cov(np.hstack([Vs, S]).T)
    np.testing.assert_allclose(emp[:2, :2], cov, atol=3e-3 * np.max(np.abs(cov)) + 1e-4)
    np.testing.assert_allclose(emp[:2, 2:], cross, atol=3e-3 * np.max(np.abs(st.P)) + 1e-4)
    np.testing.assert_allclose(yz, pl.mirror(st.x[:3])[1:], atol=1e-12)


def test_match_picks_the_true_plane_and_refuses_an_unknown_one():
    rng = np.random.default_rng(3)
    planes = _planes()
    from tunnelkit.tracking.javelin.config import JavelinConfig

    cfg = JavelinConfig(base_station=tuple(BS))
    st = JavelinState(np.array([-25.0, 1.0, 1.2]), np.eye(3) * 0.05**2)
    birth = GeometricBirth.from_planes(planes)
    for s, pl in enumerate(planes):
        meas, _ = geometric_paths(
            st.x, np.zeros(3), [pl], rng, bs=BS, los=False, shuffle=False, sigma_phi=1e-4
        )
        meas = PathMeasurements.from_arrays(
            meas.phi,
            meas.psi,
            meas.kappa,
            meas.d,
            meas.v,
            cov=np.eye(3)[None] * 1e-6,
            sigma_d=[0.01],
        )
        assert birth.match(st, meas, 0, cfg, ReportedNoise()) == s
    # a plane the tracker does not know (a wall at y = -2.5) explains no path
    other = Plane(np.array([0.0, 1.0, 0.0]), 2.5)
    meas, _ = geometric_paths(st.x, np.zeros(3), [other], rng, bs=BS, los=False, shuffle=False)
    meas = PathMeasurements.from_arrays(
        meas.phi, meas.psi, meas.kappa, meas.d, meas.v, cov=np.eye(3)[None] * 1e-6, sigma_d=[0.01]
    )
    assert birth.match(st, meas, 0, cfg, ReportedNoise()) is None


def test_draw_start_has_the_stated_spread():
    rng = np.random.default_rng(4)
    truth = np.array([-40.0, 1.5, 1.0])
    p = np.array([draw_start(truth, 0.7, rng) for _ in range(20_000)])
    np.testing.assert_allclose(p.mean(axis=0), truth, atol=0.03)
    np.testing.assert_allclose(p.std(axis=0), 0.7, rtol=0.03)
    with pytest.raises(ValueError, match="sigma"):
        draw_start(truth, -1.0, rng)
    with pytest.raises(TypeError, match="rng"):
        draw_start(truth, 1.0, 0)


def _run(design, rng, start_err):
    planes = _planes()
    P, V = toy_drive(60, 0.1, start=-45.0, stop=-15.0, lane=1.5, height=1.2)
    s = dict(sigma_phi=1e-3, sigma_psi=1e-3, sigma_kappa=0.05, sigma_d=0.01)
    stream = geometric_stream(P, V, planes[:4], rng, bs=BS, **s)
    cov = np.diag([1e-6, 1e-6, 0.05**2])
    # the design's curvature is the distance to the VUE: the delay distance of this stream (no
    # clock bias), whose error (1 cm) lies within the 5 cm the covariance states
    stream = [
        PathMeasurements.from_arrays(
            m.phi,
            m.psi,
            m.d,
            m.d,
            m.v,
            cov=np.repeat(cov[None], len(m), 0),
            sigma_d=np.full(len(m), 0.01),
        )
        for m in stream
    ]
    spd = np.linalg.norm(V[:, :2], axis=1)
    hdg = np.arctan2(V[:, 1], V[:, 0])
    d = design.with_(base_station=tuple(BS), sigma_p0_ue=1.0)
    trk = Javelin(P[0] + start_err, d)
    run = trk.run(stream, spd, hdg, 0.1)
    return np.linalg.norm(run.estimates[:, :2] - P[:, :2], axis=1), trk


def test_known_surface_vues_stay_tied_to_the_ue_from_a_drawn_start():
    """A drive started 1 m off: the VUEs born from the known planes sit at the UE estimate's
    mirror images and stay there (mirror motion, tied covariance), and the UE converges."""
    crlb = {"d": 0.01, "direction": 1e-3, "kappa": 0.05}
    planes = _planes()[:4]
    known = array_design(crlb, planes=planes)
    assert isinstance(known.initiator, GeometricBirth)
    assert not isinstance(array_design(crlb).initiator, GeometricBirth)
    err, trk = _run(known, np.random.default_rng(5), np.array([0.6, -0.8, 0.0]))
    st = trk.state
    assert st.n_vue == 4
    ue = st.ue
    for yz in st.x[3:].reshape(-1, 2):
        gap = min(np.linalg.norm(pl.mirror(ue)[1:] - yz) for pl in planes)
        assert gap < 5e-3, gap
    assert np.sqrt(np.mean(err[5:] ** 2)) < 0.03


def test_first_fix_finds_the_los_when_the_start_and_the_delays_mislead():
    """The start 1.5 m off, across the UE's nearest wall, and the LoS's delay measured longer
    than a reflection's: the first fix tries every path as the LoS and keeps the one the known
    planes explain, so the UE lands on the truth, not on the wall's image."""
    planes = _planes()[:4]
    truth = np.array([-30.0, -3.0, 1.2])
    rng = np.random.default_rng(8)
    meas, tr = geometric_paths(truth, np.zeros(3), planes, rng, bs=BS, shuffle=False)
    d = tr["d"].copy()
    d[0] = d.max() + 1e-3  # the LoS measured longest
    n = len(meas)
    cov = np.repeat(np.diag([1e-8, 1e-8, 0.05**2])[None], n, 0)
    meas = PathMeasurements.from_arrays(
        tr["phi"], tr["psi"], tr["d"], d, tr["v"], cov=cov, sigma_d=np.full(n, 1e-3)
    )
    crlb = {"d": 1e-3, "direction": 1e-4, "kappa": 0.05}
    design = array_design(crlb, planes=planes).with_(
        base_station=tuple(BS), sigma_p0_ue=1.0, sigma_p0_height=0.05
    )
    start = truth + np.array([0.0, -1.5, 0.0])
    trk = Javelin(start, design)
    rep = trk.step(meas, 0.0, 0.0, 0.0)
    assert np.linalg.norm(rep.estimate[:2] - truth[:2]) < 0.02
    # without the first fix, one EKF step from 1.5 m off lands centimetres from the ray
    plain = design.with_(initiator=GeometricBirth.from_planes(planes, acquire=False))
    rep2 = Javelin(start, plain).step(meas, 0.0, 0.0, 0.0)
    e_fix = np.linalg.norm(rep.estimate[:2] - truth[:2])
    assert np.linalg.norm(rep2.estimate[:2] - truth[:2]) > 10 * e_fix


def test_the_epochs_update_is_iterated_to_the_map_estimate():
    """Brute force: one LoS path (angles and curvature, micro-radian and millimetre sigmas)
    and a prior 0.8 m off: the epoch's update is the minimum of the prior's and the rows'
    whitened residuals (scipy least squares, Gauss-Newton by another code); a single EKF step
    from that prior stops a centimetre away, far outside the covariance it reports."""
    from scipy.optimize import least_squares

    truth = np.array([-25.0, 1.5, 1.2])
    q = truth - BS
    phi, psi, r = np.arctan2(q[1], q[0]), np.arctan2(q[2], np.hypot(q[0], q[1])), np.linalg.norm(q)
    sig = np.array([2e-5, 2e-5, 0.01])
    meas = PathMeasurements.from_arrays(
        [phi], [psi], [r], [r], [0.0], cov=np.diag(sig**2)[None], sigma_d=[1e-3]
    )
    crlb = {"d": 1e-3, "direction": 2e-5, "kappa": 0.01}
    design = array_design(crlb).with_(base_station=tuple(BS), sigma_p0_ue=1.0, sigma_p0_height=0.05)
    start = truth + np.array([0.8, 0.3, 0.02])
    s0 = np.array([1.0, 1.0, 0.05])

    def res(x):
        p = x - BS
        h = [np.arctan2(p[1], p[0]), np.arctan2(p[2], np.hypot(p[0], p[1])), np.linalg.norm(p)]
        return np.concatenate([(x - start) / s0, (np.array([phi, psi, r]) - h) / sig])

    want = least_squares(res, start, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    rep = Javelin(start, design).step(meas, 0.0, 0.0, 0.0)
    assert rep.n_rows == 3
    np.testing.assert_allclose(rep.estimate, want, atol=1e-6)
    assert design.config.update_iterations > 0
    one = Javelin(start, design.with_(update_iterations=0)).step(meas, 0.0, 0.0, 0.0)
    e_one = np.linalg.norm(one.estimate - want)
    assert e_one > 1e-3  # a one-step EKF from 0.8 m off is millimetres or more off
    dx = one.estimate - want
    assert dx @ np.linalg.solve(one.cov, dx) > 100.0  # and far outside what it claims
