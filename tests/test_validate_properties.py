"""Property-based tests of the validation layer over the public functions that take arrays.

For any finite input a function either returns finite numbers or raises ValueError/TypeError
naming one of its parameters (finite but geometrically impossible input, e.g. a point on a
station). Any input with one bad entry (NaN, inf, a complex number, text, None) raises
ValueError/TypeError naming that parameter. Never a NaN, never another exception type.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tunnelkit import (
    budget,
    constants,
    crlb,
    fresnel,
    geometry,
    metrics,
    positioning,
    propagation,
)
from tunnelkit import doppler_drive as drive
from tunnelkit.tracking import pcrlb, upf
from tunnelkit.tracking.gating import mahalanobis2

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
coord = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
pos = st.floats(1e-3, 1e3, allow_nan=False, allow_infinity=False)
BAD = {
    "nan": np.nan,
    "inf": np.inf,
    "complex": 1j,
    "text": "x",
    "none": None,
}


def _names(msg: str, names) -> bool:
    return any(re.search(rf"(?<![A-Za-z0-9_]){re.escape(n)}(?![A-Za-z0-9_])", msg) for n in names)


def finite_or_clear(fn, names):
    """Call ``fn``: finite output, or ValueError/TypeError naming one of ``names``."""
    try:
        out = fn()
    except (ValueError, TypeError) as exc:
        assert _names(str(exc), names), f"error does not name {names}: {exc}"
        return None
    leaves = out if isinstance(out, tuple) else (out,)
    for leaf in leaves:
        a = np.asarray(leaf)
        if a.dtype.kind in "fc":
            assert np.all(np.isfinite(a)), f"non-finite output {a}"
    return out


def clear_error(fn, name):
    with pytest.raises((ValueError, TypeError)) as info:
        fn()
    assert _names(str(info.value), (name,)), f"error does not name {name}: {info.value}"


def _poison(arr, kind):
    if kind == "none":
        return None
    if kind == "text":
        return np.full(np.shape(arr), "x").tolist()
    out = np.array(arr, dtype=complex if kind == "complex" else float)
    out.flat[0] = BAD[kind] if kind != "complex" else out.flat[0] + 1j
    return out


points2 = arrays(float, st.tuples(st.integers(1, 4), st.just(2)), elements=coord)
stations = arrays(float, st.tuples(st.integers(2, 4), st.just(2)), elements=coord)
bad_kind = st.sampled_from(sorted(BAD))


@SETTINGS
@given(p=points2, s=stations, sth=pos, sd=pos)
def test_crlb_finite_or_clear(p, s, sth, sd):
    names = ("p", "stations", "F", "sigma_theta", "sigma_d")
    finite_or_clear(lambda: crlb.toa_doa(p, s), names)
    finite_or_clear(lambda: crlb.toa_doa_jacobian(p, s), names)
    finite_or_clear(lambda: crlb.crlb_rmse(p, s, sth, sd), names)


@SETTINGS
@given(p=points2, s=stations, kind=bad_kind, which=st.sampled_from(["p", "stations"]))
def test_crlb_bad_entry_named(p, s, kind, which):
    args = {"p": p, "stations": s}
    args[which] = _poison(args[which], kind)
    clear_error(lambda: crlb.toa_doa(**args), which)
    clear_error(lambda: crlb.fim_toa_doa(**args, sigma_theta=0.01, sigma_d=0.5), which)


@SETTINGS
@given(F=arrays(float, (2, 2), elements=coord))
def test_crlb_trace_finite_positive_or_clear(F):
    out = finite_or_clear(lambda: crlb.crlb_trace(F), ("F",))
    if out is not None:
        assert out > 0


@SETTINGS
@given(a=arrays(float, st.integers(0, 5), elements=coord), kind=bad_kind)
def test_wrap_angle(a, kind):
    w = finite_or_clear(lambda: crlb.wrap_angle(a), ("a",))
    assert np.all((w > -np.pi) & (w <= np.pi))
    if a.size:
        clear_error(lambda: crlb.wrap_angle(_poison(a, kind)), "a")


@SETTINGS
@given(
    s=stations,
    d=arrays(float, 4, elements=pos),
    th=arrays(float, 4, elements=st.floats(-3.14, 3.14)),
    kind=bad_kind,
)
# found by the search: numerically singular systems (stations 1e-253 m apart in x; two stations
# on the y axis with every bearing 1e-103 rad from x)
@example(
    s=np.array([[2.4819217e-253, 1.0], [0.0, 0.0]]),
    d=np.ones(4),
    th=np.zeros(4),
    kind="complex",
)
@example(
    s=np.array([[0.0, 1.0], [0.0, 0.0]]),
    d=np.ones(4),
    th=np.full(4, 1.36688833e-103),
    kind="complex",
)
def test_positioning(s, d, th, kind):
    n = s.shape[0]
    d, th = d[:n], th[:n]
    names = ("stations", "d_hat", "theta_hat")
    finite_or_clear(lambda: positioning.ls_toa_doa(s, d, th), names)
    finite_or_clear(lambda: positioning.tswls(s, d, th, 0.5, 0.01), names)
    good = np.array([[0.0, 0.0], [0.0, 10.0], [0.0, -10.0], [5.0, 5.0]])[:n]
    clear_error(lambda: positioning.tswls(good, _poison(d, kind), th, 0.5, 0.01), "d_hat")
    clear_error(lambda: positioning.ls_toa_doa(good, d, _poison(th, kind)), "theta_hat")


@SETTINGS
@given(p=arrays(float, st.tuples(st.integers(1, 3), st.just(3)), elements=coord), kind=bad_kind)
def test_plane_mirror(p, kind):
    plane = geometry.Plane(np.array([0.0, 1.0, 0.0]), -5.0)
    m = finite_or_clear(lambda: plane.mirror(p), ("p",))
    np.testing.assert_allclose(plane.mirror(m), p, atol=1e-9)
    clear_error(lambda: plane.mirror(_poison(p, kind)), "p")


@SETTINGS
@given(
    est=arrays(float, st.tuples(st.integers(0, 4), st.just(2)), elements=coord),
    kind=bad_kind,
)
def test_metrics(est, kind):
    tru = np.zeros_like(est)
    out = finite_or_clear(lambda: metrics.rmse(est, tru), ("estimate", "truth"))
    if est.shape[0] == 0:
        assert out is None  # an empty sample is an error, not NaN
    if est.size:
        clear_error(lambda: metrics.rmse(_poison(est, kind), tru), "estimate")
        clear_error(lambda: metrics.error_stats(_poison(est, kind)), "errors")


@SETTINGS
@given(
    p=points2,
    v=arrays(float, 2, elements=coord),
    tx=arrays(float, 2, elements=coord),
    dz=coord,
    fc=st.floats(1e6, 1e11),
    kind=bad_kind,
)
def test_drive_helpers(p, v, tx, dz, fc, kind):
    names = ("p", "v", "tx", "fc", "dz")
    finite_or_clear(lambda: drive.slant_range(p, tx, dz), names)
    finite_or_clear(lambda: drive.doppler_shift(p, v, tx, fc, dz), names)
    clear_error(lambda: drive.doppler_shift(_poison(p, kind), v, tx, fc, dz), "p")
    clear_error(lambda: drive.slant_range(p, _poison(tx, kind), dz), "tx")
    clear_error(lambda: drive.doppler_shift(p, v, tx, -fc, dz), "fc")


@SETTINGS
@given(w=arrays(float, st.tuples(st.integers(1, 3), st.integers(1, 6)), elements=st.floats(0, 10)))
def test_particle_weights(w):
    seed = 0
    ess = finite_or_clear(lambda: upf.effective_sample_size(w), ("weights",))
    idx = finite_or_clear(
        lambda: upf.systematic_resample(w, np.random.default_rng(seed)), ("weights",)
    )
    if ess is not None:
        assert np.all((ess >= 1 - 1e-9) & (ess <= w.shape[-1] + 1e-9))
        assert idx.shape == w.shape and np.all((idx >= 0) & (idx < w.shape[-1]))
        assert np.all(w[np.arange(w.shape[0])[:, None], idx] > 0)  # never a zero-weight particle
    neg = w.copy()
    neg.flat[0] = -1.0
    clear_error(lambda: upf.systematic_resample(neg, np.random.default_rng(seed)), "weights")


@SETTINGS
@given(ci=arrays(float, st.integers(1, 4), elements=st.floats(0, 1)), eps=st.floats(1, 80))
def test_fresnel_te(ci, eps):
    g = finite_or_clear(lambda: propagation.fresnel_te(complex(eps, -0.3), ci), ("cos_i", "eps_r"))
    assert np.all(np.abs(g) <= 1 + 1e-12)
    clear_error(lambda: propagation.fresnel_te(eps, ci + 1.5), "cos_i")
    clear_error(lambda: propagation.fresnel_te(eps, -ci - 0.5), "cos_i")


@SETTINGS
@given(
    R=arrays(float, st.integers(1, 3), elements=st.floats(0.5, 500)),
    W=st.floats(0.5, 10),
    frac=st.floats(-2, 0.99),
    kind=bad_kind,
)
def test_mmax_bounds(R, W, frac, kind):
    names = ("R", "W", "y_u", "fc", "eps_phi")
    finite_or_clear(lambda: fresnel.mmax_2d(R, W, frac * W, 5.9e9, 0.15), names)
    finite_or_clear(lambda: fresnel.mmax_nonparaxial(R, W, frac * W, 5.9e9, 0.15), names)
    clear_error(lambda: fresnel.mmax_2d(_poison(R, kind), W, frac * W, 5.9e9, 0.15), "R")


@SETTINGS
@given(x=arrays(float, st.integers(1, 4), elements=st.floats(-100, 100)), kind=bad_kind)
def test_db_helpers(x, kind):
    finite_or_clear(lambda: constants.db2lin(x), ("x_db",))
    np.testing.assert_allclose(constants.lin2db(constants.db2lin(x)), x, atol=1e-9)
    clear_error(lambda: constants.db2lin(_poison(x, kind)), "x_db")


@SETTINGS
@given(A=arrays(float, (3, 3), elements=st.floats(-10, 10)), y=arrays(float, 3, elements=coord))
def test_information_matrices(A, y):
    spd = A @ A.T + 1e-3 * np.eye(3)
    assert finite_or_clear(lambda: mahalanobis2(y, spd), ("y", "S")) >= 0
    assert np.all(finite_or_clear(lambda: pcrlb.pcrlb_position_rmse(spd), ("bounds",)) >= 0)
    clear_error(lambda: mahalanobis2(y, -spd), "S")
    clear_error(lambda: pcrlb.pcrlb_position_rmse(-spd), "bounds")
    if not np.allclose(A, A.T):
        clear_error(lambda: crlb.crlb_trace(A), "F")


@SETTINGS
@given(n=st.integers(10**9, 10**15))
def test_budget_names_the_parameter(n):
    clear_error(lambda: budget.check_elements("n_particles", n, 32), "n_particles")
