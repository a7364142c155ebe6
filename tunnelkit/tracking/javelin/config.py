"""JAVELIN's numbers (Italiano et al. 2026, section 4.2), validated at construction.

Every value is SI and radians inside; :meth:`JavelinConfig.paper` documents the published values
in the units the paper prints them (degrees, metres). Parameters the paper does not give (the VUE
random-walk intensity, the UE height drift, the Doppler tolerance) are named as ours. The config
holds numbers only: how the tracker behaves (noise model, associator, births, VUE motion,
curvature model, updater, pre-filters) is chosen by its roles
(:mod:`~tunnelkit.tracking.javelin.roles`), and the named designs are factory functions
(:mod:`~tunnelkit.tracking.javelin.designs`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from ..._physical import start_spread
from ..._validate import choice, integer, nonnegative, positive, probability, vector

__all__ = ["MOTION_STEPS", "JavelinConfig"]

_SIGMAS = ("sigma_phi", "sigma_psi", "sigma_kappa", "sigma_delta_d", "sigma_speed", "sigma_heading",
           "sigma_p0", "sigma_p0_ue", "sigma_vue_walk", "sigma_height", "doppler_tolerance",
           "sigma_speed_missing")  # fmt: skip

#: eq. 62's held message, or the midpoint of two (:func:`.motion.midpoint_messages`)
MOTION_STEPS = ("held", "midpoint")
#: the odometry's repeating errors a tracker can be told (:meth:`JavelinConfig.told`)
_ODOMETRY = ("sigma_speed_scale", "sigma_heading_bias", "heading_drift", "sigma_yaw_rate_bias")


@dataclass(frozen=True)
class JavelinConfig:
    """Tracker numbers. Defaults are the paper's (section 4.2) where it gives them.

    - ``gate_probability`` p of eq. 59 (0.99), ``max_misses`` zeta of Algorithm 3 (1),
      ``los_gamma`` gamma of eq. 61 (0.2);
    - measurement noise ``sigma_phi``, ``sigma_psi`` (2 deg), ``sigma_kappa`` (1.5 m),
      ``sigma_delta_d`` (1.5 m), used by the ``FixedNoise`` role (and as ``ReportedNoise``'s
      fallback);
    - V2X velocity-sensor noise ``sigma_speed`` (0.2 m/s), ``sigma_heading`` (1 deg);
    - birth covariance ``sigma_p0`` (10 m, ``P_0|0 = sigma_P^2 I``) and the initial UE
      uncertainty ``sigma_p0_ue`` (10 m as in the paper's ``P_0|0``; the studies start from an
      open-sky fix of 1 m); ``sigma_p0_height`` (ours) the initial uncertainty of the UE's
      height when it is known better than its position (a vehicle's antenna height; default
      ``None``: ``sigma_p0_ue`` on every axis, as the paper);
    - ours (not in the paper): ``sigma_vue_walk`` [m/sqrt(s)] random-walk intensity of a VUE,
      ``sigma_height`` [m/sqrt(s)] drift of the (known) UE height, ``doppler_tolerance`` [m/s]
      for the static/dynamic test, ``sigma_speed_missing`` [m/s] extra speed noise while the
      speed/heading message is missing;
    - ``base_station``: reference-antenna position [m] (the paper's origin);
    - ours: ``update_iterations`` the relinearisations of each epoch's update at most (an
      iterated EKF, :func:`~tunnelkit.tracking.javelin.iterated.iterate`; default 0:
      the paper's one EKF step);
    - ours, the odometry's repeating errors the tracker is told (:meth:`told`; default 0: the
      paper's white messages): ``sigma_speed_scale`` the sigma of the speed scale factor,
      ``sigma_heading_bias`` [rad] of the heading bias at the start, ``heading_drift``
      [rad/sqrt(s)] its random walk, ``sigma_yaw_rate_bias`` [rad/s] of the yaw-rate bias; any
      of them above 0 adds the odometry states to the state (:attr:`n_odo`);
    - ours: ``motion_step``, eq. 62's ``"held"`` message or the ``"midpoint"`` of two
      (:func:`.motion.midpoint_messages`; :func:`~.designs.ours` steps on the midpoint).
    """

    gate_probability: float = 0.99
    max_misses: int = 1
    los_gamma: float = 0.2
    sigma_phi: float = float(np.radians(2.0))
    sigma_psi: float = float(np.radians(2.0))
    sigma_kappa: float = 1.5
    sigma_delta_d: float = 1.5
    sigma_speed: float = 0.2
    sigma_heading: float = float(np.radians(1.0))
    sigma_p0: float = 10.0
    sigma_p0_ue: float = 10.0
    sigma_vue_walk: float = 0.3
    sigma_height: float = 0.01
    doppler_tolerance: float = 1.0
    sigma_speed_missing: float = 1.0
    sigma_p0_height: float | None = None
    base_station: tuple[float, float, float] = (0.0, 0.0, 0.0)
    update_iterations: int = 0
    sigma_speed_scale: float = 0.0
    sigma_heading_bias: float = 0.0
    heading_drift: float = 0.0
    sigma_yaw_rate_bias: float = 0.0
    motion_step: str = "held"

    def __post_init__(self) -> None:
        probability("gate_probability", self.gate_probability)
        integer("max_misses", self.max_misses, minimum=0)
        g = positive("los_gamma", self.los_gamma)
        if g > 1:
            raise ValueError(f"los_gamma: must lie in (0, 1], got {g}")
        for name in _SIGMAS:
            positive(name, getattr(self, name))
        start_spread("sigma_p0", self.sigma_p0), start_spread("sigma_p0_ue", self.sigma_p0_ue)
        if self.sigma_p0_height is not None:
            positive("sigma_p0_height", self.sigma_p0_height)
        bs = vector("base_station", self.base_station, 3)
        object.__setattr__(self, "base_station", tuple(float(v) for v in bs))
        integer("update_iterations", self.update_iterations, minimum=0)
        for name in _ODOMETRY:
            nonnegative(name, getattr(self, name))
        choice("motion_step", self.motion_step, MOTION_STEPS)
        if self.sigma_speed_scale >= 1.0:
            raise ValueError(f"sigma_speed_scale: a fraction below 1, got {self.sigma_speed_scale}")

    @property
    def n_odo(self) -> int:
        """The odometry states the tracker carries: 3 (:data:`~.state.ODOMETRY_STATES`) when it
        is told any repeating odometry error, else 0 (the paper's state)."""
        return 3 if any(getattr(self, name) for name in _ODOMETRY) else 0

    @property
    def odometry_sigmas(self) -> tuple[float, float, float] | None:
        """The prior sigmas of the odometry states (``None`` without them)."""
        if not self.n_odo:
            return None
        return (self.sigma_speed_scale, self.sigma_heading_bias, self.sigma_yaw_rate_bias)

    def told(self, odometry) -> JavelinConfig:
        """A copy told the odometry model ``odometry`` (:func:`~.odometrystates.told_config`)."""
        from .odometrystates import told_config  # a tracker told the odometry

        return told_config(self, odometry)

    @property
    def bs(self) -> np.ndarray:
        """Base-station position as an array (3,)."""
        return np.asarray(self.base_station, dtype=float)

    @classmethod
    def paper(cls, **overrides) -> JavelinConfig:
        """The paper's section 4.2 values: p = 0.99, zeta = 1, gamma = 0.2, sigma_phi = sigma_psi
        = 2 deg, sigma_kappa = sigma_dd = 1.5 m, sigma_nu = 0.2 m/s, sigma_theta = 1 deg,
        sigma_P = 10 m; ``overrides`` replace any field (validated)."""
        return cls(**overrides)

    def with_(self, **overrides) -> JavelinConfig:
        """A copy with some fields replaced (validated again)."""
        names = {f.name for f in fields(self)}
        for k in overrides:
            if k not in names:
                raise ValueError(f"{k}: not a JavelinConfig parameter; known: {sorted(names)}")
        return replace(self, **overrides)
