"""design.achievable / design.mcrb: the misspecified bound of the array design, checked against
brute force (finite-difference Jacobians, explicit covariances, an exact nonlinear fit) and the
route's existing bounds."""

import numpy as np
import pytest

from tunnelkit import design
from tunnelkit.design.achievable import (
    DesignImpairments,
    achievable_bound,
    path_error_model,
)

SCEN = "italiano2026-straight"
EPOCHS = [0, 12, 25]


@pytest.fixture(scope="module")
def setup():
    return design.DesignSetup.from_scenario(SCEN)


# --- the route-level results ----------------------------------------------------------------


def test_ideal_model_is_the_per_path_crlb(setup):
    m = path_error_model(setup, "6x6", epochs=EPOCHS)
    np.testing.assert_array_equal(m.cov, m.crlb)
    assert not m.bias.any() and m.k_phase is None and m.k_gain is None
    pb = design.path_bounds(setup, "6x6", epochs=EPOCHS)
    sd = np.sqrt(np.diagonal(m.crlb, axis1=1, axis2=2)).reshape(*m.exists.shape, 4)[m.exists]
    # kappa and d: the same joint bound as extraction.crlb_paths
    np.testing.assert_allclose(sd[:, 2], pb["kappa"], rtol=1e-6)
    np.testing.assert_allclose(sd[:, 3], pb["d"], rtol=1e-6)
    # direction: sqrt(var phi cos^2 psi + var psi) is the angle between unit vectors
    psi = m.truth[m.exists][:, 1]
    ang = np.sqrt(sd[:, 0] ** 2 * np.cos(psi) ** 2 + sd[:, 1] ** 2)
    np.testing.assert_allclose(ang, pb["direction"], rtol=1e-4)


def test_truth_is_the_measurement_space_of_the_tracker(setup):
    g = design.route_geometry(setup, "6x6", epochs=EPOCHS)
    m = path_error_model(setup, "6x6", geometry=g)
    rel = g.source - g.origin[:, None, :]
    t, p = np.nonzero(g.exists)
    z = m.truth[t, p]
    np.testing.assert_allclose(z[:, 2], np.linalg.norm(rel[t, p], axis=1))
    np.testing.assert_allclose(z[:, 3], z[:, 2])
    back = z[:, 2, None] * np.column_stack(
        [np.cos(z[:, 1]) * np.cos(z[:, 0]), np.cos(z[:, 1]) * np.sin(z[:, 0]), np.sin(z[:, 1])]
    )
    np.testing.assert_allclose(back, rel[t, p], atol=1e-9)
    np.testing.assert_allclose(m.t, setup.trajectory.t[EPOCHS])


def test_no_impairment_achievable_equals_peb(setup):
    b = achievable_bound(setup, "6x6", DesignImpairments(), epochs=EPOCHS)
    peb = design.route_bounds(setup, "6x6", epochs=EPOCHS).peb
    np.testing.assert_array_equal(b.achievable, peb)
    np.testing.assert_array_equal(b.peb, peb)
    assert not (b.calibration.any() or b.wideband.any() or b.diffuse.any())
