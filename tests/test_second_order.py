"""Second-order specular paths by the image method, against brute force (Fermat's principle)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

import tunnelkit as tk
from tunnelkit import propagation as pr
from tunnelkit.constants import C
from tunnelkit.propagation.second_order import second_order_paths


def _setup(k):
    sc = tk.load_scenario("italiano2026-straight")
    tun = sc.tunnel()
    traj = sc.trajectory(tun)
    ue, vel = traj.position[k], traj.velocity[k]
    arr = pr.select_array(pr.scenario_arrays(sc), ue)
    return tun, arr, ue, vel, sc.get("radio.fc")


def _shortest_via(s1, s2, ue, a0):
    """Brute force: the shortest UE -> plane(S1) -> plane(S2) -> a0 (a convex problem in the
    four plane coordinates), the two points where it bounces."""

    def pts(x):
        q1 = s1.corner + x[0] * s1.edge_u + x[1] * s1.edge_v
        q2 = s2.corner + x[2] * s2.edge_u + x[3] * s2.edge_v
        return q1, q2

    def length(x):
        q1, q2 = pts(x)
        return np.linalg.norm(ue - q1) + np.linalg.norm(q1 - q2) + np.linalg.norm(q2 - a0)

    r = minimize(length, np.full(4, 0.5), method="BFGS", options={"gtol": 1e-12, "xrtol": 1e-14})
    return r.fun, *pts(r.x)


@pytest.mark.parametrize("k", [0, 12, 25])
def test_second_order_paths_are_the_shortest_double_bounces(k):
    tun, arr, ue, vel, fc = _setup(k)
    second = second_order_paths(tun, arr, ue, vel, fc=fc)
    assert len(second) >= 3  # ceiling-road, road-ceiling, an RRM or a wall pair
    by_name = {s.name: s for s in tun.surfaces}
    for p in second:
        n1, n2 = p.surface.split(" > ")
        s1, s2 = by_name[n1], by_name[n2]
        best, q1, q2 = _shortest_via(s1, s2, ue, arr.origin)
        assert p.length == pytest.approx(best, abs=1e-6)
        np.testing.assert_allclose(p.point, q2, atol=1e-4)
        assert s1.contains(q1, tol=1e-6) and s2.contains(q2, tol=1e-6)
        # the source is the UE mirrored twice; the wavefront is centred on it at every antenna
        np.testing.assert_allclose(p.source, s2.plane.mirror(s1.plane.mirror(ue)), atol=1e-12)
        np.testing.assert_allclose(p.lengths, np.linalg.norm(arr.world - p.source, axis=1))
        # SR-NF length: the path up to the last bounce, then straight to each antenna
        lead = np.linalg.norm(ue - q1) + np.linalg.norm(q1 - q2)
        np.testing.assert_allclose(
            p.lengths_srnf, lead + np.linalg.norm(arr.world - q2, axis=1), atol=1e-4
        )
        # Doppler: the finite-difference rate of the brute-force length
        dt = 1e-3
        plus = _shortest_via(s1, s2, ue + vel * dt, arr.origin)[0]
        minus = _shortest_via(s1, s2, ue - vel * dt, arr.origin)[0]
        assert p.range_rate == pytest.approx((plus - minus) / (2 * dt), abs=1e-4)
        assert p.doppler == pytest.approx(-fc * p.range_rate / C)
        # |gain| = |Gamma1 Gamma2| lambda / (4 pi d) with each bounce's own incidence
        ci1 = s1.plane.signed_distance(ue) / np.linalg.norm(ue - q1)
        ci2 = s2.plane.signed_distance(q1) / np.linalg.norm(q1 - q2)
        gam = s1.reflection_coefficient(fc, ci1) * s2.reflection_coefficient(fc, ci2)
        assert p.reflection_coefficient == pytest.approx(complex(gam), rel=1e-4)
        assert abs(p.gain) == pytest.approx(
            abs(p.reflection_coefficient) * C / fc / (4 * np.pi * p.length), rel=1e-12
        )
        assert p.kind == p.surface_kind == pr.SECOND_ORDER


def test_second_order_finds_every_double_bounce():
    """Every surface pair whose brute-force shortest double bounce lands inside both finite
    surfaces (on their lit sides, in front of the array) is found, and no other pair: a pair
    within 0.1 mm of a surface's edge (a bounce into the corner between two facets) may go
    either way."""
    tun, arr, ue, vel, fc = _setup(12)
    found = {p.surface for p in second_order_paths(tun, arr, ue, vel, fc=fc)}
    inside, edge = set(), set()
    for s1 in tun.surfaces:
        for s2 in tun.surfaces:
            if s1 is s2 or s1.plane.signed_distance(ue) <= 0:
                continue
            if s2.plane.signed_distance(arr.origin) <= 0:
                continue
            if s2.plane.signed_distance(s1.plane.mirror(ue)) <= 0:
                continue
            _, q1, q2 = _shortest_via(s1, s2, ue, arr.origin)
            lit = (
                s1.plane.signed_distance(q2) > -1e-4
                and s2.plane.signed_distance(q1) > -1e-4
                and arr.in_front(q2)
            )
            name = f"{s1.name} > {s2.name}"
            if lit and s1.contains(q1, tol=-1e-4) and s2.contains(q2, tol=-1e-4):
                inside.add(name)
            elif lit and s1.contains(q1, tol=1e-4) and s2.contains(q2, tol=1e-4):
                edge.add(name)
    assert len(inside) >= 4
    assert inside <= found <= inside | edge


def test_trace_paths_order_two_keeps_the_first_order_untouched():
    tun, arr, ue, vel, fc = _setup(12)
    one = pr.trace_paths(tun, arr, ue, vel, fc=fc)
    two = pr.trace_paths(tun, arr, ue, vel, fc=fc, order=2)
    assert [p.length for p in two[: len(one)]] == [p.length for p in one]
    extra = two[len(one) :]
    assert extra and all(p.kind == pr.SECOND_ORDER for p in extra)
    assert [p.surface for p in extra] == [
        p.surface for p in second_order_paths(tun, arr, ue, vel, fc=fc)
    ]
    # kinds filters both bounces
    no_rrm = pr.trace_paths(
        tun, arr, ue, vel, fc=fc, order=2, kinds=("los", "wall", "ceiling", "road")
    )
    assert all("RRM" not in p.surface for p in no_rrm)
    assert any("RRM" in p.surface for p in extra)


@pytest.mark.parametrize(
    ("kw", "name"), [({"order": 3}, "order"), ({"order": 0}, "order"), ({"kinds": ("x",)}, "kinds")]
)
def test_bad_input(kw, name):
    tun, arr, ue, vel, fc = _setup(0)
    with pytest.raises(ValueError, match=name):
        pr.trace_paths(tun, arr, ue, vel, fc=fc, **kw)
    if "kinds" in kw:
        with pytest.raises(ValueError, match=name):
            second_order_paths(tun, arr, ue, vel, fc=fc, **kw)
