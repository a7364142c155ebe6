"""What the ray-traced channel needs besides the tunnel: materials, diffuse scattering, depth.

:class:`RTSettings` is the optional ``[raytracing]`` section of a scenario (all keys have
defaults, :meth:`RTSettings.from_scenario`). Materials are ITU-R P.2040 models, evaluated by
Sionna RT at the scenario's carrier:

* the tunnel shell (walls and ceiling facets): ``"concrete"`` (ITU concrete, 0.3 m slab);
* the road: ``"asphalt"`` maps to the ITU ``"very_dry_ground"`` model (relative permittivity 3,
  conductivity 1.5e-4 f_GHz^2.52 S/m, valid 1-10 GHz; about 0.013 S/m at 5.9 GHz), the nearest
  ground model to the permittivity of dry asphalt (about 3-6 at 5-6 GHz), on a 0.05 m slab (the
  stored traces and records at 5.9 GHz use it); ``"asphalt_concrete"`` is the ITU asphalt
  concrete model (permittivity 4.83, conductivity 0.0108 f_GHz^1.3969 S/m, valid 1-40 GHz), the
  road of the 28 GHz presets. A material is refused at a carrier where its model is not defined
  (:data:`MATERIAL_BANDS`, :meth:`RTSettings.check_carrier`);
* the road markings (RRMs) and blocker boxes: ``"metal"``.

Diffuse scattering (Sionna's model, Degli-Esposti 2007): a surface with scattering coefficient
``S`` in [0, 1] keeps ``sqrt(1 - S^2)`` of the specular field and scatters ``S^2`` of the
reflected power in a ``"lambertian"`` lobe or a ``"directive"`` one of width parameter
``alpha_r`` (an integer >= 1; larger is narrower, around the specular direction). ``S`` applies
to the shell and the road; ``metal_scattering_coefficient`` (0 by default: smooth plates) to the
plates and blockers. ``max_depth`` is the number of bounces traced (2: second-order specular
paths and diffuse paths of up to two interactions). ``samples_per_src`` is the number of rays
shot from the vehicle (Fibonacci directions); the diffuse power is a Monte-Carlo estimate over
them.

``array_tracing`` says how the array is traced: ``"element"`` (the default) traces every element
as its own receiver, so each element gets its own ray set (its own delays, and its own cut-offs
where a specular point leaves a plate or a facet across the aperture); ``"centre"`` traces one
receiver at the array's centroid and carries each of its paths to every element as a spherical
wave from the path's unfolded source (centroid + path length along the arrival direction): every
element sees the same paths, with the spherical wavefront and the per-element delay (the
spatial-wideband term) kept; ``"synthetic"`` is Sionna's synthetic array (one ray set at the
centroid, a plane-wave phase per element, the same delay at every element): no curvature and no
spatial-wideband term either. The last two are study switches (what per-element tracing costs
eq. 1's fit), not a better channel.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass

from .._physical import carrier
from .._validate import choice, instance, integer, nonnegative, text

__all__ = [
    "ANTENNA_PATTERNS",
    "ARRAY_TRACING",
    "MATERIALS",
    "MATERIAL_BANDS",
    "SCATTERING_PATTERNS",
    "RTSettings",
]

#: tunnelkit material name -> (ITU-R P.2040 material type in Sionna RT, slab thickness [m])
MATERIALS: dict[str, tuple[str, float]] = {
    "concrete": ("concrete", 0.3),
    "asphalt": ("very_dry_ground", 0.05),
    "asphalt_concrete": ("asphalt_concrete", 0.05),
    "metal": ("metal", 0.01),
    "brick": ("brick", 0.2),
    "marble": ("marble", 0.05),
    "glass": ("glass", 0.01),
    "medium_dry_ground": ("medium_dry_ground", 0.1),
    "wet_ground": ("wet_ground", 0.1),
}
#: the carriers [Hz] at which each material's ITU-R P.2040 model is defined (its Table 3, as
#: Sionna RT holds them): the ground models, and so the road's asphalt, only from 1 to 10 GHz
MATERIAL_BANDS: dict[str, tuple[float, float]] = {
    "concrete": (1e9, 100e9),
    "asphalt": (1e9, 10e9),
    "asphalt_concrete": (1e9, 40e9),
    "metal": (1e9, 100e9),
    "brick": (1e9, 40e9),
    "marble": (1e9, 60e9),
    "glass": (0.1e9, 100e9),
    "medium_dry_ground": (1e9, 10e9),
    "wet_ground": (1e9, 10e9),
}
#: Sionna's scattering lobes
SCATTERING_PATTERNS = ("lambertian", "directive")
#: element patterns (one receiver per element, oriented along the array's boresight):
#: ``"iso"`` (isotropic, as the image method) or Sionna's ``"tr38901"`` (3GPP TR 38.901 element)
ANTENNA_PATTERNS = ("iso", "tr38901")
#: how the array is traced (module docstring): one receiver per element, or one ray set at the
#: centroid carried to the elements as spherical or (Sionna's synthetic array) plane waves
ARRAY_TRACING = ("element", "centre", "synthetic")
#: settings added after traces and records were stored, with the value they had before: left out
#: of :meth:`RTSettings.record` (and so of the cache key) at that value, so a cache or a record
#: of the unchanged channel stays valid
_LATER = {"array_tracing": "element"}


def _material(name: str, value) -> str:
    if not isinstance(value, str) or value not in MATERIALS:
        raise ValueError(
            f"{name}: unknown material {value!r}; expected one of {', '.join(sorted(MATERIALS))}"
        )
    return value


def _coefficient(name: str, value) -> float:
    s = nonnegative(name, value)
    if s > 1.0:
        raise ValueError(f"{name}: a scattering coefficient must lie in [0, 1], got {s}")
    return s


@dataclass(frozen=True)
class RTSettings:
    """The ray tracer's scene and solver settings (module docstring); defaults documented there.

    >>> RTSettings(scattering_coefficient=1.5)
    Traceback (most recent call last):
    ...
    ValueError: scattering_coefficient: a scattering coefficient must lie in [0, 1], got 1.5
    """

    scattering_coefficient: float = 0.3
    metal_scattering_coefficient: float = 0.0
    scattering_pattern: str = "lambertian"
    alpha_r: int = 4
    max_depth: int = 2
    samples_per_src: int = 20_000
    wall_material: str = "concrete"
    road_material: str = "asphalt"
    rrm_material: str = "metal"
    antenna_pattern: str = "iso"
    array_tracing: str = "element"

    def __post_init__(self) -> None:
        _coefficient("scattering_coefficient", self.scattering_coefficient)
        _coefficient("metal_scattering_coefficient", self.metal_scattering_coefficient)
        choice("scattering_pattern", self.scattering_pattern, SCATTERING_PATTERNS)
        integer("alpha_r", self.alpha_r, minimum=1, maximum=100)
        integer("max_depth", self.max_depth, minimum=1, maximum=5)
        integer("samples_per_src", self.samples_per_src, minimum=100, maximum=10_000_000)
        for key in ("wall_material", "road_material", "rrm_material"):
            _material(key, getattr(self, key))
        choice("antenna_pattern", self.antenna_pattern, ANTENNA_PATTERNS)
        choice("array_tracing", self.array_tracing, ARRAY_TRACING)

    @property
    def diffuse(self) -> bool:
        """True when some surface scatters (a coefficient above zero)."""
        return self.scattering_coefficient > 0 or self.metal_scattering_coefficient > 0

    def material_for(self, kind: str) -> tuple[str, str, float, float]:
        """``(tunnelkit material, ITU type, thickness [m], scattering coefficient)`` of a surface
        of ``kind`` ("wall", "ceiling", "road", "rrm", "blocker"; anything else is shell)."""
        kind = text("kind", kind)
        if kind == "road":
            name = self.road_material
        elif kind in ("rrm", "blocker"):
            name = self.rrm_material if kind == "rrm" else "metal"
        else:
            name = self.wall_material
        itu, thickness = MATERIALS[name]
        s = self.metal_scattering_coefficient if name == "metal" else self.scattering_coefficient
        return name, itu, thickness, s

    def check_carrier(self, fc: float) -> None:
        """Refuse a carrier ``fc`` [Hz] at which a material of the scene has no model (the tracer
        would fail every epoch): ``ValueError`` naming the material's key."""
        fc = carrier("fc", fc)
        for key in ("wall_material", "road_material", "rrm_material"):
            lo, hi = MATERIAL_BANDS[getattr(self, key)]
            if not lo <= fc <= hi:
                raise ValueError(
                    f"{key}: {getattr(self, key)!r} (ITU-R P.2040 {MATERIALS[getattr(self, key)][0]}) "
                    f"is modelled from {lo / 1e9:g} to {hi / 1e9:g} GHz, not at the carrier "
                    f"{fc / 1e9:g} GHz; choose one modelled there (MATERIAL_BANDS)"
                )

    def record(self) -> dict:
        """Every setting as a dict, less those added later that hold their earlier value
        (``_LATER``): what a stored record's provenance and :meth:`fingerprint` compare."""
        out = asdict(self)
        for key, old in _LATER.items():
            if out[key] == old:
                del out[key]
        return out

    def fingerprint(self) -> str:
        """A stable hash of every setting (:meth:`record`; part of the ray-tracing cache key)."""
        return hashlib.sha256(json.dumps(self.record(), sort_keys=True).encode()).hexdigest()

    @classmethod
    def from_scenario(cls, scenario, **overrides) -> RTSettings:
        """The scenario's ``[raytracing]`` section (absent: every default), ``overrides`` on top."""
        from ..scenarios import Scenario

        instance("scenario", scenario, Scenario)
        kw = dict(scenario.sections.get("raytracing") or {})
        kw.update(overrides)
        unknown = sorted(set(kw) - set(cls.__dataclass_fields__))
        if unknown:
            raise ValueError(
                f"raytracing: unknown key(s) {unknown}; expected {sorted(cls.__dataclass_fields__)}"
            )
        return cls(**kw)
