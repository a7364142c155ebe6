"""One propagation path and what both tracers share: the :class:`Path` record, how a tracer
makes one (:func:`make_path`), the checked arguments of a trace (:func:`trace_arguments`) and the
check every consumer of traced paths makes (:func:`as_path_list`). The tracers:
:mod:`tunnelkit.propagation.paths` (LoS and first order) and
:mod:`tunnelkit.propagation.second_order`."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from .._physical import carrier, speeds
from .._validate import boolean, choice, record, vector
from ..arrays import ArrayGeometry
from ..constants import C, wavelength
from .surfaces import Tunnel3D

__all__ = [
    "PATH_KINDS",
    "SECOND_ORDER",
    "Path",
    "arrival_angles",
    "as_path_list",
]

#: the path families :func:`~tunnelkit.propagation.paths.trace_paths` can select
PATH_KINDS = ("los", "wall", "ceiling", "road", "rrm")
#: ``Path.kind`` (and ``surface_kind``) of a second-order specular path
SECOND_ORDER = "reflection2"


@dataclass(frozen=True)
class Path:
    """One propagation path from the UE to an array, at one epoch.

    Attributes
    ----------
    kind : "los", "reflection" or "reflection2" (:data:`SECOND_ORDER`: two specular bounces)
    surface, surface_kind : name and kind ("wall", "ceiling", "road", "rrm"; "surface" for an
        object a ray tracer does not name) of the reflector
        ("" and "los" for the direct path; for a second-order path ``"first > second"`` and
        "reflection2")
    source : (3,) the VUE (the UE itself for LoS; the UE mirrored twice for a second-order
        path), world frame
    point : (3,) the reflection point (the UE for LoS; the last bounce for a second-order path),
        world frame
    length : exact path length to the reference antenna [m] (``||VUE - p_0||``)
    lengths : (M,) exact length to every antenna (spherical wavefront from the VUE)
    lengths_srnf : (M,) SR-NF lengths: ``||UE - point|| + ||point - p_m||`` (second order:
        the length up to the last bounce plus ``||point - p_m||``)
    direction : (3,) unit vector of arrival, world frame, from the reference antenna towards
        ``point`` (and the VUE, which is collinear)
    direction_local : (3,) the same in the array's local frame
    azimuth, elevation : world-frame angles of ``direction`` (Italiano eq. 46-47, 49-50) [rad]
    kappa_srnf : ``||point - p_0||``, the SR-NF curvature radius (eq. 51; ``length`` for LoS)
    range_rate : d(length)/dt [m/s]; ``velocity = -range_rate``; ``doppler = fc velocity / c``
    reflection_coefficient : complex ``Gamma`` (1 for LoS; the product of both bounces' for a
        second-order path)
    gain : complex amplitude ``Gamma lambda / (4 pi length) exp(-j 2 pi length / lambda)``
    ue : (3,) the vehicle position the path was traced from
    """

    kind: str
    surface: str
    surface_kind: str
    source: np.ndarray
    point: np.ndarray
    length: float
    lengths: np.ndarray = field(repr=False)
    lengths_srnf: np.ndarray = field(repr=False)
    direction: np.ndarray
    direction_local: np.ndarray
    azimuth: float
    elevation: float
    kappa_srnf: float
    range_rate: float
    velocity: float
    doppler: float
    reflection_coefficient: complex
    gain: complex
    ue: np.ndarray = field(default=None, repr=False)

    def __post_init__(self) -> None:
        v3, m = (3,), ("M",)
        record(self, shapes={"source": v3, "point": v3, "direction": v3, "direction_local": v3,
                             "ue": v3, "lengths": m, "lengths_srnf": m},
               positive=("length", "lengths", "lengths_srnf", "kappa_srnf"),
               may_be_empty=("surface",), skip=("ue",) if self.ue is None else ())  # fmt: skip
        choice("kind", self.kind, ("los", "reflection", SECOND_ORDER))
        choice("surface_kind", self.surface_kind, (*PATH_KINDS, SECOND_ORDER, "surface"))
        _physical_motion(self.direction, self.range_rate, self.velocity)

    def delta(self, model: str = "exact") -> np.ndarray:
        """Path-length offsets ``delta_m = d_m - d_0`` (eq. 2) for ``model`` "exact" or "srnf"."""
        if model == "exact":
            return self.lengths - self.lengths[0]
        if model == "srnf":
            return self.lengths_srnf - self.lengths_srnf[0]
        raise ValueError(f"model: expected 'exact' or 'srnf', got {model!r}")

    def kappa(self, model: str = "exact") -> float:
        """Radius of the wavefront at the reference antenna: ``length`` (VUE) or ``kappa_srnf``."""
        if model == "exact":
            return self.length
        if model == "srnf":
            return self.kappa_srnf
        raise ValueError(f"model: expected 'exact' or 'srnf', got {model!r}")

    def wave_origin(self, model: str = "exact") -> np.ndarray:
        """Where the wavefront is centred: the VUE (exact) or the reflection point (SR-NF)."""
        return self.source if choice("model", model, ("exact", "srnf")) == "exact" else self.point


def _physical_motion(direction, range_rate, velocity) -> None:
    """A path's physical sanity: a unit direction of arrival, and a length that changes no faster
    than a vehicle moves (the base station is static; :data:`tunnelkit._physical.MAX_SPEED`)."""
    if abs(float(np.linalg.norm(direction)) - 1.0) > 1e-6:
        raise ValueError(
            f"direction: must be a unit vector, got norm {np.linalg.norm(direction):g}"
        )
    speeds("range_rate", range_rate), speeds("velocity", velocity)


def arrival_angles(u) -> tuple[float, float]:
    """World-frame azimuth and elevation [rad] of the direction ``u`` (3,) (eq. 46-47, 49-50):
    ``atan2(u_y, u_x)`` and ``atan2(u_z, hypot(u_x, u_y))``."""
    return _angles(vector("u", u, 3))


def _angles(u: np.ndarray) -> tuple[float, float]:
    return float(np.arctan2(u[1], u[0])), float(np.arctan2(u[2], np.hypot(u[0], u[1])))


def _traced_path(*values) -> Path:
    """A :class:`Path` of the tracer's own values (finite, a unit direction, a speed below c by
    construction), its fields not checked again: the unchecked twin of ``Path(...)`` for the
    tracer, which makes several per epoch (the checks at the public boundary only)."""
    path = object.__new__(Path)
    for f, v in zip(dataclasses.fields(Path), values, strict=True):
        object.__setattr__(path, f.name, v)
    return path


def make_path(kind, surface, skind, source, point, ue, src_vel, array, fc, gamma, leg=None) -> Path:
    """The traced :class:`Path` from ``source`` (the VUE) via ``point`` to ``array``."""
    lam = wavelength(fc)
    ant = array.world
    lengths = np.linalg.norm(source - ant, axis=-1)
    leg = float(np.linalg.norm(ue - point)) if leg is None else float(leg)
    lengths_srnf = leg + np.linalg.norm(point - ant, axis=-1) if kind != "los" else lengths
    d0 = float(lengths[0])
    to_point = point - array.origin
    dist = np.linalg.norm(to_point)
    u = to_point / dist
    rr = float((source - array.origin) @ src_vel / d0)
    vel = -rr
    az, el = _angles(u)
    g = complex(gamma) * lam / (4 * np.pi * d0) * np.exp(-2j * np.pi * d0 / lam)
    return _traced_path(
        kind,
        surface,
        skind,
        source.copy(),
        point.copy(),
        d0,
        lengths,
        lengths_srnf,
        u,
        array.dir_to_local(u),
        az,
        el,
        float(dist),
        rr,
        vel,
        fc * vel / C,
        complex(gamma),
        g,
        ue.copy(),
    )


def trace_arguments(tunnel, array, ue, ue_velocity, fc, kinds, front_only):
    """The checked arguments of :func:`~tunnelkit.propagation.paths.trace_paths` and
    :func:`~tunnelkit.propagation.second_order.second_order_paths`:
    ``(fc, kinds, front_only, ue, ue_velocity)``, the array placed inside the tunnel and the UE
    in its radiating field (:func:`_check_array_placement`)."""
    if not isinstance(tunnel, Tunnel3D):
        raise TypeError(f"tunnel: expected a propagation.Tunnel3D, got {type(tunnel).__name__}")
    if not isinstance(array, ArrayGeometry):
        raise TypeError(f"array: expected an arrays.ArrayGeometry, got {type(array).__name__}")
    fc = carrier("fc", fc)
    if isinstance(kinds, str) or not isinstance(kinds, tuple | list | set | frozenset):
        raise TypeError(f"kinds: expected a tuple of path kinds from {PATH_KINDS}, got {kinds!r}")
    unknown = [k for k in kinds if k not in PATH_KINDS]
    if unknown or not kinds:
        raise ValueError(f"kinds: expected one or more of {PATH_KINDS}, got {tuple(kinds)!r}")
    front_only = boolean("front_only", front_only)
    ue = tunnel.require_inside("ue", vector("ue", ue, 3))
    vel = vector("ue_velocity", ue_velocity, 3)
    _check_array_placement(tunnel, array, ue, fc)
    return fc, tuple(kinds), front_only, ue, vel


def as_path_list(paths, name: str = "paths") -> list[Path]:
    """``paths`` as a non-empty list of :class:`Path` (a ``TypeError``/``ValueError`` naming
    ``name`` otherwise): the check every consumer of traced paths makes."""
    if not isinstance(name, str) or not name:
        raise TypeError(f"name: expected the parameter's name (a non-empty str), got {name!r}")
    if isinstance(paths, Path | str | bytes) or not isinstance(paths, list | tuple):
        raise TypeError(f"{name}: expected a list of propagation.Path, got {type(paths).__name__}")
    paths = list(paths)
    if not paths:
        raise ValueError(f"{name}: need at least one path (the vehicle is fully blocked)")
    for i, p in enumerate(paths):
        if not isinstance(p, Path):
            raise TypeError(f"{name}[{i}]: expected a propagation.Path, got {type(p).__name__}")
    return paths


def _check_array_placement(tunnel: Tunnel3D, array: ArrayGeometry, ue: np.ndarray, fc: float):
    """The array's reference antenna inside the tunnel (not in a wall, under the road or inside
    a blocker) and the UE in the radiating field of every element (farther than a wavelength)."""
    a0 = array.origin
    if not bool(tunnel.contains(a0, margin=1e-6)):
        raise ValueError(
            f"array: the reference antenna at {a0.tolist()} lies outside the tunnel (in a wall, "
            "under the road, above the roof or beyond its ends)"
        )
    for box in tunnel.blockers:
        if np.all(a0 >= box.lo) and np.all(a0 <= box.hi):
            raise ValueError(
                f"array: the reference antenna at {a0.tolist()} lies inside {box.name!r}"
            )
    lam = float(wavelength(fc))
    gap = float(np.min(np.linalg.norm(array.world - ue, axis=-1)))
    if gap < lam:
        raise ValueError(
            f"ue: {gap:.3g} m from an element of the array, closer than one wavelength "
            f"({lam:.3g} m): the UE must be in the array's radiating field"
        )
