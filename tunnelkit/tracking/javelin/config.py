"""JAVELIN parameters (Italiano et al. 2026, section 4.2), validated at construction.

Every value is SI and radians inside; :meth:`JavelinConfig.paper` documents the published values
in the units the paper prints them (degrees, metres). Parameters the paper does not give (the VUE
random-walk intensity, the UE height drift, the Doppler tolerance) are named as ours.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from ..._validate import integer, nonnegative, positive, probability, vector

__all__ = [
    "ASSOCIATION_COSTS",
    "ASSOCIATORS",
    "KAPPA_MODELS",
    "MEASUREMENT_NOISE",
    "VUE_MOTIONS",
    "JavelinConfig",
]

ASSOCIATORS = ("greedy", "gnn")
ASSOCIATION_COSTS = ("mahalanobis", "likelihood")
MEASUREMENT_NOISE = ("fixed", "reported")
BIRTH_COVARIANCES = ("fixed", "measured")
VUE_MOTIONS = ("random_walk", "mirror")
KAPPA_MODELS = ("reflector", "vue")

_SIGMAS = (
    "sigma_phi",
    "sigma_psi",
    "sigma_kappa",
    "sigma_delta_d",
    "sigma_speed",
    "sigma_heading",
    "sigma_p0",
    "sigma_vue_walk",
    "sigma_height",
    "doppler_tolerance",
    "sigma_speed_missing",
)


@dataclass(frozen=True)
class JavelinConfig:
    """Tracker parameters. Defaults are the paper's (section 4.2) where it gives them.

    - ``gate_probability`` p of eq. 59 (0.99), ``max_misses`` zeta of Algorithm 3 (1),
      ``los_gamma`` gamma of eq. 61 (0.2);
    - measurement noise ``sigma_phi``, ``sigma_psi`` (2 deg), ``sigma_kappa`` (1.5 m),
      ``sigma_delta_d`` (1.5 m);
    - V2X velocity-sensor noise ``sigma_speed`` (0.2 m/s), ``sigma_heading`` (1 deg);
    - birth and initial covariance ``sigma_p0`` (10 m, ``P_0|0 = sigma_P^2 I``);
    - ours (not in the paper): ``sigma_vue_walk`` [m/sqrt(s)] random-walk intensity of a VUE,
      ``sigma_height`` [m/sqrt(s)] drift of the (known) UE height, ``doppler_tolerance`` [m/s]
      for the static/dynamic test, ``sigma_speed_missing`` [m/s] extra speed noise while the
      speed/heading message is missing, ``sigma_p0_ue`` [m] initial UE uncertainty (the paper
      starts from an open-sky GNSS fix; ``None`` uses ``sigma_p0``).
    - design switches: ``associator`` ``"greedy"`` (Algorithm 2) or ``"gnn"`` (global nearest
      neighbour, ours); ``association_cost`` ``"mahalanobis"`` (the paper's ``eta^2``) or
      ``"likelihood"`` (``eta^2 + ln det S``, ours); ``vue_motion`` ``"random_walk"`` (paper) or ``"mirror"`` (a wall-fixed
      VUE mirrors the UE displacement, ours); ``kappa_model`` ``"reflector"`` (eq. 51) or
      ``"vue"`` (curvature centred on the VUE); ``correlated_delta_d``: the TDoAs share the
      reference path's delay, so their covariance is ``sigma_dd^2 (I + 1 1^T) / 2`` (ours; the
      paper uses a diagonal ``sigma_dd^2 I``); ``update_with_births``: measurements that give
      birth to a track also update the state in that epoch (the paper's Algorithm 4);
      ``measurement_noise``: ``"fixed"`` (the paper: one ``sigma_phi`` ... ``sigma_delta_d`` for
      every path) or ``"reported"`` (ours: each path's own covariance as the extraction reports
      it, ``PathMeasurements.cov`` / ``sigma_d``; an epoch without one falls back to the fixed
      sigmas, reported as a fault); ``birth_covariance``: ``"fixed"`` (the paper's
      ``sigma_P^2 I``) or ``"measured"`` (ours: the path's angle covariance and the UE's ``x``
      uncertainty carried through the intersection of Algorithm 3, with the cross-covariance);
      ``update_gate`` (ours; ``None`` = off as in the paper): the probability of a chi-square
      test on the whole stacked innovation; pairs are left out until it passes
      (:func:`~tunnelkit.tracking.javelin.update.exclude_inconsistent`); ``min_d`` [m]
      Algorithm 1's delay check, ``d >= min_d``: 0 as printed, ``-c b_max`` to keep the paths a
      negative clock bias pushed below zero (ours).
    - ``doppler_clutter_margin`` [m/s] (ours; ``None`` = off as in the paper): a path whose
      radial speed exceeds the vehicle speed by more than this margin cannot come from a static
      reflector (``|v| <= ||v_u||`` for any mirror image) and is dropped as clutter before
      association (spurious CPD components show hundreds of m/s);
    - ``doppler_sign``: measured ``v = doppler_sign * d(range)/dt``; -1 is the channel
      convention ``v = c f_d / f_c`` with ``f_d > 0`` when approaching.
    - ``base_station``: reference-antenna position [m] (the paper's origin).
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
    sigma_p0_ue: float | None = None
    sigma_vue_walk: float = 0.3
    sigma_height: float = 0.01
    doppler_tolerance: float = 1.0
    sigma_speed_missing: float = 1.0
    associator: str = "greedy"
    association_cost: str = "mahalanobis"
    vue_motion: str = "random_walk"
    kappa_model: str = "reflector"
    correlated_delta_d: bool = False
    update_with_births: bool = True
    measurement_noise: str = "fixed"
    birth_covariance: str = "fixed"
    update_gate: float | None = None
    min_d: float = 0.0
    doppler_clutter_margin: float | None = None
    doppler_sign: float = -1.0
    base_station: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        probability("gate_probability", self.gate_probability)
        integer("max_misses", self.max_misses, minimum=0)
        g = positive("los_gamma", self.los_gamma)
        if g > 1:
            raise ValueError(f"los_gamma: must lie in (0, 1], got {g}")
        for name in _SIGMAS:
            positive(name, getattr(self, name))
        if self.sigma_p0_ue is not None:
            positive("sigma_p0_ue", self.sigma_p0_ue)
        if not (np.isfinite(self.min_d) and self.min_d <= 0):
            raise ValueError(f"min_d: expected a finite value <= 0, got {self.min_d!r}")
        if self.update_gate is not None:
            probability("update_gate", self.update_gate)
        if self.doppler_clutter_margin is not None:
            nonnegative("doppler_clutter_margin", self.doppler_clutter_margin)
        for name, allowed in (
            ("associator", ASSOCIATORS),
            ("association_cost", ASSOCIATION_COSTS),
            ("vue_motion", VUE_MOTIONS),
            ("kappa_model", KAPPA_MODELS),
            ("measurement_noise", MEASUREMENT_NOISE),
            ("birth_covariance", BIRTH_COVARIANCES),
        ):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name}: expected one of {allowed}, got {getattr(self, name)!r}")
        if self.doppler_sign not in (-1.0, 1.0, -1, 1):
            raise ValueError(f"doppler_sign: expected +1 or -1, got {self.doppler_sign!r}")
        bs = vector("base_station", self.base_station, 3)
        object.__setattr__(self, "base_station", tuple(float(v) for v in bs))
        for name in ("correlated_delta_d", "update_with_births"):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"{name}: expected True or False, got {getattr(self, name)!r}")

    @property
    def bs(self) -> np.ndarray:
        """Base-station position as an array (3,)."""
        return np.asarray(self.base_station, dtype=float)

    @property
    def p0_ue(self) -> float:
        """Initial UE standard deviation [m]."""
        return self.sigma_p0 if self.sigma_p0_ue is None else float(self.sigma_p0_ue)

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
