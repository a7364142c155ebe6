"""Every filter follows one protocol (tunnelkit.tracking.protocol): ``predict(*inputs)``,
``update(z)``, ``step`` = both, an inspectable ``x`` and ``P``. Checked by running twins: one
steps, the other predicts then updates; their states agree bit for bit at every epoch."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tunnelkit import doppler_drive as dv
from tunnelkit.tracking import Filter, registry
from tunnelkit.tracking import virtual_station as vs
from tunnelkit.tracking.doppler import DopplerEKF, DopplerSetup, RangeKF, SpeedKF

EPOCHS = 8


def _same(a, b):
    np.testing.assert_array_equal(np.asarray(a.x), np.asarray(b.x))
    np.testing.assert_array_equal(np.asarray(a.P), np.asarray(b.P))


@pytest.mark.parametrize("name", list(registry.family("jiang2023")))
def test_jiang_filters(name):
    exp = vs.experiment("jiang2023-straight", level=2)
    Z = exp.model.simulate(exp.truth[:EPOCHS, :2], np.random.default_rng(0), size=1)[0]
    make = registry.get("jiang2023", name)
    a, b = (make(exp.model, exp.truth[0], exp.P0, rng=np.random.default_rng(5)) for _ in "ab")
    assert isinstance(a, Filter)
    for k in range(1, EPOCHS):
        a.step(Z[k])
        b.predict()
        b.update(Z[k])
        _same(a, b)


def _halili():
    drive = dv.make_drive()
    rng = np.random.default_rng(0)
    return dv.measure(drive, rng), dv.gnss_fix(drive, rng), DopplerSetup.from_drive(drive)


def test_halili_doppler_filters():
    meas, fix, setup = _halili()
    u0 = 10.0
    for make in (
        lambda: DopplerEKF(setup, fix, adaptive=True),
        lambda: SpeedKF(setup, u0, adaptive=True),
    ):
        a, b = make(), make()
        assert isinstance(a, Filter)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for k in range(1, 40):
                z = None if k == 5 else meas.doppler[k]
                a.step(z)
                b.predict()
                b.update(z)
                _same(a, b)


def test_halili_range_kf():
    meas, fix, setup = _halili()
    d0 = float(np.hypot(*(fix.position - setup.tx)))
    a, b = (RangeKF(setup, d0, calibration_epochs=3) for _ in "ab")
    assert isinstance(a, Filter) and a.x.shape == (1,) and a.P.shape == (1, 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in range(1, 40):
            a.step(8.0, meas.toa[k])
            b.predict(8.0)
            b.update(meas.toa[k])
            _same(a, b)
    # the step checks its inputs before the state moves
    x = a.x.copy()
    with pytest.raises(ValueError, match="u"):
        a.step(np.nan, meas.toa[1])
    np.testing.assert_array_equal(a.x, x)


def test_javelin():
    from tunnelkit import simulation
    from tunnelkit.tracking.javelin import Javelin, designs

    drive = simulation.simulate_drive(
        "italiano2026-straight", np.random.default_rng(0), condition="L", n_epochs=5
    )
    from tunnelkit.tracking.javelin.motion import midpoint_messages

    design = designs.ours_ml()
    assert design.config.motion_step == "midpoint"  # steps on the mean of two messages
    mid = midpoint_messages(drive.speed, drive.heading)
    a, b = (Javelin.for_drive(drive, design) for _ in "ab")
    assert isinstance(a, Filter)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k, paths in enumerate(drive.epochs):
            # the step into k on entry k-1 of the midpoint messages; epoch 0 on its own message
            j, src = (k - 1, mid) if k else (0, (drive.speed, drive.heading))
            speed, heading = src[0][j], src[1][j]
            dt = drive.dt if k else 0.0
            ra = a.step(paths, speed, heading, dt)
            b.predict(speed, heading, dt)
            rb = b.update(paths)
            _same(a, b)
            np.testing.assert_array_equal(ra.estimate, rb.estimate)
    # the run over the drive is these steps (the family's track)
    np.testing.assert_array_equal(a.x[:3], Javelin.for_drive(drive, design).track(drive)[0][-1])
    # an update without a prediction: the motion is unknown, the state did not move before it
    c = Javelin.for_drive(drive, design)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = c.update(drive.epochs[0])
    assert rep.k == 0 and np.all(np.isfinite(c.x))


def test_a_step_checks_its_arguments_before_the_state_moves():
    from tunnelkit.tracking.javelin import Javelin

    exp = vs.experiment("jiang2023-straight", level=2)
    f = registry.get("jiang2023", "EKF")(exp.model, exp.truth[0], exp.P0)
    x = np.array(f.x, copy=True)
    with pytest.raises(ValueError, match="z"):
        f.step(np.zeros(3))
    np.testing.assert_array_equal(f.x, x)
    trk = Javelin(initial_position=[-40.0, 1.5, -3.3])
    x, P = trk.x.copy(), trk.P.copy()
    with pytest.raises(TypeError, match="paths"):
        trk.step("bad", 10.0, 0.0, 0.1)
    np.testing.assert_array_equal(trk.x, x)
    np.testing.assert_array_equal(trk.P, P)
    # a missing message and a missing measurement: the paths' fault first, as one step reports
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = trk.step(None, None, None, 0.1)
    assert rep.faults[0].startswith("no measurement") and "speed/heading" in rep.faults[1]
    # a refused update keeps what the prediction left for the next one
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trk.predict(None, None, 0.1)
        with pytest.raises(TypeError, match="paths"):
            trk.update("bad")
        rep = trk.update(None)
    assert any("speed/heading" in f for f in rep.faults), rep.faults


def test_route_options_are_named_when_misplaced():
    from tunnelkit.signal_route import SignalRoute, simulate_epoch

    route = SignalRoute.from_scenario("italiano2026-straight")
    with pytest.raises(TypeError, match="third_order: not a route option"):
        route.with_options(third_order=1)
    with pytest.raises(TypeError, match="options=RouteOptions"):
        simulate_epoch("italiano2026-straight", 3, np.random.default_rng(0), model="srnf")


def test_the_batched_upf_steps_many_runs_and_checks_their_shape():
    from tunnelkit.tracking import upf

    exp = vs.experiment("jiang2023-straight", level=2)
    Z, x0 = exp.simulate(3, np.random.default_rng(0))
    f = upf.UnscentedParticleFilter(
        exp.model, x0, exp.P0, rng=np.random.default_rng(1), n_particles=50
    )
    assert f.step(Z[:, 0], first=True).shape == (3, 4)
    x = np.array(f.x, copy=True)
    with pytest.raises(ValueError, match="z"):
        f.step(Z[0, 1])  # one run's measurement for a batch of three
    np.testing.assert_array_equal(f.x, x)
    assert f.step(Z[:, 1]).shape == (3, 4)
