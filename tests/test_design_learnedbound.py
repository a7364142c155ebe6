"""The bound over the drive of a tracker that learns its VUEs (design.learnedbound)."""

from functools import lru_cache

import numpy as np
import pytest

from tunnelkit import design
from tunnelkit.design.achievable import DesignImpairments, path_error_model
from tunnelkit.design.arrayjob import model_head
from tunnelkit.design.drivebound import (
    drive_pcrlb,
    position_bias_rms,
    position_information,
)
from tunnelkit.design.learnedbound import (
    SIGMA_BIRTH,
    batch_information,
    learned_model,
    learned_pcrlb,
)


@lru_cache(maxsize=1)
def _case():
    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    spec = design.parse_array("4x4")
    imp = DesignImpairments(phase_error_deg=0.5, gain_error_db=0.2)
    m = path_error_model(setup, spec, impairments=imp)
    g = design.route_geometry(setup, spec, epochs=np.arange(m.exists.shape[0]))
    return setup, spec, m, g


def _short(K):
    setup, spec, m, _ = _case()
    return setup, model_head(m, K), design.route_geometry(setup, spec, epochs=np.arange(K))


def test_recursion_matches_the_batch_information_on_a_short_drive():
    setup, m, g = _short(8)
    walk = 0.05  # a random walk the batch's Q^-1 can be formed with
    info, Q, born, _ = learned_model(m, g, setup, sigma_walk=walk)
    # a drive stretch whose paths are all there from the first epoch: births at k = 0 only
    K = int(np.argmax(born[1:].any(axis=1))) + 1 if born[1:].any() else born.shape[0]
    assert K >= 3
    n = info.shape[1]
    P0 = np.diag([1.0, 1.0] + [SIGMA_BIRTH**2] * (n - 2))
    rec, _ = learned_pcrlb(m, g, setup, sigma_walk=walk)
    for k in range(1, K):
        J = batch_information(info[: k + 1], Q[: k + 1], P0)
        C = np.linalg.inv(J)[k * n : k * n + 2, k * n : k * n + 2]
        assert np.sqrt(np.trace(C)) == pytest.approx(rec[k], rel=1e-6)


def test_known_surfaces_reproduce_drive_pcrlb():
    setup, _, m, g = _case()
    pk, _ = learned_pcrlb(m, g, setup, vues="known")
    ref = drive_pcrlb(setup, position_information(m, g))
    np.testing.assert_allclose(pk, ref, rtol=1e-6)


def test_filter_bias_of_one_epoch_is_the_snapshot_bias():
    """One epoch, a prior that says nothing (1 km): the filter is the weighted snapshot fit, so
    its bias is position_bias_rms's (an independent computation)."""
    setup, m, g = _short(1)
    _, b = learned_pcrlb(m, g, setup, vues="known", sigma_p0=1e3)
    ref = position_bias_rms(m, g)
    assert ref[0] > 0
    assert b[0] == pytest.approx(ref[0], rel=1e-4)


def test_learning_the_vues_costs_information():
    setup, _, m, g = _case()
    pk, _ = learned_pcrlb(m, g, setup, vues="known")
    pl, _ = learned_pcrlb(m, g, setup)
    assert np.all(pl >= pk * (1 - 1e-9))
    assert np.mean(pl) > 1.05 * np.mean(pk)


def test_bad_input():
    setup, m, g = _short(3)
    with pytest.raises(ValueError, match="vues"):
        learned_model(m, g, setup, vues="guess")
    with pytest.raises(TypeError, match="model"):
        learned_model(None, g, setup)
    with pytest.raises(ValueError, match="sigma_birth"):
        learned_pcrlb(m, g, setup, sigma_birth=0.0)
