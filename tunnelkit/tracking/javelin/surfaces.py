"""VUEs from known surfaces (ours): a tracker that knows its tunnel's planes places a new VUE at
the mirror image of the UE estimate instead of learning it from the path's angles.

Algorithm 3 places a VUE where the path's arrival ray meets the plane ``x = x_u`` and learns the
surface over the drive; a design knows its tunnel, so a path from a known surface says where the
UE is as directly as the LoS does. :class:`GeometricBirth` (an initiator role) matches each free
path to the known plane whose mirror of the UE estimate best explains its angles (the smallest
normalised angle innovation, gated at ``probability``) and appends the VUE at
``v = M_s p_u - 2 o_s n_s`` (``M_s = I - 2 n_s n_s^T``, plane ``n_s . p + o_s = 0`` with
``n_s`` across the tunnel), its covariance and cross-covariance mapped through the reflection
(``M P_uu M^T``, ``M P_u,:``): the new VUE is tied to the UE, and with ``MirrorMotion`` it moves
by the mirrored displacement under the same speed/heading noise, so it stays tied (a reduced
state up to the VUE random walk). A path no known plane explains (a vehicle, a surface missing
from the model) is born from its angles as :class:`~.measuredbirth.MeasuredBirth` does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._validate import finite_array, instance, integer, positive, probability, vector
from ...geometry import spherical_jacobian
from ..gating import ChiSquareGate
from .config import JavelinConfig
from .measuredbirth import MeasuredBirth
from .measurement import PathMeasurements
from .state import JavelinState

__all__ = ["AMBIGUOUS", "GeometricBirth", "mirror_vue"]

#: :meth:`GeometricBirth.match` when two planes explain a path about equally well
AMBIGUOUS = -1


def mirror_vue(state: JavelinState, normal, offset: float) -> tuple[np.ndarray, np.ndarray]:
    """``(y, z)`` (2,) of the UE estimate mirrored in the plane ``normal . p + offset = 0``
    (``normal`` (3,) unit, no component along the tunnel) and the map ``d(y_v, z_v)/d s``
    (2, D) of the whole state (only the UE's ``y, z`` enter)."""
    instance("state", state, JavelinState)
    n = finite_array("normal", normal, shape=(3,))
    if abs(np.linalg.norm(n) - 1.0) > 1e-9 or abs(n[0]) > 1e-9:
        raise ValueError(f"normal: expected a unit normal across the tunnel (n_x = 0), got {n}")
    offset = finite_array("offset", offset, ndim=0)
    m = n[1:]
    M = np.eye(2) - 2.0 * np.outer(m, m)
    yz = M @ state.x[1:3] - 2.0 * float(offset) * m
    A = np.zeros((2, state.dim))
    A[:, 1:3] = M
    return yz, A


def _empty(v) -> bool:
    return isinstance(v, tuple | list) and not len(v)


@dataclass(frozen=True)
class GeometricBirth(MeasuredBirth):
    """Births at the mirror image of the UE in a known plane (module docstring). ``normals``
    (S, 3) unit normals across the tunnel and ``offsets`` (S,) [m] of the planes
    ``n . p + o = 0`` in the tracker's coordinates; ``probability``: the angle gate that decides
    whether a plane explains a path (2 degrees of freedom). ``update_at_birth`` defaults to
    True: the VUE was not placed by its path, so the path's information is new. ``margin``:
    a path two planes explain within this difference of ``d2`` is not born until one wins
    (a small array's angles do not tell a wall from a road marking a few degrees away). ``acquire``:
    the tracker's first epoch starts with an iterated fix on the shortest path
    (:func:`~.iterated.first_fix`), so the VUEs are placed from a UE on the LoS ray."""

    normals: tuple = ()
    offsets: tuple = ()
    probability: float = 0.9999
    update_at_birth: bool = True
    acquire: bool = True
    margin: float = 9.0

    def __post_init__(self) -> None:
        super().__post_init__()
        n = (
            np.zeros((0, 3))
            if _empty(self.normals)
            else finite_array("normals", self.normals, ndim=2)
        )
        if n.shape[1] != 3:
            raise ValueError(f"normals: expected (S, 3) unit normals, got shape {n.shape}")
        o = np.zeros(0) if _empty(self.offsets) else finite_array("offsets", self.offsets, ndim=1)
        if n.shape[0] != o.size:
            raise ValueError(
                f"normals, offsets: expected one offset per normal, got {n.shape[0]} normals "
                f"and {o.size} offsets"
            )
        if n.size and (
            np.any(np.abs(np.linalg.norm(n, axis=1) - 1.0) > 1e-9) or np.any(np.abs(n[:, 0]) > 1e-9)
        ):
            raise ValueError("normals: expected unit normals across the tunnel (n_x = 0)")
        probability("probability", self.probability)
        positive("margin", self.margin)
        if not isinstance(self.acquire, bool):
            raise TypeError(f"acquire: expected True or False, got {self.acquire!r}")
        object.__setattr__(self, "normals", tuple(map(tuple, n.tolist())))
        object.__setattr__(self, "offsets", tuple(o.tolist()))

    @classmethod
    def from_planes(cls, planes, **kw) -> GeometricBirth:
        """From :class:`tunnelkit.geometry.Plane` objects (or anything with ``normal`` (3,) and
        ``offset``); planes with a component of their normal along the tunnel are left out (a
        VUE of JAVELIN shares the UE's ``x``)."""
        if isinstance(planes, str | bytes) or not hasattr(planes, "__iter__"):
            raise TypeError(f"planes: expected a list of planes, got {type(planes).__name__}")
        planes = list(planes)
        if not planes or not all(hasattr(p, "normal") and hasattr(p, "offset") for p in planes):
            raise ValueError("planes: expected at least one plane with a normal and an offset")
        keep = [p for p in planes if abs(float(np.asarray(p.normal, float)[0])) <= 1e-9]
        return cls(
            normals=tuple(tuple(float(v) for v in p.normal) for p in keep),
            offsets=tuple(float(p.offset) for p in keep),
            **kw,
        )

    def match(self, state, meas: PathMeasurements, j: int, config: JavelinConfig, noise, ref=None):
        """The plane index whose mirror of the UE explains path ``j`` best within the gate, or
        ``None`` (:meth:`match_distance`)."""
        return self.match_distance(state, meas, j, config, noise, ref)[0]

    def inside(self, p, bs) -> bool:
        """Whether ``p`` (3,) lies on the base station's side of every known plane."""
        p, bs = vector("p", p, 3), vector("bs", bs, 3)
        n = np.asarray(self.normals, float).reshape(-1, 3)
        o = np.asarray(self.offsets, float)
        return bool(np.all((n @ p + o) * (n @ bs + o) > 0))

    def match_distance(
        self, state, meas: PathMeasurements, j: int, config: JavelinConfig, noise, ref=None
    ):
        """``(plane, d2)``: the plane whose mirror image of the UE explains path ``j`` best and
        the squared normalised innovation of its angles and, with a LoS path ``ref``, of its
        delay difference ``d_j - d_ref`` (the UE's uncertainty mapped through the mirror), gated
        at ``probability``; ``(None, inf)`` when no plane explains the path, ``(AMBIGUOUS,
        d2)`` when a second plane's ``d2`` is within ``margin`` of the best. The delay tells a
        wall from a road marking a few degrees away, which a small array's angles cannot."""
        instance("state", state, JavelinState)
        instance("meas", meas, PathMeasurements)
        instance("config", config, JavelinConfig)
        j = integer("j", j, minimum=0, maximum=len(meas) - 1)
        if ref is not None:
            ref = integer("ref", ref, minimum=0, maximum=len(meas) - 1)
        if not callable(getattr(noise, "covariances", None)):
            raise TypeError(f"noise: expected a measurement-noise role, got {type(noise).__name__}")
        if not self.normals:
            return None, np.inf
        R = noise.covariances(meas, config)[j, :2, :2]
        z = [meas.phi[j], meas.psi[j]]
        use_d = ref is not None and ref != j and np.isfinite(meas.d[j]) and np.isfinite(meas.d[ref])
        if use_d:
            Rd = float(noise.tdoa_covariance(meas, [j], ref, config)[0, 0])
            R = np.block([[R, np.zeros((2, 1))], [np.zeros((1, 2)), np.array([[Rd]])]])
            z.append(meas.d[j] - meas.d[ref])
        z = np.asarray(z, float)
        gate = ChiSquareGate(self.probability).threshold(z.size)
        u = state.x[:3]
        qu = u - config.bs
        Puu = state.P[:3, :3]
        cands = []
        for s, (n, o) in enumerate(zip(self.normals, self.offsets, strict=True)):
            yz, A = mirror_vue(state, n, o)
            q = np.array([u[0], yz[0], yz[1]]) - config.bs
            D = np.eye(3)
            D[1:, 1:] = A[:, 1:3]  # d VUE / d UE
            try:
                Js = spherical_jacobian(q) @ D  # d(phi, psi, r) / d UE
            except ValueError:
                continue
            h = [np.arctan2(q[1], q[0]), np.arctan2(q[2], np.hypot(q[0], q[1]))]
            H = Js[:2]
            if use_d:
                h.append(np.linalg.norm(q) - np.linalg.norm(qu))
                H = np.vstack([H, Js[2] - qu / np.linalg.norm(qu)])
            y = z - np.asarray(h)
            y[0] = (y[0] + np.pi) % (2 * np.pi) - np.pi
            S = H @ Puu @ H.T + R
            try:
                d2 = float(y @ np.linalg.solve(0.5 * (S + S.T), y))
            except np.linalg.LinAlgError:
                continue
            if d2 <= gate:
                cands.append((d2, s))
        if not cands:
            return None, np.inf
        cands.sort()
        if len(cands) > 1 and cands[1][0] - cands[0][0] < self.margin:
            return AMBIGUOUS, cands[0][0]
        return cands[0][1], cands[0][0]

    def place(self, state, meas: PathMeasurements, j: int, config: JavelinConfig, noise, ref=None):
        """``(yz, cov, cross, bias_cross)`` of the VUE born from path ``j`` at the mirror of the
        UE in the matched plane, or ``None`` when no known plane explains the path (the caller
        then births it from its angles). ``bias_cross`` (2, 4 L_hat + 4) with a consider
        cross-covariance ``C``: the UE's bias cross-covariance mirrored, zero for the new
        track's own bias (it did not place the VUE). ``ref``: the epoch's LoS path (its delay
        helps the match)."""
        s = self.match(state, meas, j, config, noise, ref)
        if s is None:
            return None
        if s == AMBIGUOUS:  # not born this epoch: the UE's next estimate decides
            return None, None, None, None
        yz, A = mirror_vue(state, self.normals[s], self.offsets[s])
        cross = A @ state.P
        cov = cross @ A.T
        bias_cross = None
        if state.C is not None:
            bias_cross = np.zeros((2, state.C.shape[1] + 4))
            bias_cross[:, :-4] = A @ state.C
        return yz, 0.5 * (cov + cov.T), cross, bias_cross
