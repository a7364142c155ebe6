import numpy as np
import pytest
from scipy.stats import chi2

from tunnelkit.tracking.gating import mahalanobis2
from tunnelkit.tracking.javelin import ChiSquareGate
from tunnelkit.tracking.javelin.associate import (
    association_costs,
    global_nearest_neighbour,
    greedy_nearest_neighbour,
)
from tunnelkit.tracking.javelin.measurement import PathMeasurements


def test_threshold_is_chi2_3dof_quantile():
    g = ChiSquareGate(0.99)
    assert g.threshold(3) == pytest.approx(11.3449, abs=1e-4)
    assert g.threshold(2) == pytest.approx(chi2.ppf(0.99, 2))
    np.testing.assert_array_equal(g.accepts([11.0, 11.5, np.nan], 3), [True, False, False])
    with pytest.raises(ValueError, match=r"^probability"):
        ChiSquareGate(1.2)


def test_gate_coverage_matches_p():
    # Monte-Carlo: a correctly modelled 3-D innovation passes the gate with probability p
    rng = np.random.default_rng(0)
    A = rng.standard_normal((3, 3))
    S = A @ A.T + np.eye(3)
    y = rng.multivariate_normal(np.zeros(3), S, size=20000)
    frac = np.mean(ChiSquareGate(0.99).accepts(mahalanobis2(y, S), 3))
    assert abs(frac - 0.99) < 0.003  # 4 sigma of a binomial(20000, 0.99)


def test_costs_match_a_pair_by_pair_loop():
    rng = np.random.default_rng(1)
    L, n, D = 3, 4, 7
    pred = np.column_stack(
        [rng.uniform(-3, 3, L), rng.uniform(-1, 1, L), rng.uniform(5, 50, L), rng.uniform(5, 50, L)]
    )
    J = rng.standard_normal((L, 4, D))
    A = rng.standard_normal((D, D))
    P = A @ A.T
    R3 = np.diag([0.03, 0.03, 2.0])
    meas = PathMeasurements.from_arrays(
        rng.uniform(-3, 3, n), rng.uniform(-1, 1, n), kappa=[10.0, np.nan, 30.0, 20.0]
    )
    c = association_costs(pred, J, P, meas, R3, ChiSquareGate(0.99))
    for i in range(L):
        for j in range(n):
            comp = [0, 1, 2] if np.isfinite(meas.kappa[j]) else [0, 1]
            H = J[i, comp]
            S = H @ P @ H.T + R3[np.ix_(comp, comp)]
            y = meas.triples()[j, comp] - pred[i, comp]
            y[0] = np.angle(np.exp(1j * y[0]))
            assert c.eta2[i, j] == pytest.approx(y @ np.linalg.solve(S, y), rel=1e-9)
    np.testing.assert_array_equal(c.dof, [3, 2, 3, 3])


def _costs(eta2):
    eta2 = np.asarray(eta2, float)
    from tunnelkit.tracking.javelin.associate import AssociationCosts

    return AssociationCosts(
        eta2, np.full(eta2.shape[1], 3), eta2 < 11.34, np.full(eta2.shape[1], 11.34)
    )


def test_greedy_and_global_nearest_neighbour_differ_where_they_should():
    # greedy takes (0, 0) = 1 first and leaves track 1 only the ungated path 1;
    # the global assignment pairs (0, 1) + (1, 0) with total 2 + 3 = 5 and keeps both tracks
    eta2 = [[1.0, 2.0], [3.0, 50.0]]
    assert greedy_nearest_neighbour(_costs(eta2)) == [(0, 0)]
    assert global_nearest_neighbour(_costs(eta2)) == [(0, 1), (1, 0)]
    # nothing in the gate: no pair
    assert (
        greedy_nearest_neighbour(_costs([[20.0]]))
        == []
        == global_nearest_neighbour(_costs([[20.0]]))
    )
    # each path and each track at most once
    rng = np.random.default_rng(2)
    for _ in range(50):
        e = rng.uniform(0, 15, (4, 5))
        for f in (greedy_nearest_neighbour, global_nearest_neighbour):
            pairs = f(_costs(e))
            assert len({i for i, _ in pairs}) == len(pairs) == len({j for _, j in pairs})
            assert all(e[i, j] < 11.34 for i, j in pairs)
        g = global_nearest_neighbour(_costs(e))
        assert len(g) >= len(greedy_nearest_neighbour(_costs(e)))


def test_association_gate_matches_chi_square_gate_accepts():
    """association_costs gates with the same quantiles as ChiSquareGate.accepts (3 and 2 dof)."""
    from tunnelkit.tracking.javelin.associate import association_costs
    from tunnelkit.tracking.javelin.measurement import PathMeasurements, track_model

    x = np.array([-20.0, 1.5, 1.0, -4.5, 1.0])
    pred, J = track_model(x)
    rng = np.random.default_rng(4)
    n = 6
    meas = PathMeasurements.from_arrays(
        pred[rng.integers(0, 2, n), 0] + 0.05 * rng.standard_normal(n),
        pred[rng.integers(0, 2, n), 1] + 0.05 * rng.standard_normal(n),
        np.where(np.arange(n) % 2, 20.0 + rng.standard_normal(n), np.nan),
    )
    gate = ChiSquareGate(0.99)
    R3 = np.diag([0.03**2, 0.03**2, 1.5**2])
    c = association_costs(pred, J, np.eye(5), meas, R3, gate)
    np.testing.assert_array_equal(c.gated, gate.accepts(c.eta2, c.dof[None, :]))
    assert set(c.dof.tolist()) == {2, 3}
