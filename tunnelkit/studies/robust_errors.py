"""Errors the tracker can trust: robust statistics of the ML route's per-path errors on the
ray-traced channel, and a design told them.

The traced design (:func:`~tunnelkit.studies.traced.traced_design`) is told the **RMS** of the
extraction's errors over every matched path. On the ray-traced channel those errors are heavy
tailed: most paths sit within a degree or two and a few decimetres, a few (the road bounce taken
from a second-order cluster, a ceiling path cut from part of the aperture) are off by ten degrees
or metres, and the RMS is set by those few. A tracker told the RMS trusts every measurement as
little as the worst, and its gate (which scales with the told sigmas) passes the gross ones.

Here the same samples (:func:`~tunnelkit.simulation.analysis.error_samples`) are summarised by
robust statistics instead:

* the **robust sigma** of each quantity, ``1.4826 MAD`` about its median (the standard deviation
  of a Gaussian core, unmoved by a minority of gross errors);
* the **gross errors**, counted apart: a sample further than ``threshold`` robust sigmas from
  the median (default 3, where a Gaussian core leaves 0.27 %);
* the **median** (a bias the tracker is not told about) beside them.

:func:`robust_design` is :func:`~tunnelkit.tracking.javelin.designs.ours_ml` told the robust
sigmas of the pooled ``"all"`` row (inflated, like the traced design, by the errors' lag-1
correlation from epoch to epoch), so that its association gate, at the same probability, rejects
what lies in the tail. ``benchmarks/bench_rt_robust.py`` measures both designs against dead
reckoning on the traced drives (``docs/results/traced-robust.md``).
"""

from __future__ import annotations

import numpy as np

from .._validate import positive
from ..simulation.analysis import ERROR_QUANTITIES
from ..tracking.javelin import designs
from ..tracking.javelin.measured import design_from_errors

__all__ = ["MAD_TO_SIGMA", "robust_design", "robust_rows"]

#: a Gaussian's standard deviation over its median absolute deviation
MAD_TO_SIGMA = 1.4826

_UNITS = {"phi": "deg", "psi": "deg", "kappa": "m", "delta_d": "m"}


def _check_samples(samples) -> dict:
    if not isinstance(samples, dict) or not samples:
        raise TypeError("samples: expected the dict of error_samples (kind -> quantities)")
    for kind, a in samples.items():
        if not isinstance(a, dict) or any(q not in a for q in ERROR_QUANTITIES):
            raise ValueError(f"samples[{kind!r}]: expected the quantities {ERROR_QUANTITIES}")
        for q in ERROR_QUANTITIES:
            x = np.asarray(a[q], float)
            if x.ndim != 1 or not np.all(np.isfinite(x)):
                raise ValueError(f"samples[{kind!r}][{q!r}]: expected finite 1-D errors")
    return samples


def _summary(x: np.ndarray, threshold: float) -> tuple:
    """(median, robust sigma, gross count, RMS of the rest) of one quantity's errors."""
    if not x.size:
        return None, None, 0, None
    med = float(np.median(x))
    sig = MAD_TO_SIGMA * float(np.median(np.abs(x - med)))
    gross = np.abs(x - med) > threshold * sig if sig > 0 else np.zeros(x.size, bool)
    rest = x[~gross]
    return med, sig, int(gross.sum()), float(np.sqrt(np.mean(rest**2))) if rest.size else None


def robust_rows(samples: dict, *, threshold: float = 3.0) -> tuple[list[str], list[list], list]:
    """Robust summaries of ``samples`` (:func:`~tunnelkit.simulation.analysis.error_samples`):
    returns ``(columns, rows, sigma_rows)``. ``rows``: per kind and a last ``"all"`` row pooling
    every kind, for each quantity its median, robust sigma (``1.4826 MAD``), the number of gross
    errors (further than ``threshold`` robust sigmas from the median) and the RMS of the others.
    ``sigma_rows``: the table :func:`~tunnelkit.tracking.javelin.measured.design_from_errors`
    reads (the columns of :func:`~tunnelkit.simulation.analysis.extraction_errors`), the robust
    sigma in place of the RMS."""
    samples = _check_samples(samples)
    threshold = positive("threshold", threshold)
    pooled = {
        q: np.concatenate([np.asarray(a[q], float) for a in samples.values()])
        for q in ERROR_QUANTITIES
    }
    pooled["far"] = sum(int(a.get("far", 0)) for a in samples.values())
    cols = ["path", "matched"]
    for q in ERROR_QUANTITIES:
        u = _UNITS[q]
        cols += [
            f"{q} median [{u}]",
            f"{q} robust sigma [{u}]",
            f"{q} gross",
            f"{q} RMS rest [{u}]",
        ]
    rows, sigma_rows = [], []
    for kind, a in [*samples.items(), ("all", pooled)]:
        stats = [_summary(np.asarray(a[q], float), threshold) for q in ERROR_QUANTITIES]
        n = len(a["phi"])
        rows.append([kind, n, *(v for st in stats for v in st)])
        sigma_rows.append([kind, n, *(st[1] for st in stats), int(a.get("far", 0))])
    return cols, rows, sigma_rows


def robust_design(samples: dict, *, correlation: dict | None = None, threshold: float = 3.0):
    """:func:`~tunnelkit.tracking.javelin.designs.ours_ml` told the robust sigmas of ``samples``
    (the ``"all"`` row of :func:`robust_rows`), each inflated by ``correlation``
    (:func:`~tunnelkit.simulation.analysis.error_correlations`) as the traced design is."""
    _, _, sigma_rows = robust_rows(samples, threshold=threshold)
    return design_from_errors(sigma_rows, base=designs.ours_ml(), correlation=correlation)
