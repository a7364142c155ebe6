"""The route's nuisance model: second-order paths in the model, the diffuse floor of the ML test."""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit import channel, propagation, rt
from tunnelkit.propagation.second_order import second_order_paths
from tunnelkit.signal_route import RouteOptions, SignalRoute
from tunnelkit.simulation import drives


def test_second_order_paths_in_the_model():
    k = 12
    base = SignalRoute.from_scenario("italiano2026-straight")
    arr, first = base.paths(k)
    every = second_order_paths(
        base.tunnel,
        arr,
        base.trajectory.position[k],
        base.trajectory.velocity[k],
        fc=base.config.fc,
    )
    assert len(every) >= 3
    for n in (1, 2, 30):
        _, ps = base.with_options(second_order=n).paths(k)
        assert [p.length for p in ps[: len(first)]] == [p.length for p in first]
        extra = ps[len(first) :]
        assert len(extra) == min(n, len(every))
        strongest = sorted(abs(p.gain) for p in every)[::-1][: len(extra)]
        assert sorted(abs(p.gain) for p in extra)[::-1] == strongest
        assert all(p.kind == propagation.SECOND_ORDER for p in extra)


def test_image_channel_with_second_order_paths_is_fitted_and_they_are_dropped():
    """On the image channel with the second-order paths synthesised (option (a)), the ML route
    with them in its model passes its own fit test; the first-order-only model on the same
    tensor does not. The estimates of the second-order paths never reach the measurements."""
    route = SignalRoute.from_scenario("italiano2026-straight", options=RouteOptions(second_order=3))
    k = 24
    ep = route.epoch(k, np.random.default_rng(3))
    n1 = sum(p.kind != propagation.SECOND_ORDER for p in ep.paths)
    assert len(ep.paths) > n1 and len(ep.estimates) == len(ep.paths)
    assert ep.estimates.fit_ok is True
    ti = np.asarray(ep.truth_index)
    assert ti.size and np.all((ti >= 0) & (ti < n1))
    assert len(ep.measurements) >= n1 - 1
    # same tensor, first-order model: the second-order power is a structured residual
    with pytest.warns(Warning, match="fit_ok = False"):
        est = route.extract(ep.snapshot.H, ep.array, n1)
    assert est.fit_ok is False


def test_route_nuisance_options_validate(tmp_path):
    with pytest.raises(ValueError, match="second_order"):
        RouteOptions(second_order=-1)
    with pytest.raises(ValueError, match="second_order"):
        SignalRoute.from_scenario("italiano2026-straight").with_options(second_order=1000)
    with pytest.raises(ValueError, match="diffuse_floor"):
        SignalRoute.from_scenario("italiano2026-straight", options=RouteOptions(diffuse_floor=True))
    with pytest.raises((TypeError, ValueError), match="diffuse_floor"):
        SignalRoute.from_scenario(
            "italiano2026-straight", channel="sionna", cache_dir=tmp_path
        ).with_options(diffuse_floor="yes")
    with pytest.raises(TypeError, match="options"):
        SignalRoute.from_scenario("italiano2026-straight", options={"second_order": 1})
    with pytest.raises(ValueError, match="nuisance"):
        drives.scenario_route("italiano2026-straight", nuisance={"third_order": 1})


def test_diffuse_floor_is_noise_plus_diffuse_power(tmp_path, monkeypatch):
    route = SignalRoute.from_scenario(
        "italiano2026-straight",
        channel="sionna",
        cache_dir=tmp_path,
        options=RouteOptions(diffuse_floor=True),
    )
    assert isinstance(route.raytraced, rt.RayTracedChannel)
    monkeypatch.setattr(
        route.raytraced, "epoch", lambda k, tunnel=None: {"power": {"diffuse": 2e-9 * (k + 1)}}
    )
    snap = channel.ChannelSnapshot(
        np.zeros((1, 1, 1), complex), 1e-12, 0.0, "exact", (), route.config
    )
    got = route.ml_noise_power(4, snap)
    assert got == pytest.approx(1e-12 + route.config.tx_power * 1e-8)
    assert route.with_options(diffuse_floor=False).ml_noise_power(4, snap) is None
    # the routes built by name are kept per nuisance setting
    a = drives.scenario_route("italiano2026-straight", nuisance={"second_order": 2})
    assert a.options.second_order == 2 and a is drives.scenario_route(
        "italiano2026-straight", nuisance={"second_order": 2}
    )
    assert drives.scenario_route("italiano2026-straight").options.second_order == 0


def test_reproduce_nuisance_options_are_refused_where_they_do_not_apply(capsys):
    from tunnelkit.cli import main
    from tunnelkit.reproduce import run

    with pytest.raises(ValueError, match="nuisance"):
        run("jiang-crlb", runs=1, nuisance={"second_order": 2})
    assert main(["reproduce", "jiang-crlb", "--second-order", "2"]) == 2
    assert "--second-order" in capsys.readouterr().err
    assert main(["reproduce", "javelin-table1", "--diffuse-floor"]) == 2
    assert "--channel sionna" in capsys.readouterr().err
