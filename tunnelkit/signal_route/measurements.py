"""Algorithm 1's measurements of one epoch in the world frame (:func:`measurements_from_estimates`,
a :class:`~tunnelkit.tracking.javelin.PathMeasurements`) and the epoch record (:class:`Epoch`);
the covariance the extraction reports: :mod:`tunnelkit.signal_route.covariance`."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .._physical import speeds
from .._validate import boolean, instance, real, record, sequence
from ..arrays import ArrayGeometry
from ..channel import ChannelSnapshot, SRSConfig
from ..evaluation import match_paths
from ..propagation import SECOND_ORDER
from ..tracking.measurements import PathMeasurements

__all__ = [
    "Epoch",
    "measure_epoch",
    "measurements_from_estimates",
]


_EPOCH_SHAPES = {"ue": (3,), "velocity": (3,), "truth_index": (None,)}  # Epoch's fields


@dataclass(frozen=True)
class Epoch:
    """Everything about one simulated epoch: the truth (``ue``, ``velocity``, ``paths``), the
    channel tensor (``snapshot``), the raw extraction output (``estimates``, a
    :class:`tunnelkit.extraction.PathEstimates`: every path found, in the array's frame, before
    Algorithm 1) and the measurements (a :class:`~tunnelkit.tracking.javelin.PathMeasurements`:
    the kept paths in the world frame, what a tracker takes) with ``truth_index`` matching them
    to the truth. One epoch of one array; a whole drive's measurements are a
    :class:`tunnelkit.simulation.DriveData`."""

    k: int
    t: float
    ue: np.ndarray
    velocity: np.ndarray
    array: ArrayGeometry = field(repr=False)
    paths: list = field(repr=False)
    snapshot: ChannelSnapshot = field(repr=False)
    estimates: object = field(repr=False)
    measurements: PathMeasurements
    truth_index: np.ndarray  # for each kept measurement, the index of the true path (-1 if none)
    #: the re-judged fit test (:func:`tunnelkit.signal_route.judging.rejudge`), None if not re-judged
    rejudged: dict | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        from ..extraction.estimates import PathEstimates  # a route that only traces loads none

        record(self, shapes=_EPOCH_SHAPES, nonnegative=("k", "t"), skip=("rejudged",))
        speeds("velocity", self.velocity)
        instance("estimates", self.estimates, PathEstimates)
        if self.rejudged is not None:
            instance("rejudged", self.rejudged, dict)

    @property
    def fit_ok(self) -> bool | None:
        """The verdict on the extraction's fit: the extraction's own (``estimates.fit_ok``,
        None for a route that does not test its fit) unless the route re-judged it against noise
        plus its impairment power (``rejudged["passed"]``)."""
        if self.rejudged is not None:
            return bool(self.rejudged["passed"])
        return getattr(self.estimates, "fit_ok", None)

    def with_estimates(self, est, config: SRSConfig | None = None, *, min_d: float = 0.0):
        """This epoch with other estimates of the same tensor (another extraction route): Algorithm
        1, the world frame and the match to the truth redone (:func:`measurements_from_estimates`)."""
        meas, truth = measure_epoch(est, self.array, self.paths, self.snapshot, config, min_d)
        return replace(self, estimates=est, measurements=meas, truth_index=truth)


def measure_epoch(est, array, paths, snap, config, min_d, judged=True):
    """Measurements of ``est`` (Algorithm 1, world frame) and their match to the true paths; the
    estimates matched to a second-order path (a nuisance path the model carries,
    :attr:`RouteOptions.second_order`) are left out of the measurements. ``judged`` as in
    :func:`~tunnelkit.signal_route.covariance.reported_covariance`."""
    paths = sequence("paths", paths, empty=True)  # empty: no true path recorded
    instance("snap", snap, ChannelSnapshot)
    meas = measurements_from_estimates(est, array, config, min_d=min_d, judged=judged)
    truth = match_paths(meas.d, meas.direction, paths, clock_bias=snap.clock_bias)
    nuisance = [i for i, p in enumerate(paths) if p.kind == SECOND_ORDER]
    if nuisance and len(meas):
        rows = np.flatnonzero(~np.isin(truth, nuisance))
        meas, truth = meas.subset(rows), truth[rows]
    return meas, truth


def measurements_from_estimates(
    est,
    array: ArrayGeometry,
    config: SRSConfig | None = None,
    *,
    min_d: float = 0.0,
    judged: bool = True,
) -> PathMeasurements:
    """Apply Algorithm 1's checks to raw estimates (``min_d``: see
    :func:`tunnelkit.extraction.algorithm1`) and express them in the world frame, seen from the
    array's reference antenna (``origin``; ``source`` the kept rows of ``est``); with
    ``config``, also the covariance the extraction reports
    (:func:`~tunnelkit.signal_route.covariance.reported_covariance`, with
    ``judged``: False for a fit the route re-judged and passed)."""
    from ..extraction import algorithm1
    from ..extraction.estimates import PathEstimates

    instance("est", est, PathEstimates)
    instance("array", array, ArrayGeometry)
    if config is not None:
        instance("config", config, SRSConfig)
    min_d = real("min_d", min_d)  # -c b_max on a route with a clock-bias support
    judged = boolean("judged", judged)
    keep = algorithm1(est, min_d)
    u = array.dir_to_world(est.direction[keep]) if keep.size else np.zeros((0, 3))
    phi = np.arctan2(u[:, 1], u[:, 0])
    psi = np.arctan2(u[:, 2], np.hypot(u[:, 0], u[:, 1]))
    d = est.d[keep]
    cov = sigma_d = None
    if config is not None and keep.size:
        from .covariance import reported_covariance

        cov, sigma_d = reported_covariance(est, keep, array, config, judged=judged)
    return PathMeasurements(
        phi, psi, est.kappa[keep], d, est.v[keep], keep, cov, sigma_d, origin=array.origin.copy()
    )
