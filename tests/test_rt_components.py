"""The ray-traced tensor split by what the first-order model leaves out (rt.components)."""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit import rt
from tunnelkit.constants import C

FC, DF, NF, T0, NT = 5.9e9, 240e3, 16, 35.7e-6, 4


def _paths(rng, constant_gain=False, same_delay=False):
    """Four slots per element on a 3 x 3 array: LoS, one first-order bounce seen by all but the
    last element, a second-order specular and a diffuse path (random delays and gains)."""
    pos = np.stack(np.meshgrid(np.arange(3), np.arange(3)), -1).reshape(-1, 2) * 0.025
    pos = np.c_[pos, np.zeros(9)]
    M = pos.shape[0]
    src = np.array([[20.0, 3.0, 1.0], [21.0, -4.0, 2.0]])
    dist = np.linalg.norm(src[:, None] - pos[None], axis=2).T  # (M, 2)
    tau = np.c_[dist / C, 30 / C + rng.uniform(0, 1e-8, (M, 2))]
    if same_delay:
        tau[:, :2] = tau[0, :2]
    amp = np.c_[1 / dist, rng.uniform(1e-3, 2e-3, (M, 2))]
    if constant_gain:
        amp[:, :2] = amp[0, :2]
    gain = amp * np.exp(-2j * np.pi * FC * tau) * np.exp(1j * rng.uniform(0, 6, (1, 4)))
    valid = np.ones((M, 4), bool)
    valid[-1, 1] = False  # the bounce leaves its facet before the last element
    return rt.ElementPaths(
        tau=tau,
        gain=gain,
        doppler=rng.uniform(-500, 500, (M, 4)),
        valid=valid,
        order=np.tile([0, 1, 2, 1], (M, 1)),
        diffuse=np.tile([False, False, False, True], (M, 1)),
        first_object=np.tile([-1, 7, 8, 9], (M, 1)),
    )


def _parts(ep):
    return rt.tensor_components(ep, FC, DF, NF, T0, NT, amplitude=2.0)


def test_parts_sum_to_the_tensor_and_match_their_paths():
    rng = np.random.default_rng(1)
    ep = _paths(rng)
    h = _parts(ep)
    total = h["first_order_model"] + sum(h[k] for k in rt.COMPONENTS)
    assert np.allclose(total, h["full"], rtol=0, atol=1e-9 * np.abs(h["full"]).max())
    direct = 2.0 * rt.element_tensor(ep, DF, NF, T0, NT, select=ep.mask("diffuse"))
    assert np.allclose(h["diffuse"], direct, atol=1e-12)
    for n in ("wideband", "element_gain", "element_doppler"):
        assert np.abs(h[n]).max() > 0, n
    groups = rt.first_order_groups(ep)
    assert [(g["order"], g["first_object"], g["count"]) for g in groups] == [(0, -1, 9), (1, 7, 8)]


def test_constant_gain_spherical_paths_leave_no_element_gain_and_equal_delays_no_wideband():
    """And equal Doppler shifts across the array leave no element_doppler part."""
    rng = np.random.default_rng(2)
    h = _parts(_paths(rng, constant_gain=True))
    scale = np.abs(h["full"]).max()
    assert np.abs(h["element_gain"]).max() < 1e-12 * scale
    h = _parts(_paths(rng, same_delay=True))
    assert np.abs(h["wideband"]).max() < 1e-12 * scale
    ep = _paths(rng)
    f = ep.doppler.copy()
    f[:, :2] = f[0, :2]
    h = _parts(rt.ElementPaths(ep.tau, ep.gain, f, ep.valid, ep.order, ep.diffuse, ep.first_object))
    assert np.abs(h["element_doppler"]).max() < 1e-12 * np.abs(h["full"]).max()


@pytest.mark.parametrize(
    ("kw", "name"),
    [({"paths": "x"}, "paths"), ({"fc": -1.0}, "fc"), ({"amplitude": 0.0}, "amplitude")],
)
def test_components_refuse_bad_input(kw, name):
    args = {"paths": _paths(np.random.default_rng(0)), "fc": FC}
    args.update(kw)
    err = TypeError if name == "paths" else ValueError
    with pytest.raises(err, match=name):
        rt.tensor_components(
            args["paths"], args["fc"], DF, NF, T0, NT, amplitude=kw.get("amplitude", 1.0)
        )
