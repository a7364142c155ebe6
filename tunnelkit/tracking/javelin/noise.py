"""The measurement-noise role of JAVELIN: the covariance of every measured row.

:class:`FixedNoise` is the paper's (one sigma per quantity, section 4.2); :class:`ReportedNoise`
takes each path's covariance as the extraction reports it (ours). Both answer the same two
questions: the (n, 3, 3) covariance of each path's ``(phi, psi, kappa)``
(:meth:`~FixedNoise.covariances`) and the covariance of the TDoA rows ``d_j - d_ref``
(:meth:`~FixedNoise.tdoa_covariance`). The bias-aware tracker's noise, which also splits each
reported covariance into a white and a repeating share, is
:class:`~tunnelkit.tracking.javelin.consider.ConsiderNoise`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..._validate import instance, integer
from .config import JavelinConfig
from .measurement import PathMeasurements

__all__ = ["FixedNoise", "ReportedNoise"]


def check_tdoa_rows(meas, others, reference: int, config) -> tuple[list[int], int]:
    """The checked arguments of a ``tdoa_covariance`` (this module's and
    :class:`~tunnelkit.tracking.javelin.consider.ConsiderNoise`'s): path indices of ``meas``."""
    instance("meas", meas, PathMeasurements)
    instance("config", config, JavelinConfig)
    n = len(meas)
    if isinstance(others, str) or not hasattr(others, "__len__"):
        raise TypeError(f"others: expected a sequence of path indices, got {others!r:.60}")
    rows = [integer("others", j, minimum=0, maximum=n - 1) for j in others]
    return rows, integer("reference", reference, minimum=0, maximum=n - 1)


@dataclass(frozen=True)
class FixedNoise:
    """One sigma per quantity for every path (the paper): ``diag(sigma_phi^2, sigma_psi^2,
    sigma_kappa^2)``, TDoA rows ``sigma_dd^2 I``; with ``correlated_delta_d`` (ours) the TDoAs
    share the reference path's delay, ``sigma_dd^2 (I + 1 1^T) / 2``."""

    correlated_delta_d: bool = False
    #: whether the route must report a covariance per path
    needs_reported: ClassVar[bool] = False

    def __post_init__(self) -> None:
        if not isinstance(self.correlated_delta_d, bool):
            raise TypeError(
                f"correlated_delta_d: expected True or False, got {self.correlated_delta_d!r}"
            )

    def covariances(self, meas: PathMeasurements, config: JavelinConfig) -> np.ndarray:
        """The (n, 3, 3) covariance of each path's ``(phi, psi, kappa)``."""
        instance("meas", meas, PathMeasurements)
        instance("config", config, JavelinConfig)
        var = np.array([config.sigma_phi, config.sigma_psi, config.sigma_kappa]) ** 2
        return np.broadcast_to(np.diag(var), (len(meas), 3, 3))

    def tdoa_covariance(
        self, meas: PathMeasurements, others, reference: int, config: JavelinConfig
    ) -> np.ndarray:
        """Covariance of the TDoA rows ``d_j - d_ref`` for the paths ``others``."""
        others, reference = check_tdoa_rows(meas, others, reference, config)
        nd = len(others)
        s2 = config.sigma_delta_d**2
        if self.correlated_delta_d:
            return 0.5 * s2 * (np.eye(nd) + np.ones((nd, nd)))
        return s2 * np.eye(nd)


@dataclass(frozen=True)
class ReportedNoise:
    """Each path's own covariance as the extraction reports it (ours; ``PathMeasurements.cov``
    and ``sigma_d``): TDoA rows ``diag(s_j^2) + s_ref^2 1 1^T``. An epoch without a reported
    covariance falls back to ``fallback`` (reported as a fault by the tracker). Needs a
    measurement route that reports covariances (``RouteOptions(report_covariance=True)``)."""

    fallback: FixedNoise = field(default_factory=FixedNoise)
    needs_reported: ClassVar[bool] = True

    def __post_init__(self) -> None:
        if not isinstance(self.fallback, FixedNoise):
            raise TypeError(f"fallback: expected a FixedNoise, got {type(self.fallback).__name__}")

    def covariances(self, meas: PathMeasurements, config: JavelinConfig) -> np.ndarray:
        """The reported (n, 3, 3) covariances, or the fallback's."""
        instance("meas", meas, PathMeasurements)
        instance("config", config, JavelinConfig)
        if meas.reported:
            return meas.cov
        return self.fallback.covariances(meas, config)

    def tdoa_covariance(
        self, meas: PathMeasurements, others, reference: int, config: JavelinConfig
    ) -> np.ndarray:
        """``Delta d_j = d_j - d_ref``: ``var = s_j^2 + s_ref^2``, the reference shared."""
        others, reference = check_tdoa_rows(meas, others, reference, config)
        if not meas.reported:
            return self.fallback.tdoa_covariance(meas, others, reference, config)
        return np.diag(meas.sigma_d[others] ** 2) + meas.sigma_d[reference] ** 2
