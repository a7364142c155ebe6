"""The lag-1 correlation of the errors the tracker is fed (``simulation.error_correlations``) and
the long-run inflation of the sigmas it sets (``design_from_errors(correlation=)``), each checked
on drives whose errors are drawn as AR(1) processes of a known coefficient."""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit.simulation.analysis import error_correlations, extraction_errors
from tunnelkit.simulation.drives import DriveData
from tunnelkit.tracking.javelin import PathMeasurements, designs
from tunnelkit.tracking.javelin.measured import design_from_errors


def _ar1(rng, r, sigma, n):
    e = np.empty(n)
    e[0] = rng.standard_normal() * sigma
    w = rng.standard_normal(n) * sigma * np.sqrt(1 - r**2)
    for k in range(1, n):
        e[k] = r * e[k - 1] + w[k]
    return e


def _drive(r, seed=0, T=1500):
    """A UE along x at 1 m height, the array at the origin 1 m up; the LoS and the ceiling
    (z = 10 m) reflection (2.6 m or more longer) measured with AR(1) errors of coefficient ``r``
    in every quantity."""
    rng = np.random.default_rng(seed)
    bs = np.array([0.0, 0.0, 1.0])
    x = np.linspace(10.0, 60.0, T)
    ue = np.column_stack([x, np.full(T, 1.0), np.full(T, 1.0)])
    vue = ue.copy()
    vue[:, 2] = 20.0 - ue[:, 2]  # the mirror image in z = 10
    sig = {"phi": 0.02, "psi": 0.03, "kappa": 4.0, "d": 0.1}
    err = {(p, q): _ar1(rng, r, s, T) for p in (0, 1) for q, s in sig.items()}
    clock = rng.normal(0.0, 5.0, T)
    epochs, sources = [], []
    for k in range(T):
        src = np.stack([ue[k], vue[k]])
        q = src - bs
        rr = np.linalg.norm(q, axis=1)
        phi = np.arctan2(q[:, 1], q[:, 0]) + [err[(p, "phi")][k] for p in (0, 1)]
        psi = np.arctan2(q[:, 2], np.hypot(q[:, 0], q[:, 1])) + [err[(p, "psi")][k] for p in (0, 1)]
        kap = rr + [err[(p, "kappa")][k] for p in (0, 1)]
        d = rr + [err[(p, "d")][k] for p in (0, 1)] + clock[k] + 20.0
        epochs.append(PathMeasurements.from_arrays(phi, psi, kap, d, np.zeros(2), warn=False))
        sources.append(src)
    return DriveData(
        scenario="synthetic", condition=None, t=np.arange(T) * 0.1, truth=ue,
        velocity=np.tile([10.0, 0.0, 0.0], (T, 1)), speed=np.full(T, 10.0),
        heading=np.zeros(T), epochs=epochs, los=np.ones(T, bool), n_true=np.full(T, 2),
        base_station=bs, truth_index=[np.arange(2)] * T, kinds=[["los", "ceiling"]] * T,
        sources=sources, extraction="ml",
    )  # fmt: skip


@pytest.mark.parametrize("r", [0.0, 0.6])
def test_the_lag_one_correlation_of_ar1_errors_is_recovered(r):
    out = error_correlations([_drive(r, seed=1), _drive(r, seed=2)])
    for q in ("phi", "psi", "kappa"):
        assert out[q]["pairs"] == 2 * 2 * 1499  # both paths, consecutive epochs
        assert out[q]["r"] == pytest.approx(r, abs=0.05)
    # the TDoA of the later path against the earlier (LoS) one: e_1 - e_0, the same AR(1)
    assert out["delta_d"]["pairs"] == 2 * 1499
    assert out["delta_d"]["r"] == pytest.approx(r, abs=0.06)
    # the RMS of the same drives' errors: what the sigmas are
    _, rows = extraction_errors([_drive(r, seed=1)])
    los = {row[0]: row for row in rows}["los"]
    assert los[2] == pytest.approx(np.degrees(0.02), rel=0.15)
    assert los[4] == pytest.approx(4.0, rel=0.15)


def test_a_path_is_not_paired_with_another_one():
    """Errors of opposite sign on the two paths at every epoch: pairing across paths would read
    a negative correlation; each path with itself reads +1."""
    d = _drive(0.0, seed=3, T=50)
    for k, m in enumerate(d.epochs):
        src = d.sources[k] - d.base_station
        rr = np.linalg.norm(src, axis=1)
        m.kappa[:] = rr + np.array([1.0, -1.0])
    assert error_correlations([d])["kappa"]["r"] == pytest.approx(1.0)


ROWS = [["los", 80, 2.0, 2.5, 40.0, 0.2, 3], ["all", 164, 9.0, 8.0, 33.0, 1.1, 82]]


def test_the_sigmas_take_the_long_run_inflation():
    base = designs.ours_ml()
    white = design_from_errors(ROWS, base=base).config
    corr = {"phi": 0.6, "psi": {"r": -0.2, "pairs": 10}, "kappa": 0.99, "delta_d": float("nan")}
    got = design_from_errors(ROWS, base=base, correlation=corr).config
    assert got.sigma_phi == pytest.approx(white.sigma_phi * 2.0)  # sqrt(1.6 / 0.4)
    assert got.sigma_psi == pytest.approx(white.sigma_psi)  # negative: white
    assert got.sigma_kappa == pytest.approx(white.sigma_kappa * np.sqrt(1.9 / 0.1))  # clipped
    assert got.sigma_delta_d == pytest.approx(white.sigma_delta_d)  # NaN: not measured


@pytest.mark.parametrize(
    "corr, exc, match",
    [
        ([0.5], TypeError, "correlation"),
        ({"theta": 0.5}, ValueError, "unknown"),
        ({"phi": 1.0}, ValueError, r"correlation\['phi'\]"),
        ({"phi": "high"}, TypeError, r"correlation\['phi'\]"),
    ],
)
def test_bad_correlations_are_named(corr, exc, match):
    with pytest.raises(exc, match=match):
        design_from_errors(ROWS, base=designs.ours_ml(), correlation=corr)
