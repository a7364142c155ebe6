"""Track management of Algorithm 3: deaths after zeta misses, births by intersection, the LoS test
of eq. 60-61 (:mod:`~tunnelkit.tracking.javelin.lostest`) and the Doppler test that tells static
from dynamic reflectors."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._checks import sign as check_sign
from ..._checks import unchecked
from ..._validate import instance, integer, real, record, sequence, vector
from .config import JavelinConfig
from .measurement import PathMeasurements
from .state import JavelinState

__all__ = [
    "FixedBirth",
    "ManageResult",
    "intersection",
    "manage_tracks",
    "static_doppler",
]


def intersection(phi: float, psi: float, x_u: float, bs=(0.0, 0.0, 0.0)) -> np.ndarray | None:
    """``Intersection`` of Algorithm 3: the arrival ray from the base station meets the plane
    ``x = x_u`` (the VUE shares the UE's x). Returns the VUE ``(y, z)`` or ``None`` if the ray
    runs parallel to that plane or points away from it."""
    real("phi", phi), real("psi", psi), real("x_u", x_u)
    b = vector("bs", bs, 3)
    u = np.array([np.cos(psi) * np.cos(phi), np.cos(psi) * np.sin(phi), np.sin(psi)])
    if abs(u[0]) < 1e-6:
        return None
    t = (x_u - b[0]) / u[0]
    if t <= 0:
        return None
    p = b + t * u
    return p[1:].copy()


def static_doppler(p_u, p_v, v_u, bs=(0.0, 0.0, 0.0), sign: float = -1.0) -> float:
    """Radial speed a static reflector would produce: the VUE moves with the UE velocity mirrored
    in the reflecting plane (normal along ``p_v - p_u``); ``p_v = p_u`` means the LoS path.

    Returns ``sign * d||p_v - b||/dt`` (``sign = -1``: positive when approaching)."""
    for name, value in (("p_u", p_u), ("p_v", p_v), ("v_u", v_u), ("bs", bs)):
        vector(name, value, 3)
    sign = check_sign("sign", sign)
    pu, pv, vu = (np.asarray(a, dtype=float) for a in (p_u, p_v, v_u))
    b = np.asarray(bs, dtype=float)
    w = pv - pu
    nw = np.linalg.norm(w)
    vv = vu if nw < 1e-9 else vu - 2.0 * np.dot(w / nw, vu) * (w / nw)
    q = pv - b
    return float(sign * np.dot(q / np.linalg.norm(q), vv))


@dataclass(frozen=True)
class FixedBirth:
    """A new VUE with covariance ``sigma_P^2 I`` (the paper, Algorithm 3); ``update_at_birth``:
    the path that gave birth also updates the state in that epoch (the paper's Algorithm 4);
    ``doppler_sign``: the measured radial speed is ``doppler_sign * d(range)/dt`` in the test
    that tells static from dynamic reflectors (-1: the channel convention ``v = c f_d / f_c``
    with ``f_d > 0`` when approaching)."""

    update_at_birth: bool = True
    doppler_sign: float = -1.0

    def __post_init__(self) -> None:
        if self.doppler_sign not in (-1.0, 1.0):
            raise ValueError(f"doppler_sign: expected +1 or -1, got {self.doppler_sign!r}")
        if not isinstance(self.update_at_birth, bool):
            raise TypeError(
                f"update_at_birth: expected True or False, got {self.update_at_birth!r}"
            )

    def covariance(self, state, meas, j: int, config: JavelinConfig, noise):
        """Covariance (2, 2) of the VUE born from path ``j`` and its cross-covariance (or None)."""
        birth_arguments(state, meas, j, noise)
        instance("config", config, JavelinConfig)
        return np.eye(2) * config.sigma_p0**2, None


@dataclass
class ManageResult:
    """What Algorithm 3 did: pairs to update with, LoS flag/path, born and dead track ids."""

    pairs: list[tuple[int, int]]
    los: bool
    los_path: int | None
    born: list[int] = field(default_factory=list)
    dead: list[int] = field(default_factory=list)
    dynamic: list[int] = field(default_factory=list)
    unborn: list[int] = field(default_factory=list)

    def __post_init__(self) -> None:
        lists = ("pairs", "born", "dead", "dynamic", "unborn")
        record(self, may_be_empty=lists, nonnegative=("los_path",))
        if self.los != (self.los_path is not None):
            raise ValueError(f"los: {self.los} disagrees with los_path = {self.los_path}")


def birth_arguments(state, meas, j, noise) -> None:
    """The arguments every initiator's ``covariance`` takes (a path index into ``meas``)."""
    instance("state", state, JavelinState)
    instance("meas", meas, PathMeasurements)
    integer("j", j, minimum=0, maximum=len(meas) - 1)
    noise_role("noise", noise)


def noise_role(name: str, noise):
    """``None`` (the paper's fixed sigmas) or a measurement-noise role (``covariances``)."""
    if noise is not None and not callable(getattr(noise, "covariances", None)):
        raise TypeError(f"{name}: expected a measurement-noise role, got {type(noise).__name__}")
    return noise


def manage_tracks(
    state: JavelinState,
    meas: PathMeasurements,
    pairs,
    config: JavelinConfig,
    v_u=None,
    *,
    initiator=None,
    noise=None,
) -> ManageResult:
    """Algorithm 3 on ``state`` (modified in place, already predicted).

    1. unassociated VUEs count a miss; at ``misses >= zeta`` they are marginalised out (the UE is
       never removed); associated VUEs reset their counter;
    2. LoS (lines 13-23): the path associated with the UE, else eq. 60-61 among the paths no VUE
       claimed (ours: the paper searches all paths; a claimed path already has a track);
    3. births (lines 8-12): every other unassociated path starts a VUE at the intersection of its
       arrival ray with ``x = x_u`` with the covariance the ``initiator`` role gives
       (``FixedBirth``: ``sigma_P^2 I``, the default; ``MeasuredBirth``:
       :func:`~.measuredbirth.birth_covariance`
       with the ``noise`` role's angle covariance; an initiator with a ``place`` method,
       :class:`~.surfaces.GeometricBirth`, puts the VUE at the UE's mirror image in a known
       plane that explains the path instead); with a UE velocity ``v_u``
       and a Doppler ``v``, a path whose Doppler misses the static prediction by more than
       ``doppler_tolerance`` is dynamic: its track is ``transient`` (dropped after this epoch);
       the born path also updates the state this epoch when ``initiator.update_at_birth``.

    Returned ``pairs`` use the track indices after removals and births.
    """
    instance("state", state, JavelinState)
    instance("meas", meas, PathMeasurements)
    instance("config", config, JavelinConfig)
    sequence("pairs", pairs, empty=True), noise_role("noise", noise)
    if v_u is not None:
        vector("v_u", v_u, 3)
    initiator = FixedBirth() if initiator is None else instance("initiator", initiator, FixedBirth)
    pairs = [(int(i), int(j)) for i, j in pairs]
    assoc_tracks = {i for i, _ in pairs}
    assoc_paths = {j for _, j in pairs}
    # 1. misses and deaths
    to_remove = []
    for k in range(state.n_vue):
        i = k + 1
        if i in assoc_tracks:
            state.misses[k] = 0
        else:
            state.misses[k] += 1
            if state.misses[k] >= config.max_misses:
                to_remove.append(i)
    state.ue_misses = 0 if 0 in assoc_tracks else state.ue_misses + 1
    # re-index the surviving pairs before marginalising
    old_to_new = {}
    new = 1
    for i in range(1, state.n_vue + 1):
        if i not in to_remove:
            old_to_new[i] = new
            new += 1
    old_to_new[0] = 0
    dead = state.remove(to_remove)
    pairs = [(old_to_new[i], j) for i, j in pairs if i in old_to_new]
    # 2. LoS
    los_path = next((j for i, j in pairs if i == 0), None)
    free = [j for j in range(len(meas)) if j not in assoc_paths]
    if los_path is None:
        from .lostest import los_test  # no path associated with the UE

        los_path = los_test(meas.d, meas.kappa, config.los_gamma, candidates=free)
        if los_path is not None:
            pairs.append((0, los_path))
            free.remove(los_path)
    # 3. births
    born, dynamic, unborn = [], [], []
    for j in free:
        placed = None
        if callable(getattr(initiator, "place", None)):  # VUEs from known surfaces
            placed = initiator.place(state, meas, j, config, noise, ref=los_path)
            if placed is not None and placed[0] is None:  # two surfaces explain it: wait
                unborn.append(j)
                continue
        yz = intersection(meas.phi[j], meas.psi[j], state.x[0], config.bs)
        if placed is not None:
            yz = placed[0]
        if yz is None:
            unborn.append(j)
            continue
        transient = False
        if v_u is not None and np.isfinite(meas.v[j]):
            p_v = np.array([state.x[0], yz[0], yz[1]])
            v_pred = static_doppler(state.ue, p_v, v_u, config.bs, initiator.doppler_sign)
            transient = abs(meas.v[j] - v_pred) > config.doppler_tolerance
        if placed is not None:
            _, cov, cross, bias_cross = placed
            if not getattr(noise, "consider", False):
                bias_cross = None
        else:
            cov, cross = initiator.covariance(state, meas, j, config, noise)
            bias_cross = None
            if state.C is not None and cross is not None and getattr(noise, "consider", False):
                from .linearbirth import birth_bias_cross  # a bias-aware tracker's measured birth

                bias_cross = birth_bias_cross(state, meas, j, config, noise)
        tid = state.append(yz, cov, transient=transient, cross=cross, bias_cross=bias_cross)
        born.append(tid)
        if transient:
            dynamic.append(tid)
        if initiator.update_at_birth:
            pairs.append((state.n_vue, j))
    return unchecked(
        ManageResult, sorted(pairs), los_path is not None, los_path, born, dead, dynamic, unborn
    )
