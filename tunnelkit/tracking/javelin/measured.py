"""A JAVELIN design whose measurement noise is a measured extraction error
(:func:`design_from_errors`): the sigmas from a table of :func:`tunnelkit.simulation.extraction_errors`,
each inflated to the long-run spread its lag-1 error correlation leaves (:data:`CORRELATED`)."""

from __future__ import annotations

import numpy as np

from ..._validate import real, sequence
from .designs import ours_coherent
from .roles import JavelinDesign

__all__ = ["CORRELATED", "MAX_CORRELATION", "design_from_errors"]


#: the largest lag-1 correlation :func:`design_from_errors` inflates by (a larger one is an
#: error that hardly changes along the drive: a bias, which no white noise describes)
MAX_CORRELATION = 0.9
#: the quantities a ``correlation`` may name, in the order of the sigmas
CORRELATED = ("phi", "psi", "kappa", "delta_d")


def _inflation(correlation) -> np.ndarray:
    """``sqrt((1 + r) / (1 - r))`` per quantity of :data:`CORRELATED` (1 where not given), ``r``
    clipped to ``[0, MAX_CORRELATION]``."""
    f = np.ones(len(CORRELATED))
    if correlation is None:
        return f
    if not isinstance(correlation, dict):
        raise TypeError(f"correlation: expected a dict quantity -> r, got {correlation!r:.60}")
    unknown = set(correlation) - set(CORRELATED)
    if unknown:
        raise ValueError(f"correlation: unknown quantities {sorted(unknown)}; known {CORRELATED}")
    for i, q in enumerate(CORRELATED):
        r = correlation.get(q)
        r = r.get("r") if isinstance(r, dict) else r
        if r is None or (isinstance(r, float) and np.isnan(r)):
            continue
        r = float(real(f"correlation[{q!r}]", r))
        if not -1.0 < r < 1.0:
            raise ValueError(f"correlation[{q!r}]: a correlation lies in (-1, 1), got {r}")
        r = min(max(r, 0.0), MAX_CORRELATION)
        f[i] = np.sqrt((1.0 + r) / (1.0 - r))
    return f


def design_from_errors(
    rows: list[list],
    base: JavelinDesign | None = None,
    *,
    correlation: dict | None = None,
) -> JavelinDesign:
    """A design whose measurement noise is the measured extraction error: ``sigma_phi``,
    ``sigma_psi``, ``sigma_kappa``, ``sigma_delta_d`` from the ``"all"`` row of
    :func:`tunnelkit.simulation.extraction_errors`; every role and other number from ``base``
    (default :func:`~tunnelkit.tracking.javelin.designs.ours_coherent`). ``correlation``: each quantity's lag-1 error correlation ``r``
    (:func:`tunnelkit.simulation.error_correlations`, ``{"phi", "psi", "kappa", "delta_d"}`` to
    ``r`` or to ``{"r": r, ...}``): its sigma times ``sqrt((1 + r) / (1 - r))``, the long-run
    standard deviation of an AR(1) error (what averaging over epochs leaves of it; ``r`` clipped
    to ``[0, MAX_CORRELATION]``: a white model for a negative one, and a bias is not AR(1))."""
    base = ours_coherent() if base is None else base
    if not isinstance(base, JavelinDesign):
        raise TypeError(f"base: expected a JavelinDesign, got {type(base).__name__}")
    table = {r[0]: r for r in sequence("rows", rows)}
    pooled = table.get("all")
    if pooled is None:
        raise ValueError("rows: expected the table of extraction_errors (an 'all' row)")
    f = _inflation(correlation)
    sig = [float(np.radians(pooled[2])), float(np.radians(pooled[3])), *map(float, pooled[4:6])]
    sig = [float(v * fi) for v, fi in zip(sig, f, strict=True)]
    out = base.with_(sigma_phi=sig[0], sigma_psi=sig[1], sigma_kappa=sig[2], sigma_delta_d=sig[3])
    return out
