"""The swappable roles of JAVELIN (Italiano et al. 2026, sections 3.2-3.5), one small class each.

A tracker is :class:`~tunnelkit.tracking.javelin.config.JavelinConfig` (numbers only) plus one
object per role (measurement noise, associator, initiator, VUE motion, curvature model, updater,
pre-filters), held together by :class:`JavelinDesign`, which refuses a combination that cannot
work. The named designs are in :mod:`~tunnelkit.tracking.javelin.designs`.

The paper's role and ours, side by side: docs/internals/tracking.md.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

from ..._validate import instance
from .associate import Associator
from .config import JavelinConfig
from .manage import FixedBirth
from .measurement import DelayCheck, DopplerClutter, ReflectorCurvature, VueCurvature
from .motion import MirrorMotion, RandomWalk
from .noise import FixedNoise, ReportedNoise
from .update import JointTestUpdater, JosephUpdater

__all__ = [
    "Associator",
    "DelayCheck",
    "DopplerClutter",
    "FixedBirth",
    "FixedNoise",
    "JavelinDesign",
    "JointTestUpdater",
    "JosephUpdater",
    "MirrorMotion",
    "RandomWalk",
    "ReflectorCurvature",
    "ReportedNoise",
    "VueCurvature",
]


# -- the design -----------------------------------------------------------------------------------
_ROLE_TYPES = {
    "noise": (FixedNoise, ReportedNoise),
    "associator": (Associator,),
    "initiator": (FixedBirth,),
    "vue_motion": (RandomWalk,),
    "curvature": (ReflectorCurvature,),
    "updater": (JosephUpdater,),
}


@dataclass(frozen=True)
class JavelinDesign:
    """A JAVELIN tracker: its numbers (``config``) and one object per role (docs/internals).

    ``prefilters`` run in order on every epoch's paths before association; Algorithm 1's
    :class:`DelayCheck` comes first in every design. The defaults are the paper's design.
    """

    config: JavelinConfig = field(default_factory=JavelinConfig)
    noise: FixedNoise | ReportedNoise = field(default_factory=FixedNoise)
    associator: Associator = field(default_factory=Associator)
    initiator: FixedBirth = field(default_factory=FixedBirth)
    vue_motion: RandomWalk = field(default_factory=RandomWalk)
    curvature: ReflectorCurvature = field(default_factory=ReflectorCurvature)
    updater: JosephUpdater = field(default_factory=JosephUpdater)
    prefilters: tuple = (DelayCheck(),)

    def __post_init__(self) -> None:
        if not isinstance(self.config, JavelinConfig):
            raise TypeError(f"config: expected a JavelinConfig, got {type(self.config).__name__}")
        for name, types in _ROLE_TYPES.items():
            v = getattr(self, name)
            if not isinstance(v, types):
                want = " or ".join(t.__name__ for t in types)
                raise TypeError(f"{name}: expected a {want}, got {type(v).__name__}")
        pre = tuple(self.prefilters) if isinstance(self.prefilters, list | tuple) else None
        if pre is None or not all(isinstance(p, DelayCheck | DopplerClutter) for p in pre):
            raise TypeError(
                "prefilters: expected a tuple of DelayCheck / DopplerClutter, got "
                f"{self.prefilters!r}"
            )
        if not pre or not isinstance(pre[0], DelayCheck):
            raise ValueError("prefilters: Algorithm 1's DelayCheck must come first")
        if sum(isinstance(p, DelayCheck) for p in pre) > 1:
            raise ValueError("prefilters: one DelayCheck (Algorithm 1) per design")
        if sum(isinstance(p, DopplerClutter) for p in pre) > 1:
            raise ValueError("prefilters: one DopplerClutter per design")
        object.__setattr__(self, "prefilters", pre)

    @property
    def min_d(self) -> float:
        """The delay check's ``min_d`` (the first pre-filter)."""
        return self.prefilters[0].min_d

    def with_(self, **changes) -> JavelinDesign:
        """A copy with some roles replaced; numbers go to ``config`` (``with_(sigma_phi=...)``)."""
        names = {f.name for f in fields(self)}
        roles = {k: v for k, v in changes.items() if k in names}
        numbers = {k: v for k, v in changes.items() if k not in names}
        if numbers:
            roles["config"] = roles.get("config", self.config).with_(**numbers)
        return replace(self, **roles)

    def with_prefilter(self, pre) -> JavelinDesign:
        """A copy with ``pre`` replacing the pre-filter of its type (or appended)."""
        instance("pre", pre, (DelayCheck, DopplerClutter))
        kind = type(pre)
        kept = [p for p in self.prefilters if type(p) is not kind]
        new = [pre, *kept] if kind is DelayCheck else [*kept, pre]
        return replace(self, prefilters=tuple(new))

    def requires_reported_covariance(self) -> bool:
        """Whether the measurement route must report a covariance per path."""
        return self.noise.needs_reported

    def describe(self) -> dict[str, str]:
        """Each role's class and arguments, for tables and notebooks."""
        out = {f.name: repr(getattr(self, f.name)) for f in fields(self) if f.name != "config"}
        out["prefilters"] = ", ".join(repr(p) for p in self.prefilters)
        return out
