"""The per-kind measurement noise: each path's sigmas from the kind of surface the geometry test
assigned it (``PathMeasurements.kind``, :class:`KindNoise`, ``design_from_errors(per_kind=True)``,
:func:`geometry_labels`), each checked against a brute-force construction."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tunnelkit.consistency import plane_kinds, tunnel_planes
from tunnelkit.simulation.drives import scenario_route
from tunnelkit.simulation.prefilter import geometry_keep, geometry_labels, traced_measurements
from tunnelkit.tracking.javelin import (
    FixedNoise,
    JavelinConfig,
    KindNoise,
    PathMeasurements,
    designs,
)

ROWS = (("los", 0.01, 0.02, 30.0, 0.2), ("road", 0.2, 0.3, 20.0, 1.6))


def _meas(kinds):
    n = len(kinds)
    m = PathMeasurements.from_arrays(
        np.linspace(0.1, 0.5, n), np.zeros(n), d=np.arange(10.0, 10.0 + n), warn=False
    )
    return m.with_kinds(kinds)


def test_each_path_gets_its_kinds_sigmas_and_every_other_path_the_configs():
    cfg = JavelinConfig()
    noise = KindNoise(ROWS)
    kinds = ["road", "", "los", "wall", "road"]
    m = _meas(kinds)
    table = {k: s for k, *s in ROWS}
    pooled = [cfg.sigma_phi, cfg.sigma_psi, cfg.sigma_kappa, cfg.sigma_delta_d]
    want = np.array([table.get(k, pooled) for k in kinds])
    cov = noise.covariances(m, cfg)
    for j in range(len(m)):  # brute force: one diagonal matrix per path
        np.testing.assert_array_equal(cov[j], np.diag(want[j, :3] ** 2))
    np.testing.assert_array_equal(
        noise.tdoa_covariance(m, [0, 1, 3, 4], 2, cfg), np.diag(want[[0, 1, 3, 4], 3] ** 2)
    )
    # unlabelled measurements: exactly the paper's fixed sigmas
    bare = replace(m, kind=None)
    fixed = FixedNoise()
    np.testing.assert_array_equal(noise.covariances(bare, cfg), fixed.covariances(bare, cfg))
    np.testing.assert_array_equal(
        noise.tdoa_covariance(bare, [0, 1], 2, cfg), fixed.tdoa_covariance(bare, [0, 1], 2, cfg)
    )


@pytest.mark.parametrize(
    "rows, exc, match",
    [
        ("los", TypeError, "sigmas"),
        ((), ValueError, "at least one row"),
        ((("los", 1.0, 1.0, 1.0),), TypeError, "sigmas"),
        ((("los", 1.0, 1.0, 1.0, 0.0),), ValueError, "sigmas"),
        ((("los", 1.0, 1.0, 1.0, np.nan),), ValueError, "sigmas"),
        ((("los", 1, 1, 1, 1), ("los", 2, 2, 2, 2)), ValueError, "distinct"),
        ((("", 1, 1, 1, 1),), ValueError, "non-empty"),
        ((("los", "a", 1, 1, 1),), TypeError, r"sigmas\['los'\]"),
        ((("los", None, 1, 1, 1),), TypeError, r"sigmas\['los'\]"),
        ((("los", True, 1, 1, 1),), TypeError, r"sigmas\['los'\]"),
    ],
)
def test_bad_kind_rows_are_named(rows, exc, match):
    with pytest.raises(exc, match=match):
        KindNoise(rows)


def test_the_kinds_ride_along_the_checks_and_subsets():
    m = PathMeasurements.from_arrays(
        [0.1, np.nan, 0.3, 0.4],
        [0.0, 0.1, 0.2, 0.3],
        d=[10.0, 11.0, -5.0, 12.0],
        warn=False,
        min_d=-10.0,
    )  # the NaN-angle path dropped here, the negative delay by the tracker's check
    m = m.with_kinds(["los", "road", "rrm"])
    assert m.kind.tolist() == ["los", "road", "rrm"]
    assert m.subset(np.array([2, 0])).kind.tolist() == ["rrm", "los"]
    clean, dropped = m.sanitised()
    assert dropped == 1 and clean.kind.tolist() == ["los", "rrm"]
    assert m.with_kinds(None).kind is None
    with pytest.raises(ValueError, match="kind"):
        m.with_kinds(["los"])
    with pytest.raises(TypeError, match="kind"):
        m.with_kinds("los")
    with pytest.raises(TypeError, match="kind"):
        m.with_kinds([1, 2, 3])
    with pytest.raises(TypeError, match="kind"):
        m.with_kinds({"los", "road", "rrm"})  # no order
    # one dtype whatever the strings: a record rebuilt with its checks equals the unchecked one
    assert m.kind.dtype == object and clean.kind.dtype == object


def test_plane_kinds_follow_tunnel_planes():
    tunnel = scenario_route("italiano2026-straight").tunnel
    planes, kinds = tunnel_planes(tunnel), plane_kinds(tunnel)
    assert len(planes) == len(kinds)
    for s in tunnel.surfaces:  # brute force: every surface's plane carries the surface's kind
        i = [k for k, p in enumerate(planes) if np.allclose(
            np.append(p.normal, p.offset), np.append(s.plane.normal, s.plane.offset), atol=1e-9
        )]  # fmt: skip
        assert len(i) == 1 and kinds[i[0]] == s.kind


def test_the_geometry_test_labels_the_true_kind_on_the_models_own_channel():
    route = scenario_route("italiano2026-straight")
    for k, seed in ((5, 1), (15, 2), (27, 3)):
        ep = route.epoch(k, np.random.default_rng(seed), refine="ml")
        keep, labels = geometry_labels(ep, route)
        assert keep.tolist() == geometry_keep(ep, route).tolist()
        truth = np.asarray(ep.truth_index)[keep]
        hit = truth >= 0
        true_kinds = [ep.paths[t].surface_kind for t in truth[hit]]
        assert labels[hit].tolist() == true_kinds
        pm, _ = traced_measurements(ep, route)
        assert pm.kind.tolist() == labels[np.searchsorted(keep, pm.source)].tolist()
    m = ep.measurements
    rows = ("phi", "psi", "kappa", "near_field", "d", "delta_d", "v", "direction", "alpha", "index")
    one = replace(ep, measurements=replace(m, **{f: getattr(m, f)[:1] for f in rows}))
    keep, labels = geometry_labels(one, route)
    assert keep.tolist() == [0] and labels.tolist() == [""]


def test_design_from_errors_per_kind():
    rows = [
        ["los", 80, 2.0, 2.5, 40.0, 0.2, 3],
        ["road", 79, 13.0, 16.0, None, 1.6, 79],
        ["wall", 5, 50.0, 50.0, 50.0, 5.0, 0],
        ["all", 164, 9.0, 8.0, 33.0, 1.1, 82],
    ]
    base = designs.ours_ml()
    pooled = designs.design_from_errors(rows, base=base)
    d = designs.design_from_errors(rows, base=base, per_kind=True)
    assert d.config == pooled.config and isinstance(pooled.noise, type(base.noise))
    got = {r[0]: r[1:] for r in d.noise.sigmas}
    assert sorted(got) == ["los", "road"]  # the wall's 5 measurements: too few for its own row
    assert got["los"] == pytest.approx((np.radians(2.0), np.radians(2.5), 40.0, 0.2))
    # no curvature measured on the road: the pooled sigma
    assert got["road"] == pytest.approx((np.radians(13.0), np.radians(16.0), 33.0, 1.6))
    no_psi = [["los", 80, 2.0, None, 40.0, 0.2, 3], rows[-1]]  # an empty angle: the pooled one
    got = {
        r[0]: r[1:]
        for r in designs.design_from_errors(no_psi, base=base, per_kind=True).noise.sigmas
    }
    assert got["los"] == pytest.approx((np.radians(2.0), np.radians(8.0), 40.0, 0.2))
    few = [r if r[0] != "los" else [*r[:1], 5, *r[2:]] for r in rows if r[0] != "road"]
    assert designs.design_from_errors(few, base=base, per_kind=True) == pooled
    with pytest.raises(TypeError, match="per_kind"):
        designs.design_from_errors(rows, base=base, per_kind="yes")
    with pytest.raises(ValueError, match="per_kind"):  # would drop the reported covariances
        designs.design_from_errors(
            rows,
            base=designs.array_design({"d": 0.05, "direction": 0.01, "kappa": 2.0}),
            per_kind=True,
        )
    bad = [["los", 80, -2.0, 2.5, 40.0, 0.2, 3], rows[-1]]
    with pytest.raises(ValueError, match=r"rows\['los'\]"):
        designs.design_from_errors(bad, base=base, per_kind=True)
    with pytest.raises(ValueError, match="rows"):
        designs.design_from_errors([["los", 80, 2.0], rows[-1]], base=base, per_kind=True)


def test_a_kind_row_equal_to_the_pooled_sigmas_tracks_exactly_as_the_fixed_noise():
    """Brute force: every path labelled with a kind whose row is the config's own sigmas gives
    the fixed-noise tracker's estimates bit for bit; another row for that kind moves them."""
    from tunnelkit.simulation import simulate_routes
    from tunnelkit.simulation.scoring import evaluate

    route = scenario_route("italiano2026-straight")
    drive = simulate_routes(route, np.random.default_rng(5), extractions=("ml",), n_epochs=6)["ml"]
    epochs = [None if m is None else m.with_kinds(["los"] * len(m)) for m in drive.epochs]
    labelled = replace(drive, epochs=epochs)
    base = designs.ours_ml()
    c = base.config
    assert isinstance(base.noise, FixedNoise)
    same = base.with_(
        noise=KindNoise((("los", c.sigma_phi, c.sigma_psi, c.sigma_kappa, c.sigma_delta_d),))
    )
    a, b = evaluate(drive, base), evaluate(labelled, same)
    np.testing.assert_array_equal(a.estimates, b.estimates)
    tight = base.with_(
        noise=KindNoise((("los", c.sigma_phi / 4, c.sigma_psi / 4, c.sigma_kappa, 0.05),))
    )
    assert not np.array_equal(evaluate(labelled, tight).estimates, a.estimates)
