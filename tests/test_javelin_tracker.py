import numpy as np
import pytest
from javelin_geometric import (
    geometric_paths,
    geometric_stream,
    toy_drive,
    toy_reflectors,
)

from tunnelkit.tracking.javelin import (
    Associator,
    DopplerClutter,
    FixedBirth,
    FixedNoise,
    Javelin,
    JavelinConfig,
    JavelinDesign,
    JavelinWarning,
    MirrorMotion,
    PathMeasurements,
    run_javelin,
)

BS = (0.0, 0.0, 4.8)
NOISE = dict(
    bs=BS,
    sigma_phi=np.radians(1.0),
    sigma_psi=np.radians(1.0),
    sigma_kappa=1.0,
    sigma_d=0.3,
    sigma_v=0.2,
)
CFG = JavelinDesign(JavelinConfig(base_station=BS, sigma_p0_ue=1.0))


def _drive(n, seed, *, amplitude=0.0, los_probability=1.0, speed=4.0):
    rng = np.random.default_rng(seed)
    P, V = toy_drive(n, 0.1, amplitude=amplitude, speed=speed)
    eps = geometric_stream(
        P,
        V,
        toy_reflectors(),
        rng,
        los_probability=los_probability,
        clock_bias=lambda r: r.normal(0.0, 3.0),
        **NOISE,
    )
    spd = np.linalg.norm(V, axis=1) + rng.normal(0, 0.2, n)
    hdg = np.arctan2(V[:, 1], V[:, 0]) + rng.normal(0, np.radians(1.0), n)
    return P, V, eps, spd, hdg


def _rmse2d(est, P):
    return float(np.sqrt(np.mean(np.sum((est[:, :2] - P[:, :2]) ** 2, axis=1))))


@pytest.mark.parametrize(
    ("amplitude", "los_probability", "goal"),
    [(0.0, 1.0, 0.25), (1.0, 1.0, 0.25), (0.0, 0.0, 0.35), (1.0, 0.5, 0.35)],
)
def test_tracks_the_geometric_truth(amplitude, los_probability, goal):
    P, _, eps, spd, hdg = _drive(150, 1, amplitude=amplitude, los_probability=los_probability)
    run = run_javelin(eps, spd, hdg, 0.1, P[0], CFG)
    assert _rmse2d(run.estimates, P) < goal
    assert np.mean(np.abs(run.estimates[:, 1] - P[:, 1])) < 0.12  # lane-level Y-MAE
    assert run.faults == 0
    # every path of the toy tunnel keeps a track: UE + 4 VUEs after the first epoch
    assert np.median(run.n_tracks) == 5


@pytest.mark.parametrize(
    "variant",
    [
        {"associator": Associator(solver="gnn")},
        {"vue_motion": MirrorMotion()},
        {"noise": FixedNoise(correlated_delta_d=True)},
        {"initiator": FixedBirth(update_at_birth=False)},
    ],
)
def test_variants_track_too(variant):
    P, _, eps, spd, hdg = _drive(100, 2, amplitude=1.0)
    run = run_javelin(eps, spd, hdg, 0.1, P[0], CFG.with_(**variant))
    assert _rmse2d(run.estimates, P) < 0.3


def test_faults_never_stop_a_run():
    P, V, eps, spd, hdg = _drive(60, 3)
    eps[10] = None  # dropped epoch
    eps[11] = PathMeasurements.empty()  # everything missed
    rng = np.random.default_rng(4)
    m, _ = geometric_paths(P[20], V[20], toy_reflectors(), rng, **NOISE)
    phi = m.phi.copy()
    phi[1] = np.nan
    with pytest.warns(JavelinWarning, match="NaN angle"):
        eps[20] = PathMeasurements.from_arrays(phi, m.psi, m.kappa, m.d, m.v)
    # more paths than the geometry explains: three spurious ones
    eps[30] = PathMeasurements.from_arrays(
        np.append(m.phi, rng.uniform(-3, 3, 3)),
        np.append(m.psi, rng.uniform(-1, 1, 3)),
        np.append(m.kappa, rng.uniform(5, 50, 3)),
        np.append(m.d, rng.uniform(5, 50, 3)),
    )
    spd[40:43] = np.nan  # speed/heading message missing
    trk = Javelin(P[0], CFG)
    faults = []
    for k in range(60):
        with pytest.warns(JavelinWarning) if k in (10, 11, 41, 42, 43) else _nowarn():
            r = trk.step(eps[k], spd[max(k - 1, 0)], hdg[max(k - 1, 0)], 0.1 if k else 0.0)
        faults.append(len(r.faults))
        assert np.all(np.isfinite(r.estimate))
    assert [k for k, f in enumerate(faults) if f] == [10, 11, 41, 42, 43]
    assert np.linalg.norm(r.estimate[:2] - P[-1, :2]) < 0.5
    with pytest.raises(TypeError, match=r"^paths"):
        trk.step({"phi": [0.1]}, 1.0, 0.0, 0.1)


class _nowarn:
    def __enter__(self):
        import warnings

        self._cm = warnings.catch_warnings()
        self._cm.__enter__()
        warnings.simplefilter("error", JavelinWarning)

    def __exit__(self, *exc):
        return self._cm.__exit__(*exc)


def test_no_message_ever_assumes_a_still_ue():
    trk = Javelin([-20.0, 1.0, 1.0], CFG)
    with pytest.warns(JavelinWarning) as rec:
        r = trk.step(None, None, None, 0.1)
    msgs = " | ".join(str(w.message) for w in rec)
    assert "predict only" in msgs and "none received yet" in msgs
    np.testing.assert_allclose(r.estimate, [-20.0, 1.0, 1.0])


def test_2000_epochs_finite_and_covariances_symmetric_psd():
    n = 2000
    P, _, eps, spd, hdg = _drive(n, 5, amplitude=1.0, los_probability=0.5, speed=2.0)
    rng = np.random.default_rng(6)
    for k in rng.choice(n, 100, replace=False):
        eps[k] = None
    trk = Javelin(P[0], CFG.with_(associator=Associator(solver="gnn")))
    worst = 0.0
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", JavelinWarning)
        for k in range(n):
            trk.step(eps[k], spd[max(k - 1, 0)], hdg[max(k - 1, 0)], 0.1 if k else 0.0)
            Pk = trk.state.P
            assert np.all(np.isfinite(trk.state.x)) and np.all(np.isfinite(Pk))
            assert np.array_equal(Pk, Pk.T)
            ev = np.linalg.eigvalsh(Pk)
            worst = min(worst, ev[0] / ev[-1])
    assert worst >= -1e-12
    assert np.linalg.norm(trk.state.ue[:2] - P[-1, :2]) < 1.0


def test_constructor_checks():
    with pytest.raises(ValueError, match=r"^initial_position"):
        Javelin([0.0, 1.0])
    with pytest.raises(TypeError, match=r"^design"):
        Javelin([0.0, 1.0, 1.0], design={"max_misses": 1})
    with pytest.raises(ValueError, match=r"^epochs, speed, heading"):
        run_javelin([None, None], [1.0], [0.0, 0.0], 0.1, [0, 1, 1])


def test_directly_built_paths_never_stop_a_run():
    # PathMeasurements(...) built without from_arrays: no ``source`` (the Doppler clutter filter
    # subsets it) and a NaN angle / a negative delay Algorithm 1 would have dropped
    P, _, eps, spd, hdg = _drive(5, 7)
    m = eps[1]
    raw = PathMeasurements(
        np.append(m.phi, [np.nan, 0.3]),
        np.append(m.psi, [0.0, -0.1]),
        np.append(m.kappa, [np.nan, 10.0]),
        np.append(m.d, [20.0, -4.0]),
        np.append(m.v, [500.0, 0.0]),
    )
    np.testing.assert_array_equal(raw.source, np.arange(len(m) + 2))
    trk = Javelin(P[0], CFG.with_prefilter(DopplerClutter(1.0)))
    trk.step(eps[0], spd[0], hdg[0], 0.0)
    with pytest.warns(JavelinWarning, match="Algorithm 1"):
        r = trk.step(raw, spd[0], hdg[0], 0.1)
    assert r.n_paths == len(m) and np.all(np.isfinite(trk.state.x))
    np.testing.assert_array_equal(r.paths.source, np.arange(len(m)))
    assert np.linalg.norm(r.estimate[:2] - P[1, :2]) < 0.5
    with pytest.raises(ValueError, match=r"^psi"):
        PathMeasurements(np.zeros(2), np.zeros(1), np.zeros(2), np.zeros(2), np.zeros(2))


def test_a_ue_on_the_base_station_axis_is_predict_only():
    trk = Javelin([0.0, 0.0, 1.0])  # under the reference antenna: azimuth undefined
    m = PathMeasurements.from_arrays([0.1], [-0.5], [5.0], [5.0])
    with pytest.warns(JavelinWarning, match="measurement model undefined"):
        r = trk.step(m, 1.0, 0.0, 0.0)
    np.testing.assert_allclose(r.estimate, [0.0, 0.0, 1.0])
    r = trk.step(m, 1.0, 0.0, 0.1)  # moved off the axis: a normal epoch again
    assert not r.faults and r.n_rows > 0
