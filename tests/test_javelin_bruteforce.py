"""Closed forms of the JAVELIN roles against finite differences, Monte Carlo and brute force."""

import numpy as np
import pytest
from javelin_geometric import toy_reflectors

from tunnelkit.crlb import numeric_jacobian, wrap_angle
from tunnelkit.reflection import reflector_point
from tunnelkit.tracking.javelin import (
    FixedNoise,
    JavelinConfig,
    JavelinState,
    PathMeasurements,
    measurement_model,
    track_model,
)
from tunnelkit.tracking.javelin.manage import manage_tracks, static_doppler
from tunnelkit.tracking.javelin.motion import motion_increment, predict
from tunnelkit.tracking.javelin.update import stack_measurement


@pytest.mark.parametrize("kappa_model", ["reflector", "vue"])
def test_jacobian_for_any_base_station_and_either_side_of_the_array(kappa_model):
    # the existing test keeps the UE behind a fixed base station; here the UE may be on either
    # side, the base station anywhere, and azimuth differences are wrapped across the branch cut
    rng = np.random.default_rng(11)
    for _ in range(200):
        nv = int(rng.integers(0, 4))
        bs = rng.uniform(-5, 5, 3)
        x = np.concatenate(
            [
                [rng.uniform(-50, 50), rng.uniform(-5, 5), rng.uniform(-3, 6)],
                rng.uniform(-15, 15, 2 * nv),
            ]
        )
        h, H = measurement_model(x, bs, kappa_model)
        mask = np.zeros(h.size, bool)
        mask[: nv + 1] = True
        Hn = numeric_jacobian(
            lambda s, bs=bs: measurement_model(s, bs, kappa_model)[0], x, step=1e-6, angle_mask=mask
        )
        np.testing.assert_allclose(H, Hn, atol=1e-5 * (1 + np.abs(Hn)).max(), rtol=1e-5)
        if kappa_model == "reflector":
            pred, _ = track_model(x, bs)
            for k, yz in enumerate(x[3:].reshape(-1, 2)):
                pv = np.array([x[0], *yz])
                pr = reflector_point(x[:3], pv, bs)
                assert pred[k + 1, 2] == pytest.approx(np.linalg.norm(pr - bs), rel=1e-8)


def test_stacked_update_rows_match_finite_differences():
    # the rows stack_measurement builds (angles, curvature where present, TDoAs against a
    # non-LoS reference) are the derivative of the stacked h, also across the azimuth cut
    bs = np.array([0.0, 0.0, 4.8])
    x = np.array([-30.0, 0.02, 1.0, -0.4, 1.0, 9.0, 1.0, -10.0, 1.0])  # UE near phi = pi
    pred, J = track_model(x, bs)
    meas = PathMeasurements.from_arrays(
        pred[:, 0], pred[:, 1], kappa=[np.nan, pred[1, 2], np.nan, pred[3, 2]], d=pred[:, 3] + 5.0
    )
    pairs = [(1, 1), (2, 2), (3, 3), (0, 0)]
    cfg = JavelinConfig(base_station=tuple(bs))
    m = stack_measurement(pred, J, meas, sorted(pairs), cfg, los_path=None)
    assert m.reference is not None and m.reference[0] == 0  # the UE has the shortest path
    m2 = stack_measurement(pred, J, meas, [(1, 1), (2, 2), (3, 3)], cfg)
    assert m2.reference[0] != 0  # TDoA between reflections only

    for mm, prs in ((m, sorted(pairs)), (m2, [(1, 1), (2, 2), (3, 3)])):

        def h_of(s, prs=prs):
            p, Jk = track_model(s, bs)
            return stack_measurement(p, Jk, meas, prs, cfg).h

        Hn = numeric_jacobian(h_of, x, step=1e-6, angle_mask=mm.angle)
        np.testing.assert_allclose(mm.H, Hn, atol=1e-6, rtol=1e-6)
        assert np.all(np.abs(mm.residual()) < 1e-9)


def test_correlated_tdoa_covariance_is_the_sample_covariance_of_differenced_delays():
    # d_j = r_j + b + e_j with iid e_j of variance sigma_dd^2 / 2: the TDoAs against one
    # reference have covariance sigma_dd^2 (I + 1 1^T) / 2 (correlated_delta_d=True)
    bs = (0.0, 0.0, 4.8)
    x = np.array([-20.0, 1.0, 1.0, 8.0, 1.0, -10.0, 1.0, 1.0, -1.2])
    pred, J = track_model(x, bs)
    cfg = JavelinConfig(base_station=bs)
    corr = FixedNoise(correlated_delta_d=True)
    meas = PathMeasurements.from_arrays(pred[:, 0], pred[:, 1], d=pred[:, 3])
    m = stack_measurement(pred, J, meas, [(i, i) for i in range(4)], cfg, los_path=0, noise=corr)
    dd = [k for k, lab in enumerate(m.labels) if lab[0] == "delta_d"]
    rng = np.random.default_rng(3)
    e = rng.normal(0.0, cfg.sigma_delta_d / np.sqrt(2.0), (200_000, 4))
    tdoa = e[:, 1:] - e[:, [0]]
    np.testing.assert_allclose(np.cov(tdoa.T), m.R[np.ix_(dd, dd)], atol=0.03)


def test_static_doppler_is_the_time_derivative_of_the_mirrored_range():
    bs = np.array([0.0, 0.0, 4.8])
    rng = np.random.default_rng(4)
    for _ in range(20):
        pu = np.array([rng.uniform(-45, -5), rng.uniform(-3, 3), rng.uniform(0.5, 2.0)])
        vu = np.array([rng.uniform(-15, 15), rng.uniform(-2, 2), 0.0])
        for pl in [None, *toy_reflectors()]:

            def rng_at(t, pl=pl, pu=pu, vu=vu):
                p = pu + t * vu
                pv = p if pl is None else pl.mirror(p)
                return np.linalg.norm(pv - bs)

            h = 1e-5
            rate = (rng_at(h) - rng_at(-h)) / (2 * h)
            pv = pu if pl is None else pl.mirror(pu)
            assert static_doppler(pu, pv, vu, bs) == pytest.approx(-rate, abs=1e-6)
            assert static_doppler(pu, pv, vu, bs, sign=1.0) == pytest.approx(rate, abs=1e-6)


@pytest.mark.parametrize("vue_motion", ["random_walk", "mirror"])
def test_process_noise_is_the_covariance_of_the_sampled_motion(vue_motion):
    # Q = G diag(s_nu^2, s_theta^2) G^T (+ diagonal walks) against the sample covariance of the
    # increment under sampled speed and heading (small angles: the linearisation is tight)
    st = JavelinState.initial([-30.0, 1.0, 1.0], 1.0)
    for pl in toy_reflectors():
        st.append(pl.mirror(st.ue)[1:], np.eye(2))
    st.P = np.zeros_like(st.P)
    cfg = JavelinConfig(sigma_vue_walk=1e-6, sigma_height=1e-6)
    speed, heading, dt = 10.0, 0.3, 0.1
    _, Q = predict(st, speed, heading, dt, cfg, vue_motion=vue_motion)
    rng = np.random.default_rng(5)
    nu = speed + cfg.sigma_speed * rng.standard_normal(40_000)
    th = heading + cfg.sigma_heading * rng.standard_normal(40_000)
    inc = np.array([motion_increment(st, a, b, dt, vue_motion)[0] for a, b in zip(nu, th)])
    # 5 standard errors of a sample covariance entry, sqrt((Q_ii Q_jj + Q_ij^2) / N)
    sd = np.sqrt(np.diag(Q))
    tol = 5.0 * np.sqrt((np.outer(sd, sd) ** 2 + Q**2) / nu.size) + 1e-12
    assert np.all(np.abs(np.cov(inc.T) - Q) <= tol)


def test_track_management_keeps_every_track_its_own_mean_covariance_and_pairs():
    # random misses, deaths, births: each surviving track keeps its mean and its covariance
    # blocks (with the cross terms), and every association pair still names the same track
    rng = np.random.default_rng(6)
    for _ in range(300):
        nv = int(rng.integers(0, 6))
        st = JavelinState.initial([-20.0, 1.0, 1.0], 1.0)
        for _k in range(nv):
            st.append([rng.uniform(-10, 10), rng.uniform(-3, 6)], np.eye(2))
        A = rng.standard_normal((st.dim, st.dim))
        st.P = A @ A.T + np.eye(st.dim)
        st.misses = [int(v) for v in rng.integers(0, 3, nv)]
        n = int(rng.integers(0, 6))
        meas = PathMeasurements.from_arrays(
            wrap_angle(np.pi + rng.uniform(-0.3, 0.3, n)),
            rng.uniform(-0.2, 0.2, n),
            kappa=rng.uniform(5, 30, n),
            d=rng.uniform(5, 30, n),
        )
        tr, pa = rng.permutation(nv + 1), rng.permutation(n)
        pairs = [(int(tr[q]), int(pa[q])) for q in range(int(rng.integers(0, min(nv + 1, n) + 1)))]
        ids0 = [0, *st.ids]
        P0 = st.P.copy()
        pos0 = {ids0[i]: st.position(i) for i in range(nv + 1)}
        idx0 = {0: [0, 1, 2], **{t: [3 + 2 * k, 4 + 2 * k] for k, t in enumerate(ids0[1:])}}
        res = manage_tracks(st, meas, pairs, JavelinConfig(max_misses=int(rng.integers(0, 3))))
        ids1 = [0, *st.ids]
        assert {(ids0[i], j) for i, j in pairs} <= {(ids1[i], j) for i, j in res.pairs}
        assert len({j for _, j in res.pairs}) == len(res.pairs) == len({i for i, _ in res.pairs})
        new, old = [], []
        for k, t in enumerate(ids1):
            if t in idx0:
                np.testing.assert_allclose(st.position(k), pos0[t])
                new += [0, 1, 2] if k == 0 else [3 + 2 * (k - 1), 4 + 2 * (k - 1)]
                old += idx0[t]
        np.testing.assert_array_equal(st.P[np.ix_(new, new)], P0[np.ix_(old, old)])
