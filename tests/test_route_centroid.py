"""A path whose curvature is unresolved is reported from the array's centroid
(:func:`tunnelkit.signal_route.farfield.centroid_far_field`)."""

from dataclasses import replace

import numpy as np
import pytest

from tunnelkit import arrays
from tunnelkit.extraction import PathEstimates
from tunnelkit.signal_route.farfield import UNRESOLVED_Z, centroid_far_field
from tunnelkit.signal_route.measurements import measurements_from_estimates

FC = 28e9


def _estimates(arr, q, d):
    """Estimates of wave origins ``q`` (L, 3; local frame, from the reference antenna)."""
    kappa = np.linalg.norm(q, axis=1)
    u = q / kappa[:, None]
    L = len(kappa)
    return PathEstimates(
        alpha=np.ones(L, complex),
        d=np.asarray(d, float),
        v=np.zeros(L),
        direction=u,
        kappa=kappa,
        near_field=np.ones(L, bool),
        phi=np.arctan2(u[:, 1], u[:, 0]),
        psi=np.arccos(u[:, 2]),
        valid=np.ones(L, bool),
        kappa_nf=kappa,
        delta=np.zeros((L, arr.M)),
        mu_f=np.zeros(L),
        mu_t=np.zeros(L),
        factors=(np.ones((arr.M, L)), np.ones((4, L)), np.ones((2, L))),
    )


def test_unresolved_curvature_is_reported_from_the_centroid():
    """Two paths whose fitted wave origin sits 4 m from the array on the ray from the centroid
    toward a source 80 m away (what a calibration error's quadratic phase does to an unresolved
    curvature, 28 GHz example): seen from the reference antenna (element 0, a corner) their
    directions are off by ``|c_perp| / 4 m`` (about 6 mrad on an 8 x 8); with a reported
    ``sigma_kappa`` the curvature cannot carry (200 m, an impairment budget), the direction is
    the centroid's (the source's to ``|c_perp| / 80 m``) and the path far-field; a resolved
    curvature (sigma 0.1 m) keeps the reference's direction and curvature."""
    arr = arrays.make_array(8, 8, fc=FC, azimuth=0.3, elevation=-0.4, origin=[0, 0, 6])
    c = arr.local.mean(axis=0)
    assert np.linalg.norm(c) > 0.02  # the reference antenna is a corner: 2.6 cm from the centre
    u0 = np.array([[0.1, 0.05, 1.0], [-0.12, 0.08, 1.0]])
    u0 /= np.linalg.norm(u0, axis=1, keepdims=True)
    source = 80.0 * u0  # local, from the reference antenna
    fitted = c + 4.0 * (source - c) / np.linalg.norm(source - c, axis=1, keepdims=True)
    est = _estimates(arr, fitted, [80.0, 81.0])
    meas = measurements_from_estimates(est, arr)
    truth = arr.dir_to_world(u0)
    off = np.linalg.norm(meas.direction - truth, axis=1)
    assert np.all(off > 4e-3)  # the old report: several mrad from the source

    cov = np.zeros((2, 3, 3))
    cov[:, :2, :2] = np.eye(2) * 1e-5
    cov[:, 2, 2] = 200.0**2
    loose = centroid_far_field(replace(meas, cov=cov, sigma_d=np.ones(2)), est, arr)
    err = np.linalg.norm(loose.direction - truth, axis=1)
    assert np.all(err < np.linalg.norm(c) / 80.0 + 1e-9)  # the far-field limit's model error
    assert np.all(err < 0.1 * off)
    assert np.all(np.isnan(loose.kappa)) and not loose.near_field.any()
    np.testing.assert_allclose(loose.phi, np.arctan2(truth[:, 1], truth[:, 0]), atol=5e-4)
    np.testing.assert_allclose(np.linalg.norm(loose.direction, axis=1), 1.0, atol=1e-12)
    np.testing.assert_array_equal(loose.d, meas.d)
    np.testing.assert_array_equal(loose.cov, cov)

    cov[0, 2, 2] = 0.1**2  # path 0 resolved (4 m >= 3 x 0.1 m), path 1 not
    mixed = centroid_far_field(replace(meas, cov=cov, sigma_d=np.ones(2)), est, arr)
    np.testing.assert_array_equal(mixed.direction[0], meas.direction[0])
    assert mixed.kappa[0] == meas.kappa[0] and mixed.near_field[0]
    assert np.isnan(mixed.kappa[1]) and err[1] == pytest.approx(
        np.linalg.norm(mixed.direction[1] - truth[1]), abs=1e-12
    )
    # the threshold: unresolved below z sigma_kappa
    at = 4.0 / UNRESOLVED_Z
    cov[0, 2, 2] = (at * 1.001) ** 2
    assert np.isnan(
        centroid_far_field(replace(meas, cov=cov, sigma_d=np.ones(2)), est, arr).kappa[0]
    )
    cov[0, 2, 2] = (at * 0.999) ** 2
    assert not np.isnan(
        centroid_far_field(replace(meas, cov=cov, sigma_d=np.ones(2)), est, arr).kappa[0]
    )


def test_centroid_far_field_without_covariance_and_bad_input():
    """No reported covariance: nothing to judge, the measurements as they are; a bad ``z`` or
    estimates that are not the measurements' are refused by name."""
    arr = arrays.make_array(4, 4, fc=FC, azimuth=0.0, elevation=0.0)
    est = _estimates(arr, np.array([[0.1, 0.0, 3.0]]), [3.0])
    meas = measurements_from_estimates(est, arr)
    assert centroid_far_field(meas, est, arr) is meas
    with pytest.raises(ValueError, match="z"):
        centroid_far_field(meas, est, arr, z=0.0)
    with pytest.raises(TypeError, match="est"):
        centroid_far_field(meas, "est", arr)


def test_route_flag_is_checked():
    """``RouteOptions.centroid_unresolved`` is a boolean."""
    from tunnelkit.signal_route import SignalRoute

    route = SignalRoute.from_scenario("italiano2026-straight")
    assert route.options.centroid_unresolved is False
    with pytest.raises((TypeError, ValueError), match="centroid_unresolved"):
        route.with_options(centroid_unresolved="yes")
