"""The route's model order by a detection test per added path (``glrt_paths``,
``SignalRoute(model_order="glrt")``)."""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit import channel
from tunnelkit.signal_route import SignalRoute, glrt_paths

NF, NT = 48, 6


def _tensor(seed: int = 5):
    route = SignalRoute.from_scenario("italiano2026-straight")
    arr, paths = route.paths(12)
    cfg = route.config
    rng = np.random.default_rng(seed)
    H0 = channel.channel_tensor(paths, cfg, n_tones=NF, n_symbols=NT)
    H = channel.add_noise(H0, cfg.noise_power, rng)
    return route, arr, paths, H


def test_glrt_adds_the_paths_a_short_start_misses_and_stops_there():
    route, arr, paths, H = _tensor()
    L = len(paths)
    est = glrt_paths(H, arr, route.config, 1, 10, noise_power=route.config.noise_power)
    assert est.fit_ok is True
    assert len(est) == L
    assert est.fit.peak <= est.fit.peak_max
    d_true = np.sort([p.length for p in paths])
    assert np.allclose(np.sort(est.d), d_true, atol=0.05)
    # a cap below the true order stops at the cap, with the residual test still failing
    with pytest.warns(Warning, match="fit_ok = False"):
        capped = glrt_paths(H, arr, route.config, 1, L - 1, noise_power=route.config.noise_power)
    assert len(capped) == L - 1 and capped.fit.peak > capped.fit.peak_max


@pytest.mark.parametrize(
    ("args", "name"),
    [
        ((0, 4), "n_start"),
        ((3, 2), "max_paths"),
        ((100, 120), "n_start"),
    ],
)
def test_glrt_refuses_bad_input(args, name):
    route, arr, _, H = _tensor()
    with pytest.raises(ValueError, match=name):
        glrt_paths(H, arr, route.config, *args)


def test_glrt_refuses_a_tensor_of_another_array():
    route, arr, _, H = _tensor()
    with pytest.raises(ValueError, match="H"):
        glrt_paths(H[:50], arr, route.config, 1, 4)
    with pytest.raises(TypeError, match="array"):
        glrt_paths(H, "ura", route.config, 1, 4)


def test_route_model_order_validates():
    with pytest.raises(ValueError, match="model_order"):
        SignalRoute.from_scenario("italiano2026-straight", model_order="aic")
    with pytest.raises(ValueError, match="max_paths"):
        SignalRoute.from_scenario("italiano2026-straight", model_order="glrt", max_paths=0)
