import numpy as np
import pytest

from tunnelkit.tracking.javelin import PathMeasurements, TeNFiLoc
from tunnelkit.tracking.javelin.geometric import geometric_paths, toy_reflectors

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
