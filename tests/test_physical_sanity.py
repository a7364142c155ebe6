"""Inputs that would give physically impossible results are refused with the parameter named:
real-valued channel tensors, carriers given in GHz, bands reaching 0 Hz, sizes that are not sizes."""

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit.budget import memory_budget, set_memory_budget
from tunnelkit.channel import SRSConfig
from tunnelkit.extraction import extract_paths
from tunnelkit.propagation import fresnel_te
from tunnelkit.sizes import format_bytes


@pytest.mark.parametrize(
    "make", [np.abs, np.real, lambda H: np.real(H).astype(np.float32), lambda H: H != 0]
)
def test_a_real_valued_tensor_is_refused(epoch, make):
    H, L, array, srs = epoch
    with pytest.raises(TypeError, match=r"^H: expected a complex channel tensor"):
        extract_paths(make(H), L, array, srs)


def test_a_complex64_tensor_still_works(epoch):
    H, L, array, srs = epoch
    est = extract_paths(H.astype(np.complex64), L, array, srs, refine="joint")
    assert len(est.d) == L


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        (
            {"fc": 28.0},
            r"^fc: expected 1e\+08 to 3e\+11 Hz, got 28 \(fc is in Hz: did you mean 28e9\?\)",
        ),
        ({"fc": 5.9e3}, r"^fc: "),
        ({"fc": 100e6, "bandwidth": 200e6, "n_rb": 1}, r"^bandwidth: .* reaches 0 Hz"),
        ({"fc": 120e6, "bandwidth": 250e6, "n_rb": 1}, r"^bandwidth: "),
    ],
)
def test_radio_units_and_band(kw, match):
    with pytest.raises(ValueError, match=match):
        SRSConfig(**kw)


def test_a_band_just_inside_zero_is_accepted():
    cfg = SRSConfig(fc=100.1e6, bandwidth=200e6, n_rb=1)
    assert cfg.fc - cfg.bandwidth / 2 > 0


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -1.0])
def test_format_bytes_refuses_what_is_not_a_size(bad):
    with pytest.raises(ValueError, match=r"^n: "):
        format_bytes(bad)
    assert format_bytes(1536) == "1.5 KiB" and format_bytes(0) == "0 B"


def test_memory_budget_beyond_float_range_is_a_clear_error():
    before = memory_budget()
    with pytest.raises(ValueError, match=r"^nbytes: "):
        set_memory_budget(10**400)
    assert memory_budget() == before


def test_fresnel_without_a_boundary_at_grazing_incidence():
    with pytest.raises(ValueError, match=r"^eps_r, cos_i: "):
        fresnel_te(1.0, 0.0)
    assert fresnel_te(1.0, 0.5) == pytest.approx(0.0)  # no boundary: no reflection
    assert np.isfinite(fresnel_te(5.24, 0.0))  # a real boundary at grazing: |Gamma| = 1


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"target": np.nan}, "^target"),
        ({"share": np.nan}, "^share"),
        ({"share": 0.0}, "^share"),
        ({"share": 1.5}, "^share"),
    ],
)
def test_smallest_meeting_refuses_nan_targets(kw, match):
    setup = tk.design.DesignSetup.from_scenario("italiano2026-straight")
    with pytest.raises(ValueError, match=match):
        tk.design.smallest_meeting(setup, ["4x4"], **kw)


def test_a_path_faster_than_light_or_with_a_bent_direction_is_refused():
    import dataclasses

    from tunnelkit import signal_route
    from tunnelkit.constants import C
    from tunnelkit.propagation import Path

    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    p = route.paths(10)[1][0]
    kw = {f.name: getattr(p, f.name) for f in dataclasses.fields(p)}
    from tunnelkit._physical import MAX_SPEED

    for name in ("velocity", "range_rate"):
        for v in (1.01 * C, -2 * MAX_SPEED):  # light, and a car faster than any vehicle
            with pytest.raises(ValueError, match=rf"^{name}: .* faster than any road vehicle"):
                Path(**{**kw, name: v})
    with pytest.raises(ValueError, match=r"^direction: must be a unit vector"):
        Path(**{**kw, "direction": 2 * p.direction})
    with pytest.raises(ValueError, match=r"^length: must be > 0"):
        Path(**{**kw, "length": -1.0})
    assert Path(**kw) == p  # the traced path itself passes


def test_algorithm1_keeps_no_unphysical_path(epoch):
    """The bias-aware delay check (min_d < 0) does not read ``valid``: it drops an estimate
    faster than light or from behind the array itself."""
    import dataclasses

    from tunnelkit.constants import C
    from tunnelkit.extraction import algorithm1

    H, L, array, srs = epoch
    est = extract_paths(H, L, array, srs, refine="joint")
    kept = algorithm1(est, -30.0)
    i = int(kept[0])
    v = est.v.copy()
    v[i] = 2 * C
    fast = dataclasses.replace(est, v=v, valid=est.valid & (np.arange(L) != i))
    np.testing.assert_array_equal(algorithm1(fast, -30.0), kept[1:])
