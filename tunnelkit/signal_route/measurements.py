"""Algorithm 1's measurements of one epoch in the world frame (:class:`RouteMeasurements`), the
epoch record (:class:`Epoch`) and the covariance the extraction reports
(:func:`reported_covariance`)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .._checks import indices
from .._physical import speeds
from .._validate import boolean, instance, real, record, sequence
from ..arrays import ArrayGeometry
from ..channel import ChannelSnapshot, SRSConfig
from ..evaluation import match_paths

__all__ = [
    "Epoch",
    "RouteMeasurements",
    "measure_epoch",
    "measurements_from_estimates",
    "reported_covariance",
    "restrict_rows",
]


_SHAPES = dict.fromkeys("phi psi kappa near_field d delta_d v alpha index sigma_d".split(), ("K",))
_SHAPES.update(
    origin=(3,), direction=("K", 3), cov=("K", 3, 3), bias_cov=("K", 4, 4)
)  # RouteMeasurements' fields
_EPOCH_SHAPES = {"ue": (3,), "velocity": (3,), "truth_index": (None,)}  # Epoch's fields


@dataclass(frozen=True)
class RouteMeasurements:
    """Algorithm 1 output for one array, angles in the **world** frame, seen from ``origin``.

    Per kept path (sorted by ``d``; path 0 is the earliest arrival): ``phi``/``psi`` azimuth and
    elevation (eq. 46-47), ``kappa`` (NaN when far-field), ``near_field``, ``d`` (biased distance),
    ``delta_d = d - d[0]`` (eq. 52, ``delta_d[0] = 0``), ``v`` (m/s), ``direction`` (K, 3) world unit
    vectors, ``alpha``. ``z`` is eq. 54, ``[phi; psi; kappa; delta_d[1:]]``. ``index`` maps each
    kept path to its row in the raw :class:`tunnelkit.extraction.PathEstimates`.
    ``cov`` (K, 3, 3) / ``sigma_d`` (K,): the uncertainty the extraction reports for
    ``(phi, psi, kappa)`` and ``d`` (:func:`reported_covariance`), ``None`` unless the route
    was asked for it. ``bias_cov`` (K, 4, 4): the share of the error of ``(phi, psi, kappa, d)``
    that repeats every epoch (a route with a bias budget,
    :func:`~tunnelkit.signal_route.judging.apply_budget`), ``None`` otherwise.
    """

    origin: np.ndarray
    array: str
    phi: np.ndarray
    psi: np.ndarray
    kappa: np.ndarray
    near_field: np.ndarray
    d: np.ndarray
    delta_d: np.ndarray
    v: np.ndarray
    direction: np.ndarray
    alpha: np.ndarray
    index: np.ndarray
    cov: np.ndarray | None = None
    sigma_d: np.ndarray | None = None
    bias_cov: np.ndarray | None = None

    def __post_init__(self) -> None:  # kappa is NaN for a far-field path
        record(self, shapes=_SHAPES, allow_nan=("kappa",), may_be_empty=("array",))

    def __len__(self) -> int:
        return self.d.shape[0]

    @property
    def z(self) -> np.ndarray:
        """Eq. 54 stacked vector ``[phi; psi; kappa; delta_d[1:]]`` (kappa NaN for far-field)."""
        return np.concatenate([self.phi, self.psi, self.kappa, self.delta_d[1:]])

    @property
    def wave_origins(self) -> np.ndarray:
        """``origin + kappa * direction`` (K, 3), NaN rows for far-field paths (Fig. 5)."""
        return self.origin + self.kappa[:, None] * self.direction


@dataclass(frozen=True)
class Epoch:
    """Everything about one simulated epoch (truth, tensor, raw estimates, measurements)."""

    k: int
    t: float
    ue: np.ndarray
    velocity: np.ndarray
    array: ArrayGeometry = field(repr=False)
    paths: list = field(repr=False)
    snapshot: ChannelSnapshot = field(repr=False)
    estimates: object = field(repr=False)
    measurements: RouteMeasurements
    truth_index: np.ndarray  # for each kept measurement, the index of the true path (-1 if none)
    #: the re-judged fit test (:func:`tunnelkit.signal_route.judging.rejudge`), None if not re-judged
    rejudged: dict | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        from ..extraction.estimates import PathEstimates

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
    :func:`reported_covariance`."""
    from ..propagation import SECOND_ORDER

    paths = sequence("paths", paths, empty=True)  # empty: no true path recorded
    instance("snap", snap, ChannelSnapshot)
    meas = measurements_from_estimates(est, array, config, min_d=min_d, judged=judged)
    truth = match_paths(meas.d, meas.direction, paths, clock_bias=snap.clock_bias)
    nuisance = [i for i, p in enumerate(paths) if p.kind == SECOND_ORDER]
    if nuisance and len(meas):
        rows = np.flatnonzero(~np.isin(truth, nuisance))
        meas, truth = restrict_rows(meas, rows), truth[rows]
    return meas, truth


def restrict_rows(m: RouteMeasurements, rows: np.ndarray) -> RouteMeasurements:
    """``m`` restricted to ``rows`` (``delta_d`` re-referenced to the first row kept)."""
    instance("m", m, RouteMeasurements)
    rows = indices("rows", rows, len(m))
    d = m.d[rows]
    return replace(
        m,
        phi=m.phi[rows],
        psi=m.psi[rows],
        kappa=m.kappa[rows],
        near_field=m.near_field[rows],
        d=d,
        delta_d=d - d[0] if d.size else d,
        v=m.v[rows],
        direction=m.direction[rows],
        alpha=m.alpha[rows],
        index=m.index[rows],
        cov=None if m.cov is None else m.cov[rows],
        sigma_d=None if m.sigma_d is None else m.sigma_d[rows],
        bias_cov=None if m.bias_cov is None else m.bias_cov[rows],
    )


def reported_covariance(est, keep, array: ArrayGeometry, config: SRSConfig, judged=True):
    """The CRLB at the estimate (:func:`tunnelkit.extraction.estimate_crlb`) of the kept paths
    ``keep`` (their Fisher information jointly) as the covariance of the world-frame ``(phi,
    psi, kappa)`` (K, 3, 3) and the standard deviation of ``d`` (K,): the wave origin's
    covariance rotated to the world frame, mapped through d(phi, psi, r)/dq (``spherical_jacobian``).
    Returns ``(None, None)`` when the Fisher information is singular at the estimate or, if
    ``judged``, the fit failed its own residual test (``fit.rho > fit.rho_max``: a wrong basin)."""
    from ..extraction import estimate_crlb
    from ..extraction.estimates import PathEstimates
    from ..geometry import spherical_jacobian

    instance("est", est, PathEstimates)
    instance("array", array, ArrayGeometry)
    instance("config", config, SRSConfig)
    keep = indices("keep", keep, len(est.d))
    fit = getattr(est, "fit", None)
    if boolean("judged", judged) and fit is not None and not fit.rho <= fit.rho_max:
        return None, None
    try:
        b = estimate_crlb(est, array, config, paths=keep)
    except np.linalg.LinAlgError:
        return None, None
    rot = array.R  # local -> world: u_world = R u_local
    cov_w = rot @ b["source_cov"] @ rot.T
    G = spherical_jacobian(array.dir_to_world(b["source"]))
    return G @ cov_w @ np.swapaxes(G, 1, 2), b["d"]


def measurements_from_estimates(
    est,
    array: ArrayGeometry,
    config: SRSConfig | None = None,
    *,
    min_d: float = 0.0,
    judged: bool = True,
) -> RouteMeasurements:
    """Apply Algorithm 1's checks to raw estimates (``min_d``: see
    :func:`tunnelkit.extraction.algorithm1`) and express them in the world frame; with
    ``config``, also the covariance the extraction reports (:func:`reported_covariance`, with
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
        cov, sigma_d = reported_covariance(est, keep, array, config, judged=judged)
    return RouteMeasurements(
        array.origin.copy(),
        array.name,
        phi,
        psi,
        est.kappa[keep],
        est.near_field[keep],
        d,
        d - d[0] if d.size else d,
        est.v[keep],
        u,
        est.alpha[keep],
        keep,
        cov,
        sigma_d,
    )
