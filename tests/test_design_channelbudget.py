"""The design's impairment budget handed to the channel route (tunnelkit.design.channelbudget)
and the route's switches for it (RouteOptions.model_error_floor / bias_budget)."""

import numpy as np
import pytest

from tunnelkit.design import DesignSetup, parse_array
from tunnelkit.design.achievable import DesignImpairments, path_error_model
from tunnelkit.design.bounds import route_geometry
from tunnelkit.design.channelbudget import channel_budget, channel_route_budget
from tunnelkit.design.errordraws import split
from tunnelkit.signal_route.judging import BiasBudget


@pytest.fixture(scope="module")
def setup():
    return DesignSetup.from_scenario("example-rectangular-28ghz")


def test_budget_is_the_split_less_the_noise_by_slot(setup):
    spec = parse_array("4x4")
    imp = DesignImpairments(phase_error_deg=0.5)
    m = path_error_model(setup, spec, imp)
    b = channel_budget(m, setup, spec)
    white, rep = split(m)
    T = m.exists.shape[0]
    g = route_geometry(setup, spec, epochs=np.arange(T))
    assert np.array_equal(b.source, g.source) and np.array_equal(b.exists, m.exists)
    k, p = 5, int(np.flatnonzero(m.exists[5])[1])
    noise = np.asarray(m.cov)[k, 4 * p : 4 * p + 4, 4 * p : 4 * p + 4]
    assert np.allclose(b.extra[k, p], white[k, p] - noise + rep[k, p])
    assert np.allclose(b.repeating, rep)
    # the budget is a covariance: positive semi-definite for every existing slot
    ev = np.linalg.eigvalsh(b.extra[m.exists])
    assert ev.min() >= -1e-9 * ev.max()
    # the slots are the surfaces, not the kinds: two walls, two road-marking columns
    assert sorted(g.kinds).count("wall") == 2
    assert channel_route_budget(setup, spec, DesignImpairments()) is None
    assert channel_route_budget(setup, spec, None) is None
    with pytest.raises(TypeError, match="impairments"):
        channel_route_budget(setup, spec, 0.5)


def test_route_switches_checked(setup):
    spec = parse_array("4x4")
    route = setup.signal_route(spec)
    with pytest.raises(TypeError, match="model_error_floor"):
        route.with_options(model_error_floor="yes")
    with pytest.raises(TypeError, match="bias_budget"):
        route.with_options(bias_budget=np.zeros(3))
    b = channel_route_budget(setup, spec, DesignImpairments(phase_error_deg=0.5))
    short = BiasBudget(b.source[:3], b.exists[:3], b.origin[:3], b.extra[:3], b.repeating[:3])
    with pytest.raises(ValueError, match="bias_budget"):
        route.with_options(bias_budget=short)
    assert route.with_options(model_error_floor=True, bias_budget=b).options.bias_budget is b
