import numpy as np
import pytest
from javelin_geometric import geometric_paths, toy_reflectors

from tunnelkit.tracking.javelin import PathMeasurements, TeNFiLoc

BS = (0.0, 0.0, 4.8)
PU = np.array([-22.0, 1.4, 1.0])


def _paths(los=True, bias=0.0, seed=0, **noise):
    return geometric_paths(
        PU,
        [5.0, 0, 0],
        toy_reflectors(),
        np.random.default_rng(seed),
        bs=BS,
        los=los,
        clock_bias=bias,
        **noise,
    )


def test_los_tuple_is_exact_without_noise():
    meas, _ = _paths(bias=2.0)
    fix = TeNFiLoc(base_station=BS).locate(meas)
    assert fix.mode == "los-kappa"
    np.testing.assert_allclose(fix.position, PU, atol=1e-9)
    # a clock bias of 12 m on a 22 m range breaks eq. 61 (d / kappa = 1.5): treated as NLoS
    meas12, _ = _paths(bias=12.0)
    assert TeNFiLoc(base_station=BS).locate(meas12).mode == "nlos"


def test_far_field_los_falls_back_on_the_biased_delay():
    meas, _ = _paths(bias=3.0)
    ff = PathMeasurements.from_arrays(meas.phi, meas.psi, None, meas.d, meas.v)
    fix = TeNFiLoc(base_station=BS).locate(ff)
    assert fix.mode == "los-d"
    # the clock bias lands on the range: error = bias along the arrival direction
    assert np.linalg.norm(fix.position - PU) == pytest.approx(3.0, abs=1e-9)


def test_nlos_eq69_least_squares_recovers_position_and_bias():
    meas, _ = _paths(los=False, bias=4.0)
    fix = TeNFiLoc(base_station=BS).locate(meas)  # started from the reflectors' centroid
    assert fix.mode == "nlos"
    np.testing.assert_allclose(fix.position, PU, atol=1e-5)
    # four spheres, four unknowns: another root exists, a poor start can land on it
    other = TeNFiLoc(base_station=BS).locate(meas, initial=PU + np.array([3.0, 1.0, 0.5]))
    assert 0.1 < np.linalg.norm(other.position - PU) < 0.5
    # the paper's synchronised version is biased by the clock offset
    sync = TeNFiLoc(base_station=BS, estimate_bias=False).locate(meas)
    assert np.linalg.norm(sync.position - PU) > 0.5


def test_not_enough_paths_gives_no_fix():
    meas, _ = _paths(los=False)
    assert TeNFiLoc(base_station=BS).locate(meas.subset([0, 1, 2])).position is None
    assert TeNFiLoc(base_station=BS).locate(None).mode == "none"
    assert TeNFiLoc(base_station=BS, nlos=False).locate(meas).position is None
    with pytest.raises(ValueError, match=r"^los_gamma"):
        TeNFiLoc(los_gamma=0.0)


def _los_only(kappa, d):
    """One LoS path along +x from BS with the given curvature and delay distance."""
    return PathMeasurements.from_arrays([0.0], [0.0], [kappa], [d], [0.0], warn=False)


def test_implausible_los_curvature_falls_back_on_the_delay():
    # a 45 m LoS path whose curvature came out at 6 km: the fix used to land 6 km away
    tf = TeNFiLoc(base_station=BS, assume_los=True)
    fix = tf.locate(_los_only(6000.0, 45.0))
    assert fix.mode == "los-d"
    np.testing.assert_allclose(fix.position, np.add(BS, [45.0, 0, 0]), atol=1e-12)
    # within the range but inconsistent with the delay beyond the clock-bias support (30 m)
    assert tf.bias_limit == pytest.approx(29.979, abs=1e-3)
    assert tf.locate(_los_only(80.0, 45.0)).mode == "los-d"
    assert tf.locate(_los_only(-3.0, 45.0)).mode == "los-d"
    # consistent: kappa - d = 25 m of clock bias (inside the support) keeps the curvature
    fix = tf.locate(_los_only(20.0, 45.0))
    assert fix.mode == "los-kappa"
    np.testing.assert_allclose(fix.position, np.add(BS, [20.0, 0, 0]), atol=1e-12)
    assert tf.plausible_kappa(20.0, 45.0) and not tf.plausible_kappa(20.0, 50.5)
    assert tf.plausible_kappa(20.0, np.nan) and not tf.plausible_kappa(201.0, np.nan)


def test_max_range_holds_on_every_branch():
    tf = TeNFiLoc(base_station=BS, assume_los=True, nlos=False, max_range=100.0)
    # curvature and delay both beyond max_range: no fix rather than a far one
    assert tf.locate(_los_only(150.0, 160.0)).position is None
    ff = PathMeasurements.from_arrays([0.0], [0.0], None, [500.0], [0.0], warn=False)
    assert tf.locate(ff).position is None
    # a negative delay (clock bias larger than the range) gives no range either
    assert tf.locate(_los_only(np.nan, -2.0)).position is None
    # NLoS: reflectors with curvatures beyond max_range are not used
    meas, _ = _paths(los=False, bias=4.0)
    wild = PathMeasurements.from_arrays(
        meas.phi, meas.psi, np.append(meas.kappa[:3], 5e3), meas.d, meas.v, warn=False
    )
    assert TeNFiLoc(base_station=BS).locate(wild).position is None  # 3 usable paths < 4
    with pytest.raises(ValueError, match=r"^bias_limit"):
        TeNFiLoc(bias_limit=0.0)


def test_nlos_fit_with_a_bias_outside_its_support_is_refused():
    meas, _ = _paths(los=False, bias=4.0)
    assert TeNFiLoc(base_station=BS, bias_limit=5.0).locate(meas).mode == "nlos"
    assert TeNFiLoc(base_station=BS, bias_limit=3.0).locate(meas).position is None
