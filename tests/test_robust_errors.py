"""Robust summaries of the extraction's errors (tunnelkit.studies.robust_errors) against brute
force on samples with a known Gaussian core and known gross errors."""

from __future__ import annotations

import numpy as np
import pytest

from tunnelkit.studies.robust_errors import MAD_TO_SIGMA, robust_design, robust_rows
from tunnelkit.tracking.javelin import designs
from tunnelkit.tracking.javelin.measured import design_from_errors

QUANTITIES = ("phi", "psi", "kappa", "delta_d")


def _samples(rng, n, sigma, gross_share, gross_size, bias=0.0):
    x = bias + sigma * rng.standard_normal(n)
    k = round(gross_share * n)
    x[:k] = bias + gross_size * rng.choice([-1.0, 1.0], k)
    return rng.permutation(x)


def test_robust_sigma_sees_the_core_and_counts_the_gross_apart():
    rng = np.random.default_rng(20261205)
    sig = {"phi": 1.5, "psi": 2.0, "kappa": 20.0, "delta_d": 0.2}
    big = {"phi": 15.0, "psi": 20.0, "kappa": 300.0, "delta_d": 2.0}
    samples = {
        "los": {q: _samples(rng, 4000, sig[q], 0.03, big[q], bias=0.1 * sig[q]) for q in QUANTITIES}
        | {"far": 3},
        "road": {q: _samples(rng, 2000, 2 * sig[q], 0.2, 2 * big[q]) for q in QUANTITIES}
        | {"far": 5},
    }
    cols, rows, sigma_rows = robust_rows(samples)
    assert [r[0] for r in rows] == ["los", "road", "all"] and len(cols) == 2 + 4 * 4
    los = dict(zip(cols, rows[0], strict=True))
    for q in QUANTITIES:
        # the core's sigma within 12 % despite 3 % gross errors (the MAD's bias there about 4 %,
        # its sampling error about 2 % at 4,000 samples);
        # the RMS about twice it
        assert (
            abs(los[f"{q} robust sigma [{'deg' if q in ('phi', 'psi') else 'm'}]"] / sig[q] - 1)
            < 0.12
        )
        x = samples["los"][q]
        assert np.sqrt(np.mean(x**2)) > 1.8 * sig[q]
        # gross: the 3 % planted plus the core's few beyond three (slightly inflated) sigmas
        n_gross = los[f"{q} gross"]
        assert 0.029 * 4000 < n_gross < 0.035 * 4000, (q, n_gross)
    # brute force of one cell: median, MAD, the rest's RMS
    x = samples["road"]["kappa"]
    med = np.median(x)
    s = MAD_TO_SIGMA * np.median(np.abs(x - med))
    rest = x[np.abs(x - med) <= 3 * s]
    road = dict(zip(cols, rows[1], strict=True))
    assert road["kappa median [m]"] == pytest.approx(med)
    assert road["kappa robust sigma [m]"] == pytest.approx(s)
    assert road["kappa RMS rest [m]"] == pytest.approx(np.sqrt(np.mean(rest**2)))
    # the pooled row pools the samples; the sigma rows feed the design
    allx = np.concatenate([samples[k]["psi"] for k in ("los", "road")])
    med_all = np.median(allx)
    assert sigma_rows[-1][0] == "all" and sigma_rows[-1][1] == 6000 and sigma_rows[-1][-1] == 8
    assert sigma_rows[-1][3] == pytest.approx(MAD_TO_SIGMA * np.median(np.abs(allx - med_all)))
    d = robust_design(samples)
    expect = design_from_errors(sigma_rows, base=designs.ours_ml())
    assert d.config.sigma_phi == pytest.approx(expect.config.sigma_phi)
    assert d.config.sigma_phi == pytest.approx(np.radians(sigma_rows[-1][2]))
    assert (
        d.config.sigma_phi
        < design_from_errors(
            [
                [
                    "all",
                    6000,
                    *(
                        np.sqrt(np.mean(np.concatenate([samples[k][q] for k in samples]) ** 2))
                        for q in QUANTITIES
                    ),
                    8,
                ]
            ],
            base=designs.ours_ml(),
        ).config.sigma_phi
    )


def test_bad_samples_are_refused():
    ok = {q: np.zeros(3) for q in QUANTITIES}
    with pytest.raises(TypeError, match="samples"):
        robust_rows([])
    with pytest.raises(ValueError, match="samples\\['los'\\]"):
        robust_rows({"los": {"phi": np.zeros(3)}})
    with pytest.raises(ValueError, match="finite"):
        robust_rows({"los": {**ok, "psi": np.array([0.0, np.nan])}})
    with pytest.raises(ValueError, match="threshold"):
        robust_rows({"los": ok}, threshold=-1.0)
