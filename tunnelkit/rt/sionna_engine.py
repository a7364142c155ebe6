"""Sionna RT as a second propagation engine, returning :class:`tunnelkit.propagation.Path` lists.

The image method (:func:`tunnelkit.propagation.trace_paths`) mirrors the vehicle (UE) in every
surface. Here the same tunnel, exported to Mitsuba (:mod:`tunnelkit.rt.mitsuba`), is ray-traced by
Sionna RT (shoot-and-bounce candidates, then Sionna's own image-method refinement, float32): a
path is LoS or one specular bounce, exactly the families of the image method.

Set-up (uplink, as in the paper): the UE is the single-antenna transmitter with its velocity, and
**every antenna of the base-station array is a single-antenna receiver placed at its world
position**. That sidesteps Sionna's ``PlanarArray`` conventions (elements in the local y-z plane,
its own element order) and gives, per antenna, an independently traced path length. From
Sionna's output (per receiver ``m``: delay ``tau_m``, arrival angles ``theta_r, phi_r``,
interaction vertex, object id, Doppler, complex coefficient ``a``) each path becomes a ``Path``:

* ``lengths[m] = c tau_m``, ``length = lengths[0]`` (the reference antenna);
* ``direction`` = the unit vector of Sionna's arrival angles at antenna 0; ``source`` (the VUE) =
  ``p_0 + length * direction`` (the unfolded path), ``point`` = Sionna's interaction vertex;
* ``doppler`` = Sionna's Doppler shift, ``velocity = c doppler / fc``, ``range_rate = -velocity``
  (the same sign convention as the image method: positive Doppler when the path shortens);
* ``gain = a exp(-j 2 pi fc tau)`` (Sionna's ``a`` excludes the carrier phase); with isotropic,
  vertically polarised antennas ``reflection_coefficient = gain 4 pi length / lambda
  exp(+j 2 pi length / lambda)`` is Sionna's full-polarimetric ITU-slab coefficient (the image
  method uses the TE Fresnel coefficient, so gains of reflected paths differ by design).

The same ``kinds`` and ``front_only`` filters as the image method apply. A path that Sionna finds
at the reference antenna but not at some other antenna (the specular point slides off the edge of
a plate across the array) keeps the spherical-wavefront length from its VUE for those antennas;
:attr:`SionnaEngine.last_gaps` counts them and :attr:`SionnaEngine.last_traced` maps each
path ``(kind, surface)`` to the (M,) mask of antennas at which Sionna traced it.

Every path, per element (the ray-traced channel): :meth:`SionnaEngine.apply_settings` gives the
shapes the materials, scattering coefficients and lobe of a
:class:`~tunnelkit.rt.settings.RTSettings` and the element receivers their pattern (oriented
along the array's boresight); :meth:`SionnaEngine.trace_elements` then returns everything Sionna
traces up to ``max_depth`` (LoS, specular of any order, diffuse) as an
:class:`~tunnelkit.rt.elements.ElementPaths`, which :mod:`tunnelkit.rt.cache` turns into eq. 1's
tensor. With the settings' ``array_tracing`` other than ``"element"`` it traces one receiver at the
array's centroid instead and carries that ray set to every element (:func:`_carry`: spherical
waves from each path's unfolded source, or Sionna's synthetic array's plane-wave phases).
"""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike
from pathlib import Path as FsPath

import numpy as np

from .._physical import carrier
from .._validate import boolean, choice, integer, sequence, vector
from ..arrays import ArrayGeometry
from ..constants import C, wavelength
from ..propagation import Path, Tunnel3D, arrival_angles
from . import require_sionna
from .elements import ElementPaths
from .mitsuba import MitsubaScene, SceneError, export_tunnel, read_scene
from .settings import RTSettings

__all__ = ["SionnaEngine", "load_sionna_scene"]

_ALL_KINDS = ("los", "wall", "ceiling", "road", "rrm")


def load_sionna_scene(scene: MitsubaScene | str | FsPath, *, fc: float):
    """Load a Mitsuba XML into a ``sionna.rt.Scene`` with ``merge_shapes=False``.

    Raises :class:`~tunnelkit.rt.mitsuba.SceneError` when the file does not parse, references
    missing meshes or materials, or has no surfaces; ``ImportError`` when the ``rt`` extra is
    missing.
    """
    require_sionna()
    import sionna.rt as srt

    ms = scene if isinstance(scene, MitsubaScene) else read_scene(scene)
    try:
        sc = srt.load_scene(str(ms.xml), merge_shapes=False)
    except Exception as exc:  # Mitsuba raises RuntimeError with its own parser message
        msg = str(exc).strip().splitlines()
        raise SceneError(
            f"scene file {str(ms.xml)!r} could not be loaded by Mitsuba: "
            f"{msg[-1] if msg else type(exc).__name__}"
        ) from None
    if not sc.objects:
        raise SceneError(f"scene file {str(ms.xml)!r} has no surfaces Sionna can trace")
    sc.frequency = carrier("fc", fc)
    return sc


@dataclass
class _RawPaths:
    """Sionna's output reduced to numpy, one row per (path key, antenna)."""

    tau: np.ndarray  # (M, P)
    valid: np.ndarray  # (M, P) bool
    obj: np.ndarray  # (M, P) uint32 object id of the bounce, INVALID for LoS
    inter: np.ndarray  # (M, P) interaction type of the first vertex
    vertex: np.ndarray  # (M, P, 3)
    theta: np.ndarray  # (M, P)
    phi: np.ndarray  # (M, P)
    doppler: np.ndarray  # (M, P)
    a: np.ndarray  # (M, P) complex


def _p3(kind, v):
    return kind(*(float(x) for x in v))


def _carry(tau, a, u, offsets, fc: float, how: str) -> tuple[np.ndarray, np.ndarray]:
    """One ray set traced at the array's centroid (delays ``tau`` (P,), coefficients ``a`` (P,)
    without the carrier phase, arrival directions ``u`` (P, 3)) carried to the elements at
    ``offsets`` (M, 3) from the centroid: ``(tau (M, P), a (M, P))``. ``"centre"``: a spherical
    wave from each path's unfolded source ``c tau u`` (the element's own distance to it as its
    delay, the coefficient unchanged); ``"synthetic"``: Sionna's synthetic array, the same delay
    at every element and the plane-wave phase ``exp(+j k0 u . offset)`` (the element nearer the
    source by ``u . offset`` sees the carrier earlier)."""
    src = C * tau[:, None] * u  # (P, 3) unfolded sources, from the centroid
    if how == "centre":
        tau_m = np.linalg.norm(src[None] - offsets[:, None], axis=-1) / C
        return tau_m, np.broadcast_to(a, tau_m.shape).copy()
    phase = np.exp(2j * np.pi * fc / C * (offsets @ u.T))  # (M, P)
    return np.broadcast_to(tau, phase.shape).copy(), a[None] * phase


class SionnaEngine:
    """Trace LoS + single-bounce paths in one tunnel with Sionna RT; reuse it across epochs.

    Parameters
    ----------
    tunnel : a :class:`~tunnelkit.propagation.Tunnel3D` (exported to ``workdir``), or a path to a
        user's Mitsuba XML / a :class:`~tunnelkit.rt.mitsuba.MitsubaScene`
    fc : carrier frequency [Hz]
    samples_per_src : rays shot from the UE (deterministic Fibonacci directions); small plates
        need about 1e5 or more
    max_num_paths_per_src : path budget per source, shared by all receivers (antennas): at least
        (number of paths) x M or paths go missing silently; ``None`` = ``max(1000, 100 M)``
    workdir : where the export goes (a temporary directory by default)
    """

    def __init__(
        self,
        tunnel,
        *,
        fc: float,
        samples_per_src: int = 100_000,
        max_num_paths_per_src: int | None = None,
        workdir=None,
    ) -> None:
        if workdir is not None and not isinstance(workdir, str | PathLike):
            raise TypeError(f"workdir: expected a directory name, got {type(workdir).__name__}")
        require_sionna()
        import sionna.rt as srt

        self.fc = carrier("fc", fc)
        self.samples_per_src = integer("samples_per_src", samples_per_src, minimum=1)
        self.max_num_paths_per_src = (
            None
            if max_num_paths_per_src is None
            else integer("max_num_paths_per_src", max_num_paths_per_src, minimum=1)
        )
        self.tunnel = tunnel if isinstance(tunnel, Tunnel3D) else None
        if isinstance(tunnel, Tunnel3D):
            if workdir is None:
                import tempfile

                self._tmp = tempfile.TemporaryDirectory(prefix="tunnelkit-rt-")
                workdir = self._tmp.name
            self.mitsuba = export_tunnel(tunnel, workdir)
        elif isinstance(tunnel, MitsubaScene):
            self.mitsuba = tunnel
        elif isinstance(tunnel, str | PathLike):
            try:
                self.mitsuba = read_scene(tunnel)
            except SceneError as exc:  # name the parameter the file came in
                raise SceneError(f"tunnel: {exc}") from None
        else:
            raise TypeError(
                "tunnel: expected a propagation.Tunnel3D, a MitsubaScene or a path to "
                f"a Mitsuba XML, got {type(tunnel).__name__}"
            )
        self.scene = load_sionna_scene(self.mitsuba, fc=self.fc)
        self.scene.tx_array = srt.PlanarArray(
            num_rows=1, num_cols=1, pattern="iso", polarization="V"
        )
        self.scene.rx_array = srt.PlanarArray(
            num_rows=1, num_cols=1, pattern="iso", polarization="V"
        )
        by_name: dict[str, tuple[str, str]] = {}
        for sid, info in self.mitsuba.surfaces.items():  # the first shape of a name wins
            by_name.setdefault(srt.SceneObject.shape_id_to_name(sid), (info.name, info.kind))
        self._surface_by_id: dict[int, tuple[str, str]] = {
            int(obj.object_id): by_name.get(name, (name, "surface"))
            for name, obj in self.scene.objects.items()
        }
        self._solver = srt.PathSolver(deterministic=True)
        self._n_rx = 0
        self.last_gaps = 0
        self.last_traced: dict[tuple[str, str], np.ndarray] = {}

    # --- every path, per element ---------------------------------------------------------------
    def apply_settings(self, settings: RTSettings) -> None:
        """Give every shape the material of ``settings`` for its kind (ITU type, slab thickness,
        scattering coefficient and lobe; :class:`~tunnelkit.rt.settings.RTSettings`) and every
        element receiver its antenna pattern, oriented along the array's boresight."""
        import sionna.rt as srt

        if not isinstance(settings, RTSettings):
            raise TypeError(f"settings: expected an RTSettings, got {type(settings).__name__}")
        made: dict[str, object] = {}
        for obj in self.scene.objects.values():
            _, kind = self._surface_by_id.get(int(obj.object_id), ("", "surface"))
            name, itu, thickness, s = settings.material_for(kind)
            tag = f"tk-{name}-{settings.fingerprint()[:12]}"  # one per material and settings
            if made.get(name) is None:
                made[name] = self.scene.get(tag)
            if made[name] is None:
                extra = (
                    {"alpha_r": settings.alpha_r}
                    if settings.scattering_pattern == "directive"
                    else {}
                )
                made[name] = srt.ITURadioMaterial(
                    tag,
                    itu,
                    thickness=thickness,
                    scattering_coefficient=s,
                    scattering_pattern=settings.scattering_pattern,
                    **extra,
                )
            obj.radio_material = made[name]
        self.scene.rx_array = srt.PlanarArray(
            num_rows=1, num_cols=1, pattern=settings.antenna_pattern, polarization="V"
        )
        self.settings = settings

    def trace_elements(self, array: ArrayGeometry, ue, ue_velocity=(0.0, 0.0, 0.0)) -> ElementPaths:
        """Every path Sionna returns from ``ue`` to each element of ``array`` (LoS, specular of
        any order up to the settings' ``max_depth``, diffuse), as an
        :class:`~tunnelkit.rt.elements.ElementPaths`; call :meth:`apply_settings` first."""
        import mitsuba as mi
        from sionna.rt.constants import InteractionType

        st = getattr(self, "settings", None)
        if st is None:
            raise RuntimeError("trace_elements: call apply_settings(settings) first")
        if not isinstance(array, ArrayGeometry):
            raise TypeError(f"array: expected an arrays.ArrayGeometry, got {type(array).__name__}")
        ue = vector("ue", ue, 3)
        vel = vector("ue_velocity", ue_velocity, 3)
        if self.tunnel is not None:
            ue = self.tunnel.require_inside("ue", ue)
        per_element = st.array_tracing == "element"
        centre = array.world.mean(axis=0)
        self._place(array, ue, vel, None if per_element else centre[None])
        b = array.boresight
        yaw, pitch = float(np.arctan2(b[1], b[0])), float(-np.arcsin(np.clip(b[2], -1, 1)))
        for m in range(self._n_rx):
            self.scene.get(f"ant-{m}").orientation = mi.Point3f(yaw, pitch, 0.0)
        p = self._solver(
            self.scene,
            max_depth=st.max_depth,
            max_num_paths_per_src=10_000_000,
            samples_per_src=st.samples_per_src,
            synthetic_array=False,
            los=True,
            specular_reflection=True,
            diffuse_reflection=st.diffuse,
            refraction=False,
            diffraction=False,
        )

        def sq(x) -> np.ndarray:
            return np.asarray(x.numpy())[:, 0, 0, 0]

        ar, ai = p.a
        tau = sq(p.tau).astype(float)
        inter = np.asarray(p.interactions.numpy())[:, :, 0, 0, 0]  # (depth, M, P)
        valid = sq(p.valid).astype(bool)
        a = sq(ar) + 1j * sq(ai)
        doppler = sq(p.doppler).astype(float)
        order = np.sum(inter != InteractionType.NONE, axis=0)
        diffuse = np.any(inter == InteractionType.DIFFUSE, axis=0)
        first = np.asarray(p.objects.numpy())[0, :, 0, 0, 0].astype(np.int64)
        if not per_element:  # one ray set at the centroid, carried to every element
            th, ph = sq(p.theta_r).astype(float)[0], sq(p.phi_r).astype(float)[0]
            u = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
            tau, a = _carry(tau[0], a[0], u, array.world - centre, self.fc, st.array_tracing)
            M = array.M
            valid, doppler, order, diffuse, first = (
                np.repeat(x[:1], M, axis=0) for x in (valid, doppler, order, diffuse, first)
            )
        return ElementPaths(
            tau=tau,
            gain=a * np.exp(-2j * np.pi * self.fc * tau),
            doppler=doppler,
            valid=valid,
            order=order,
            diffuse=diffuse,
            first_object=first,
        )

    def surface_of(self, object_id: int) -> tuple[str, str]:
        """``(surface name, kind)`` of a Sionna object id (``("", "los")`` for none)."""
        from sionna.rt.constants import INVALID_SHAPE

        object_id = integer("object_id", object_id, minimum=0)
        if int(object_id) == int(INVALID_SHAPE):
            return "", "los"
        return self._surface_by_id.get(int(object_id), (str(object_id), "surface"))

    # --- devices ------------------------------------------------------------------------------
    def _place(self, array: ArrayGeometry, ue: np.ndarray, vel: np.ndarray, points=None) -> None:
        """The UE as the transmitter and one receiver per element of ``array`` (or per row of
        ``points`` (n, 3), world positions)."""
        import mitsuba as mi
        import sionna.rt as srt

        sc = self.scene
        if "ue" not in sc.transmitters:
            sc.add(
                srt.Transmitter("ue", position=_p3(mi.Point3f, ue), velocity=_p3(mi.Vector3f, vel))
            )
        tx = sc.get("ue")
        tx.position = _p3(mi.Point3f, ue)
        tx.velocity = _p3(mi.Vector3f, vel)
        world = array.world if points is None else np.atleast_2d(points)
        n = world.shape[0]
        while self._n_rx > n:
            self._n_rx -= 1
            sc.remove(f"ant-{self._n_rx}")
        for m in range(n):
            if m >= self._n_rx:
                sc.add(srt.Receiver(f"ant-{m}", position=_p3(mi.Point3f, world[m])))
            else:
                sc.get(f"ant-{m}").position = _p3(mi.Point3f, world[m])
        self._n_rx = n

    def _solve(self) -> _RawPaths:
        from sionna.rt.constants import InteractionType

        budget = self.max_num_paths_per_src or max(1000, 100 * self._n_rx)
        p = self._solver(
            self.scene,
            max_depth=1,
            max_num_paths_per_src=budget,
            samples_per_src=self.samples_per_src,
            synthetic_array=False,
            los=True,
            specular_reflection=True,
            diffuse_reflection=False,
            refraction=False,
            diffraction=False,
        )

        # shapes: (num_rx, num_rx_ant=1, num_tx=1, num_tx_ant=1, P) -> (M, P)
        def sq(x) -> np.ndarray:
            return np.asarray(x.numpy())[:, 0, 0, 0]

        ar, ai = p.a
        raw = _RawPaths(
            tau=sq(p.tau).astype(float),
            valid=sq(p.valid).astype(bool),
            obj=np.asarray(p.objects.numpy())[0, :, 0, 0, 0],
            inter=np.asarray(p.interactions.numpy())[0, :, 0, 0, 0],
            vertex=np.asarray(p.vertices.numpy())[0, :, 0, 0, 0].astype(float),
            theta=sq(p.theta_r).astype(float),
            phi=sq(p.phi_r).astype(float),
            doppler=sq(p.doppler).astype(float),
            a=sq(ar) + 1j * sq(ai),
        )
        bad = (
            raw.valid
            & (raw.inter != InteractionType.NONE)
            & (raw.inter != InteractionType.SPECULAR)
        )
        if np.any(bad):  # cannot happen with the flags above; guard against API changes
            raise RuntimeError("Sionna returned non-specular interactions with max_depth=1")
        return raw

    # --- public -------------------------------------------------------------------------------
    def trace(
        self,
        array: ArrayGeometry,
        ue,
        ue_velocity=(0.0, 0.0, 0.0),
        *,
        kinds: tuple[str, ...] = _ALL_KINDS,
        front_only: bool = True,
    ) -> list[Path]:
        """All LoS and single-bounce paths from ``ue`` to ``array``, as the image method returns them.

        Same arguments, filters and ordering as :func:`tunnelkit.propagation.trace_paths` (LoS
        first, then reflections by length). Paths off blocker boxes are dropped (the image method
        treats boxes as blockers only).
        """
        [choice(f"kinds[{i}]", k, _ALL_KINDS) for i, k in enumerate(sequence("kinds", kinds))]
        boolean("front_only", front_only)
        if not isinstance(array, ArrayGeometry):
            raise TypeError(f"array: expected an arrays.ArrayGeometry, got {type(array).__name__}")
        ue = vector("ue", ue, 3)
        if self.tunnel is not None:
            ue = self.tunnel.require_inside("ue", ue)
            out = ~np.atleast_1d(self.tunnel.contains(array.world))
            if np.any(out):
                top = float(np.max(array.world[:, 2]))
                raise ValueError(
                    f"array: {int(out.sum())} of {array.M} antennas of {array.name or 'the array'} "
                    f"lie outside the tunnel (highest element at z = {top:.3f} m); a ray tracer "
                    "sees them behind the wall. Move the array inside (e.g. a negative z offset "
                    "in [[base_station.arrays]])."
                )
        vel = vector("ue_velocity", ue_velocity, 3)
        self._place(array, ue, vel)
        raw = self._solve()
        return self._to_paths(raw, array, ue, kinds, front_only)

    def _to_paths(self, raw: _RawPaths, array: ArrayGeometry, ue, kinds, front_only) -> list[Path]:
        from sionna.rt.constants import INVALID_SHAPE

        lam = wavelength(self.fc)
        ant = array.world
        los_key = int(INVALID_SHAPE)
        # per antenna: path key (object id, or INVALID for LoS) -> column
        cols = [
            {int(raw.obj[m, j]): j for j in np.flatnonzero(raw.valid[m])} for m in range(array.M)
        ]
        out: list[Path] = []
        gaps = 0
        self.last_traced = {}
        for key, j in cols[0].items():
            is_los = key == los_key
            label, kind = (
                ("", "los") if is_los else self._surface_by_id.get(key, (str(key), "surface"))
            )
            if kind == "blocker" or (kind not in kinds and kind != "surface"):
                continue
            d0 = float(raw.tau[0, j]) * C
            th, ph = raw.theta[0, j], raw.phi[0, j]
            u = np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
            source = array.origin + d0 * u
            point = ue.copy() if is_los else raw.vertex[0, j].copy()
            if front_only and not array.in_front(point):
                continue
            lengths = np.empty(array.M)
            traced = np.zeros(array.M, dtype=bool)
            for m in range(array.M):
                jm = cols[m].get(key)
                if jm is None:
                    lengths[m] = np.linalg.norm(source - ant[m])
                    gaps += 1
                else:
                    lengths[m] = float(raw.tau[m, jm]) * C
                    traced[m] = True
            lengths[0] = d0
            self.last_traced[("los" if is_los else "reflection", label)] = traced
            if is_los:
                lengths_srnf = lengths
            else:
                lengths_srnf = np.linalg.norm(ue - point) + np.linalg.norm(point - ant, axis=-1)
            fd = float(raw.doppler[0, j])
            vel = C * fd / self.fc
            gain = complex(raw.a[0, j] * np.exp(-2j * np.pi * self.fc * raw.tau[0, j]))
            gamma = gain * 4 * np.pi * d0 / lam * np.exp(2j * np.pi * d0 / lam)
            az, el = arrival_angles(u)
            out.append(
                Path(
                    kind="los" if is_los else "reflection",
                    surface=label,
                    surface_kind=kind,
                    source=source,
                    point=point,
                    length=d0,
                    lengths=lengths,
                    lengths_srnf=lengths_srnf,
                    direction=u,
                    direction_local=array.dir_to_local(u),
                    azimuth=az,
                    elevation=el,
                    kappa_srnf=float(np.linalg.norm(point - array.origin)),
                    range_rate=-vel,
                    velocity=vel,
                    doppler=fd,
                    reflection_coefficient=complex(gamma),
                    gain=gain,
                    ue=ue.copy(),
                )
            )
        self.last_gaps = gaps
        los = [p for p in out if p.kind == "los"]
        refl = sorted((p for p in out if p.kind != "los"), key=lambda p: p.length)
        return los + refl
