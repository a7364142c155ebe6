"""The pooled error quantile's interval over manufactured units (Woodruff's cluster interval):
its construction checked against the definition, its coverage by Monte-Carlo on clustered
errors where the percentile bootstrap over units under-covers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from tunnelkit import design


def _clustered(rng, units, s_unit, drives=2, T=40):
    """2-D errors with a unit bias (a calibration draw) and AR(1) noise along each drive."""
    b = rng.normal(0.0, s_unit, (units, 1, 1, 2))
    w = rng.normal(0.0, 0.5, (units, drives, T, 2))
    for t in range(1, T):
        w[:, :, t] = 0.9 * w[:, :, t - 1] + np.sqrt(1 - 0.81) * w[:, :, t]
    return np.linalg.norm(b + w, axis=-1).reshape(units, drives * T)


def test_the_interval_is_the_definition():
    """Pooled quantiles at share -+ t * sd(y_u) / sqrt(U), y_u each unit's share <= q."""
    rng = np.random.default_rng(11)
    e = _clustered(rng, 15, 1.0)
    q = design.share_quantile(e, 0.9)
    y = (e <= q).mean(axis=1)
    h = stats.t.ppf(0.975, 14) * y.std(ddof=1) / np.sqrt(15)
    flat = np.sort(e.ravel())
    want = [
        flat[int(np.ceil((0.9 - h) * flat.size)) - 1],
        flat[int(np.ceil((0.9 + h) * flat.size)) - 1],
    ]
    got = design.cluster_quantile_ci(e, 0.9)
    assert got == pytest.approx(want, rel=0, abs=0)
    assert got[0] <= q <= got[1]
    # a wider level, a wider interval; one unit, the degenerate interval
    w = design.cluster_quantile_ci(e, 0.9, level=0.99)
    assert w[0] <= got[0] and w[1] >= got[1]
    assert design.cluster_quantile_ci(e[:1], 0.9) == [design.share_quantile(e[:1], 0.9)] * 2
    # a unit with no estimate counts as infinite errors, never as small ones
    lost = e.copy()
    lost[:3] = np.nan
    assert design.cluster_quantile_ci(lost, 0.9)[1] == np.inf


@pytest.mark.parametrize("s_unit", [0.3, 2.0])
def test_it_covers_on_20_units_where_the_bootstrap_does_not(s_unit):
    """200 blocks of 20 units against a 20,000-unit reference (seeds not used elsewhere): the
    cluster interval covers within 90-98 % for a nominal 95 %; with a strong unit effect the
    percentile bootstrap over units covers less than it."""
    rng = np.random.default_rng([20261205, int(10 * s_unit)])
    ref = design.share_quantile(_clustered(rng, 20_000, s_unit), 0.9)
    blocks = 200
    inside = boot = 0
    for _ in range(blocks):
        e = _clustered(rng, 20, s_unit)
        lo, hi = design.cluster_quantile_ci(e, 0.9)
        inside += lo <= ref <= hi
        lo, hi = design.bootstrap_quantile_ci(e, 0.9, rng, n_boot=400)
        boot += lo <= ref <= hi
    lo, hi = design.wilson_interval(inside, blocks)
    assert 0.90 <= inside / blocks <= 0.98, (inside, boot)
    assert hi >= 0.95 >= lo or inside / blocks >= 0.93
    if s_unit >= 2.0:
        assert boot < inside


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"errors": np.ones(5)}, r"^errors: expected \(units, n\)"),
        ({"errors": -np.ones((3, 4))}, r"^errors: a position error is not negative"),
        ({"share": 1.5}, r"^share"),
        ({"level": 0.0}, r"^level"),
    ],
)
def test_bad_input_names_the_parameter(kw, match):
    args = {"errors": np.ones((3, 4)), "share": 0.9} | kw
    with pytest.raises((TypeError, ValueError), match=match):
        design.cluster_quantile_ci(args.pop("errors"), args.pop("share"), **args)
