"""The 95 % intervals of the design's pooled error quantile over manufactured units: Woodruff's
with one cluster per unit (:func:`cluster_quantile_ci`, the report's) and the percentile bootstrap
over runs (:func:`bootstrap_quantile_ci`, kept for the comparison). Information beside the
verdict, which the unit yield's Wilson interval decides (:mod:`tunnelkit.design.units`). And the
RMSE's interval over units (:func:`rmse_ci`) and the ratio of two RMSEs over the same units
(:func:`paired_rmse_ratio`): an array against another on the same drives, or dead reckoning
against the tracker (the radio's gain).

How it works: docs/internals/design.md.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from .._checks import real_array
from .._validate import integer, probability, rng_or_error
from ..budget import check_elements

__all__ = ["bootstrap_quantile_ci", "cluster_quantile_ci", "paired_rmse_ratio", "rmse_ci"]


def _error_rows(errors, expected: str) -> np.ndarray:
    """``errors`` as a 2-D float array of rows (``expected`` names its shape in the error), no
    value negative, a non-finite error (no estimate) counted as infinite."""
    real_array("errors", errors)
    e = np.asarray(errors, float)
    if e.ndim != 2 or not e.size:
        raise ValueError(f"errors: expected {expected}, got shape {e.shape}")
    if np.any(e < 0):
        raise ValueError("errors: a position error is not negative")
    return np.where(np.isfinite(e), e, np.inf)


def cluster_quantile_ci(errors, share: float, *, level: float = 0.95) -> list[float]:
    """Woodruff's ``level`` interval of :func:`~tunnelkit.design.verdict.share_quantile` of ``errors`` (units, n), one row
    per cluster (a manufactured unit: its drives share the calibration draw, and one drive's
    epochs are correlated), deterministic.

    The pooled quantile ``q`` is where the pooled empirical CDF reaches ``share``; the CDF's
    standard error at ``q`` is that of a mean over clusters, ``se = sd(y_u) / sqrt(U)`` with
    ``y_u`` the share of unit ``u``'s values <= ``q`` (the clusters are the independent
    draws); the interval is the pooled quantiles at ``share -+ t se`` (Student ``t``, ``U - 1``
    degrees of freedom), the bracketing order statistics (Woodruff 1952, the survey-sampling
    interval of a quantile under cluster sampling). On 20 units of synthetic clustered errors it
    covers 94-95 % where the percentile bootstrap over units covers 80-91 %; on the design's
    Monte-Carlo (8x8 and 16x16, the calibrated default and 2 deg of phase error, 20 units) it
    covered 90-93 % on disjoint blocks (60 to 180 per cell), 93-98 % on blocks of 20-80 units
    drawn from one long reference (``benchmarks/bench_design_units.py``, part 2: docs/results/design-units.md).
    Information beside the verdict (the unit yield's Wilson interval decides). One unit gives the
    degenerate interval ``[q, q]``."""
    share = probability("share", share, open_interval=False)
    level = probability("level", level)
    e = _error_rows(errors, "(units, n) with units, n >= 1")
    units = e.shape[0]
    q = float(np.quantile(e, share, method="inverted_cdf"))
    if units < 2:
        return [q, q]
    y = (e <= q).mean(axis=1)
    half = stats.t.ppf((1 + level) / 2, units - 1) * y.std(ddof=1) / np.sqrt(units)
    lo, hi = max(share - half, 0.0), min(share + half, 1.0)
    flat = e.ravel()
    out = [float(np.quantile(flat, lo, method="inverted_cdf")) if lo > 0 else float(flat.min())]
    out.append(float(np.quantile(flat, hi, method="inverted_cdf")))
    return out


def bootstrap_quantile_ci(
    errors, share: float, rng: np.random.Generator, *, n_boot: int = 2000, level: float = 0.95
) -> list[float]:
    """Percentile-bootstrap ``level`` interval of :func:`~tunnelkit.design.verdict.share_quantile` of ``errors``
    (runs, T): runs resampled with replacement (``n_boot`` resamples from ``rng``), the pooled
    quantile of each resample, and the ``(1 -+ level) / 2`` quantiles of those. One run gives
    the degenerate interval ``[q, q]`` (callers warn; :func:`~tunnelkit.design.verdict.judge` never decides on it)."""
    rng = rng_or_error("rng", rng)
    share = probability("share", share, open_interval=False)
    level = probability("level", level)
    n_boot = integer("n_boot", n_boot, minimum=1)
    e = _error_rows(errors, "(runs, T) with runs, T >= 1")
    runs, T = e.shape
    check_elements("n_boot", n_boot * (runs + 1), what=f"{n_boot} resamples of {runs} runs")
    draws = rng.integers(0, runs, size=(n_boot, runs))
    qs = np.empty(n_boot)
    step = max(1, 2_000_000 // (runs * T))  # bounded memory per chunk
    for i in range(0, n_boot, step):
        block = e[draws[i : i + step]].reshape(-1, runs * T)
        qs[i : i + step] = np.quantile(block, share, axis=1, method="inverted_cdf")
    p = [(1 - level) / 2, (1 + level) / 2]
    if np.all(np.isfinite(qs)):
        lo, hi = np.quantile(qs, p, method="linear")
    else:  # inf - inf has no interpolation: the bracketing order statistics
        lo, hi = np.quantile(qs, p[0], method="lower"), np.quantile(qs, p[1], method="higher")
    return [float(lo), float(hi)]


def rmse_ci(unit_rmse, *, level: float = 0.95) -> list[float] | None:
    """The ``level`` interval of the RMSE pooled over units, ``sqrt(mean(unit_rmse**2))``, from
    each unit's RMSE (a unit's drives share its calibration: the units are the independent
    draws): the delta method's on the log with Student's t over units, as
    :func:`paired_rmse_ratio` with nothing in the denominator. On the design's Monte-Carlo it
    covered 91-96 % at 4-12 units where the percentile bootstrap over units it replaced covered
    82-87 % (docs/results/design-units.md). ``None`` with fewer than two units or a unit not
    finite (a lost drive: the RMSE is infinite)."""
    level = probability("level", level)
    a = _unit_rmse("unit_rmse", unit_rmse)
    if not a.size:
        raise ValueError("unit_rmse: expected one RMSE per unit, got none")
    m = np.mean(a**2)
    if a.size < 2 or not (np.all(np.isfinite(a)) and m > 0):
        return None
    return _log_t(float(np.sqrt(m)), 0.5 * a**2 / m, level)


def _unit_rmse(name: str, values) -> np.ndarray:
    """``values`` as a 1-D array of per-unit RMSEs: >= 0, +inf allowed (a lost drive), no NaN."""
    x = np.asarray(real_array(name, values, ndim=1), float)
    if not np.all(x >= 0):  # NaN fails too: a lost drive's RMSE is +inf, never NaN
        raise ValueError(f"{name}: an RMSE is >= 0 (+inf for a lost drive), got {x.min()}")
    return x


def _log_t(value: float, z: np.ndarray, level: float) -> list[float]:
    """``value * exp(+-t se)``: ``se = sd(z) / sqrt(U)`` the standard error of the log of
    ``value`` from the units' influences ``z``, Student's t with ``U - 1`` degrees of freedom."""
    half = stats.t.ppf((1 + level) / 2, z.size - 1) * np.std(z, ddof=1) / np.sqrt(z.size)
    return [float(value * np.exp(-half)), float(value * np.exp(half))]


def paired_rmse_ratio(num, den, *, level: float = 0.95) -> tuple[float, list[float] | None]:
    """The ratio of two RMSEs pooled over the same units, ``sqrt(mean(num**2) / mean(den**2))``,
    and its ``level`` interval; ``num`` and ``den`` are per-unit RMSEs (one value per unit, unit
    ``u`` of both the same drives: an array against another in one sweep, or dead reckoning
    against the tracker). Pairing removes what the units share (the drive, the odometry).

    The interval is the delta method's on the log ratio with Student's t over units: with
    ``M = mean(x**2)`` each unit's influence is ``z_u = (num_u**2 / M_num - den_u**2 / M_den) / 2``
    and ``se = sd(z) / sqrt(U)``, ``ratio * exp(+-t_{U-1} se)``: on the design's Monte-Carlo
    93-96 % for the radio's gain, 81-89 % for an array over one whose units are heavy-tailed
    (docs/results/design-units.md): approximate there. ``None`` for the interval with fewer than
    two units or a unit not finite (a lost drive); then the ratio is still returned (``inf``
    when only ``den`` is all zero, ``nan`` when both are or both are infinite)."""
    level = probability("level", level)
    a, b = _unit_rmse("num", num), _unit_rmse("den", den)
    if a.shape != b.shape or not a.size:
        raise ValueError(f"num, den: expected one RMSE per unit in both, got {a.shape}, {b.shape}")
    ma, mb = np.mean(a**2), np.mean(b**2)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = float(np.sqrt(ma / mb)) if mb > 0 else (np.inf if ma > 0 else np.nan)
    if a.size < 2 or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b)) and ma > 0 and mb > 0):
        return ratio, None
    return ratio, _log_t(ratio, 0.5 * (a**2 / ma - b**2 / mb), level)
