"""VUE births with a measured covariance (ours, :class:`MeasuredBirth`): the intersection of
Algorithm 3 (:func:`~.manage.intersection`) linearised in the path's angles and the UE's ``x``
(:func:`~.linearbirth.intersection_jacobian`) gives the new VUE's covariance and its
cross-covariance with the state (:func:`birth_covariance`). The cross-covariance with a
bias-aware tracker's biases is :func:`~.linearbirth.birth_bias_cross`; the paper's births
(``FixedBirth``, ``sigma_P^2 I``) and the track management itself are
:mod:`~tunnelkit.tracking.javelin.manage`.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..._validate import instance
from .config import JavelinConfig
from .linearbirth import intersection_jacobian
from .manage import FixedBirth, birth_arguments
from .measurement import PathMeasurements
from .noise import FixedNoise
from .state import JavelinState

__all__ = ["MeasuredBirth"]


def birth_covariance(
    state: JavelinState, meas: PathMeasurements, j: int, config: JavelinConfig, noise=None
):
    """The covariance (2, 2) of a VUE born from path ``j`` and its cross-covariance (2, D) with
    the state, by linearising :func:`~.manage.intersection` in the path's angles and the UE's ``x``
    (ours; the initiator ``MeasuredBirth``): ``F_z R F_z^T + f P_xx f^T`` and ``f P_x,:``. ``R``
    is the path's angle covariance from the measurement-noise role ``noise`` (the reported one
    under ``ReportedNoise``; default the paper's ``diag(sigma_phi^2, sigma_psi^2)``)."""
    noise = FixedNoise() if noise is None else noise
    F = intersection_jacobian(meas.phi[j], meas.psi[j], state.x[0], config.bs)
    R = noise.covariances(meas, config)[j, :2, :2]
    f = F[:, 2:3]  # d(y, z) / d x_u
    cross = f @ state.P[0:1, :]
    cov = F[:, :2] @ R @ F[:, :2].T + f @ state.P[0:1, 0:1] @ f.T
    return 0.5 * (cov + cov.T), cross


@dataclass(frozen=True)
class MeasuredBirth(FixedBirth):
    """A new VUE with the covariance of the angles that placed it and of the UE's ``x``, carried
    through the intersection of Algorithm 3 with the cross-covariance (ours:
    :func:`birth_covariance`)."""

    def covariance(self, state, meas, j: int, config: JavelinConfig, noise):
        birth_arguments(state, meas, j, noise)
        instance("config", config, JavelinConfig)
        return birth_covariance(state, meas, j, config, noise)
