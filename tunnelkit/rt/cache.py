"""The ray-traced channel of a drive, traced once per epoch and cached on disk.

:class:`RayTracedChannel` traces every epoch of a trajectory with Sionna RT
(:meth:`~tunnelkit.rt.sionna_engine.SionnaEngine.trace_elements`: every path per element, LoS,
specular of any order, diffuse) and stores the noiseless tensor of eq. 1's form
(:func:`~tunnelkit.rt.elements.element_tensor`, unit transmit power, no clock bias) without the
LoS, plus the LoS path per element (so a blocked-LoS epoch drops it), the power per kind of path
and the trace time. Noise and clock bias are drawn per run on top
(:func:`tunnelkit.signal_route.raytraced.tensor_snapshot`), so a 20-run table traces each epoch once.

Cache layout: ``<cache_dir>/<label>/<rrms|no-rrms>/meta.json`` and ``epoch-NNN.npz``.
``cache_dir`` is ``$TUNNELKIT_RT_CACHE`` if set, else ``~/.cache/tunnelkit/rt``. ``meta.json``
holds the key: a hash of everything that changes the trace (the exported scene's XML and
meshes, the :class:`~tunnelkit.rt.settings.RTSettings`, the arrays' element positions, the
trajectory, the tensor's tones and symbols, the cache format and the sionna-rt version). A
directory written under another key (another version of the scene) is detected, emptied and
rebuilt, never reused: only the cache's own files in that directory are removed.

Nothing read is trusted: every epoch file is checked on load (its keys, shapes against the
radio and the array, finite values, the kinds of path); a truncated, foreign or non-finite file
is traced again with a warning naming it, or refused naming it when it cannot be. A label is a
plain name, and a directory that resolves outside ``cache_dir`` (a symbolic link) is refused.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import tempfile
import time
import warnings
from pathlib import Path as FsPath

import numpy as np

from .._validate import boolean, instance, integer, positive, sequence
from .elements import ElementPaths, element_tensor
from .mitsuba import export_tunnel
from .settings import RTSettings

__all__ = ["CACHE_ENV", "FORMAT", "RayTracedChannel", "default_cache_dir"]

#: environment variable naming the cache directory
CACHE_ENV = "TUNNELKIT_RT_CACHE"
#: version of the cache's file format (part of the key; 2: the tensor's tones centred on the
#: carrier, :func:`~tunnelkit.rt.elements.element_tensor`)
FORMAT = 2
#: a cache label: a plain name (no separator, no leading dot, so no ``..``)
_LABEL = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+-]{0,99}")
#: the files the cache writes in a directory (all it ever removes)
_OWN = re.compile(r"(meta\.json|\.meta-\d+\.json|epoch-\d{3,}\.npz|\.epoch-\d{3,}-\d+\.npz)")
#: the kinds of path whose power and count an epoch file stores
_KINDS = ("los", "specular1", "specular2+", "diffuse")
_FIELDS = ("array", "H", "los_tau", "los_gain", "los_doppler", "los_valid", "power_json",
           "count_json", "trace_s", "synth_s")  # fmt: skip


def default_cache_dir() -> FsPath:
    """``$TUNNELKIT_RT_CACHE`` or ``~/.cache/tunnelkit/rt``."""
    env = os.environ.get(CACHE_ENV)
    return FsPath(env) if env else FsPath.home() / ".cache" / "tunnelkit" / "rt"


def _sionna_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("sionna-rt")
    except PackageNotFoundError:
        return "absent"


def _digest(*parts) -> str:
    h = hashlib.sha256()
    for p in parts:
        h.update(p if isinstance(p, bytes) else np.ascontiguousarray(p, float).tobytes())
    return h.hexdigest()


def scene_hash(tunnel) -> str:
    """Hash of ``tunnel`` as exported for Sionna (XML and every mesh file)."""
    with tempfile.TemporaryDirectory(prefix="tunnelkit-rt-hash-") as tmp:
        export_tunnel(tunnel, tmp, name="scene")
        files = sorted(FsPath(tmp).rglob("*"))
        return _digest(
            *(f.relative_to(tmp).as_posix().encode() + f.read_bytes() for f in files if f.is_file())
        )


class RayTracedChannel:
    """Ray-traced tensors of one drive (module docstring), built lazily, cached on disk.

    Parameters
    ----------
    tunnel : the scenario's :class:`~tunnelkit.propagation.Tunnel3D`
    arrays : its arrays (the one facing the vehicle is used per epoch, as in the image route)
    trajectory : the drive (positions and velocities per epoch)
    config : the :class:`~tunnelkit.channel.SRSConfig` (carrier, tones, symbols)
    settings : :class:`~tunnelkit.rt.settings.RTSettings`
    label : the cache subdirectory (the scenario name)
    cache_dir : where the cache lives (:func:`default_cache_dir` by default)
    """

    def __init__(
        self,
        tunnel,
        arrays,
        trajectory,
        config,
        settings: RTSettings | None = None,
        *,
        label: str = "custom",
        cache_dir=None,
    ) -> None:
        from ..arrays import ArrayGeometry
        from ..propagation import Tunnel3D
        from ..scenarios import Trajectory

        instance("tunnel", tunnel, Tunnel3D)
        for i, a in enumerate(sequence("arrays", arrays)):
            instance(f"arrays[{i}]", a, ArrayGeometry)
        instance("trajectory", trajectory, Trajectory)
        if cache_dir is not None:
            instance("cache_dir", cache_dir, (str, os.PathLike), "a directory name")
        need = ("fc", "tone_spacing", "n_tones", "symbol_period", "n_symbols")
        if not all(hasattr(config, a) for a in need):
            raise TypeError(f"config: expected a channel.SRSConfig, got {type(config).__name__}")
        settings = RTSettings() if settings is None else settings
        if not isinstance(settings, RTSettings):
            raise TypeError(f"settings: expected an RTSettings, got {type(settings).__name__}")
        settings.check_carrier(config.fc)
        if not isinstance(label, str) or not _LABEL.fullmatch(label):
            raise ValueError(
                "label: expected a plain name (letters, digits, '_', '.', '+', '-', not starting "
                f"with '.', at most 100 characters), got {label!r}"
            )
        self.tunnel, self.arrays, self.trajectory = tunnel, list(arrays), trajectory
        self.config, self.settings, self.label = config, settings, label
        self.cache_dir = default_cache_dir() if cache_dir is None else FsPath(cache_dir)
        self._engines: dict[str, object] = {}
        self._checked: dict[str, FsPath] = {}
        self._memo: dict[tuple[str, int], dict] = {}

    # --- key and directory --------------------------------------------------------------------
    def key(self, tunnel=None) -> dict:
        """Everything the trace of ``tunnel`` (this drive's by default) depends on, hashed."""
        tun = self._tunnel(tunnel)
        cfg = self.config
        return {
            "format": FORMAT,
            "sionna_rt": _sionna_version(),
            "scene": scene_hash(tun),
            "settings": self.settings.fingerprint(),
            "arrays": _digest(
                *(a.world for a in self.arrays), "|".join(a.name for a in self.arrays).encode()
            ),
            "trajectory": _digest(self.trajectory.position, self.trajectory.velocity),
            "radio": [cfg.fc, cfg.tone_spacing, cfg.n_tones, cfg.symbol_period, cfg.n_symbols],
        }

    def _tunnel(self, tunnel):
        """``tunnel`` (this drive's when None), checked: a :class:`Tunnel3D`."""
        from ..propagation import Tunnel3D

        return self.tunnel if tunnel is None else instance("tunnel", tunnel, Tunnel3D)

    @staticmethod
    def variant(tunnel) -> str:
        """The cache subdirectory of ``tunnel``: "rrms" with road markings, else "no-rrms"."""
        from ..propagation import Tunnel3D

        instance("tunnel", tunnel, Tunnel3D)
        return "rrms" if getattr(tunnel, "plates", ()) else "no-rrms"

    def _inside(self, d: FsPath) -> FsPath:
        """``d`` if it resolves inside the cache directory, else ``ValueError`` naming both (a
        symbolic link out of the cache is never followed to write or delete)."""
        root = self.cache_dir.resolve()
        if not d.resolve().is_relative_to(root):
            raise ValueError(
                f"label: the cache directory {d} resolves to {d.resolve()}, outside the cache "
                f"{root} (a symbolic link?)"
            )
        return d

    def directory(self, tunnel=None) -> FsPath:
        """The checked cache directory of ``tunnel`` (emptied first if written under another key)."""
        tun = self._tunnel(tunnel)
        var = self.variant(tun)
        if var in self._checked:
            return self._checked[var]
        d = self._inside(self.cache_dir / self.label / var)
        key = self.key(tun)
        meta = d / "meta.json"
        if meta.is_file():
            try:
                old = json.loads(meta.read_text())
            except (ValueError, OSError):
                old = None
            if old != key:
                warnings.warn(
                    f"ray-tracing cache {d} was written for another scene, settings or drive; "
                    "rebuilding it",
                    stacklevel=2,
                )
                for f in d.iterdir():  # the cache's own files only, never a link's target
                    if _OWN.fullmatch(f.name) and (f.is_symlink() or f.is_file()):
                        f.unlink()
        if not meta.is_file():
            d.mkdir(parents=True, exist_ok=True)
            tmp = d / f".meta-{os.getpid()}.json"
            tmp.write_text(json.dumps(key, indent=1, sort_keys=True))
            os.replace(tmp, meta)
        self._checked[var] = d
        return d

    # --- tracing ------------------------------------------------------------------------------
    def engine(self, tunnel=None):
        """The Sionna engine of ``tunnel`` with this channel's settings (built on first use)."""
        from .sionna_engine import SionnaEngine

        tun = self._tunnel(tunnel)
        var = self.variant(tun)
        if var not in self._engines:
            eng = SionnaEngine(tun, fc=self.config.fc)
            eng.apply_settings(self.settings)
            self._engines[var] = eng
        return self._engines[var]

    def trace(self, k: int, tunnel=None) -> tuple[object, ElementPaths, float]:
        """Trace epoch ``k`` now (no cache): the array, the :class:`ElementPaths` and the seconds
        the trace took."""
        from ..propagation import select_array

        k = integer("k", k, minimum=0, maximum=len(self.trajectory) - 1)
        self._tunnel(tunnel)
        ue, vel = self.trajectory.position[k], self.trajectory.velocity[k]
        arr = select_array(self.arrays, ue)
        eng = self.engine(tunnel)
        t0 = time.perf_counter()
        ep = eng.trace_elements(arr, ue, vel)
        return arr, ep, time.perf_counter() - t0

    def components(self, k: int, *, amplitude: float = 1.0, tunnel=None):
        """Trace epoch ``k`` now (no cache) and split its noiseless tensor by what the
        first-order model lacks (:func:`~tunnelkit.rt.components.tensor_components` at this
        drive's SRS, times ``amplitude``): the array, the parts, the :class:`ElementPaths` and
        the seconds the trace took."""
        from .components import tensor_components

        amplitude = positive("amplitude", amplitude)
        arr, ep, seconds = self.trace(k, tunnel)
        c = self.config
        parts = tensor_components(
            ep,
            c.fc,
            c.tone_spacing,
            c.n_tones,
            c.symbol_period,
            c.n_symbols,
            amplitude=amplitude,
        )
        return arr, parts, ep, seconds

    def epoch(self, k: int, tunnel=None) -> dict:
        """Epoch ``k`` from the cache (traced and stored on a miss): ``array`` (name), ``H``
        (M, Nf, Nt) without the LoS, ``los_tau`` / ``los_gain`` / ``los_doppler`` / ``los_valid``
        (M,), ``power`` {kind: mean power per element}, ``count`` {kind: paths per element},
        ``trace_s`` / ``synth_s`` [s]."""
        tun = self._tunnel(tunnel)
        k = integer("k", k, minimum=0, maximum=len(self.trajectory) - 1)
        memo = (self.variant(tun), k)
        if memo in self._memo:
            return self._memo[memo]
        f = self.directory(tun) / f"epoch-{k:03d}.npz"
        if not f.is_file():
            self._store(k, tun, f)
        try:
            out = self._read(f)
        except ValueError as why:
            warnings.warn(
                f"ray-tracing cache: {f} is unreadable ({why}); tracing epoch {k} again",
                stacklevel=2,
            )
            f.unlink()
            self._store(k, tun, f)
            try:
                out = self._read(f)
            except ValueError as again:
                raise ValueError(
                    f"ray-tracing cache: {f} traced again is still bad ({again})"
                ) from None
        if len(self._memo) > 4:  # a few epochs in memory (one drive reads each epoch per run)
            self._memo.clear()
        self._memo[memo] = out
        return out

    def _read(self, f: FsPath) -> dict:
        """Epoch file ``f``, checked: ``ValueError`` saying what is wrong with it otherwise."""
        import zipfile

        try:
            with np.load(f, allow_pickle=False) as z:
                missing = [name for name in _FIELDS if name not in z.files]
                if missing:
                    raise ValueError(f"missing {', '.join(missing)}")
                out = {name: z[name] for name in _FIELDS}
            power = json.loads(str(out.pop("power_json")))
            count = json.loads(str(out.pop("count_json")))
        except (OSError, EOFError, zipfile.BadZipFile, KeyError, json.JSONDecodeError) as e:
            raise ValueError(f"{type(e).__name__}: {e}") from None
        names = {a.name: a for a in self.arrays}
        name, H = str(out["array"]), out["H"]
        cfg = self.config
        if name not in names:
            raise ValueError(f"array {name!r} is none of this drive's ({', '.join(names)})")
        M = len(names[name].world)
        if H.shape != (M, cfg.n_tones, cfg.n_symbols) or not np.iscomplexobj(H):
            raise ValueError(
                f"H: expected complex ({M}, {cfg.n_tones}, {cfg.n_symbols}), got {H.dtype} "
                f"{H.shape}"
            )
        if not np.all(np.isfinite(H)):
            raise ValueError("H: not finite")
        valid = out["los_valid"]
        if valid.shape != (M,) or valid.dtype != bool:
            raise ValueError(f"los_valid: expected ({M},) bool, got {valid.dtype} {valid.shape}")
        for key in ("los_tau", "los_gain", "los_doppler"):
            v = out[key]
            if v.shape != (M,) or not np.all(np.isfinite(v[valid])):
                raise ValueError(f"{key}: expected ({M},) finite where the LoS is, got {v.shape}")
        for key, d in (("power", power), ("count", count)):
            if not isinstance(d, dict) or set(d) != set(_KINDS):
                raise ValueError(f"{key}: expected the kinds {', '.join(_KINDS)}")
            if not all(
                isinstance(x, (int, float)) and np.isfinite(x) and x >= 0 for x in d.values()
            ):
                raise ValueError(f"{key}: expected finite non-negative numbers")
        out["array"], out["power"], out["count"] = name, power, count
        out["trace_s"], out["synth_s"] = float(out["trace_s"]), float(out["synth_s"])
        return out

    def _store(self, k: int, tunnel, f: FsPath) -> None:
        cfg = self.config
        arr, ep, trace_s = self.trace(k, tunnel)
        t0 = time.perf_counter()
        H = element_tensor(
            ep,
            cfg.tone_spacing,
            cfg.n_tones,
            cfg.symbol_period,
            cfg.n_symbols,
            select=ep.valid & (ep.order > 0),
        )
        los = ep.mask("los")
        j = np.argmax(los, axis=1)
        rows = np.arange(ep.M)
        kinds = _KINDS
        tmp = f.with_name(f".{f.stem}-{os.getpid()}.npz")
        np.savez(
            tmp,
            array=np.array(arr.name),
            H=H.astype(np.complex64),
            los_tau=ep.tau[rows, j],
            los_gain=ep.gain[rows, j],
            los_doppler=ep.doppler[rows, j],
            los_valid=los[rows, j],
            power_json=np.array(json.dumps({kd: ep.power(kd) for kd in kinds})),
            count_json=np.array(json.dumps({kd: ep.count(kd) for kd in kinds})),
            trace_s=np.array(trace_s),
            synth_s=np.array(time.perf_counter() - t0),
        )
        os.replace(tmp, f)

    def tensor(self, k: int, *, tunnel=None, los: bool = True) -> tuple[str, np.ndarray]:
        """``(array name, H)``: the noiseless tensor (M, Nf, Nt) of epoch ``k``, unit transmit
        power, no clock bias; ``los=False`` leaves the LoS path out (a blocked LoS)."""
        los = boolean("los", los)
        e = self.epoch(k, tunnel)
        H = e["H"].astype(complex)
        if los:
            cfg = self.config
            v = e["los_valid"]
            ep = ElementPaths(
                e["los_tau"][:, None],
                e["los_gain"][:, None],
                e["los_doppler"][:, None],
                v[:, None],
                np.zeros((v.size, 1), int),
                np.zeros((v.size, 1), bool),
                np.zeros((v.size, 1), np.int64),
            )
            H = H + element_tensor(
                ep, cfg.tone_spacing, cfg.n_tones, cfg.symbol_period, cfg.n_symbols
            )
        return e["array"], H

    def prepare(self, tunnel=None, epochs=None, progress: bool = False) -> dict:
        """Trace (or find in the cache) ``epochs`` (all by default) of ``tunnel``; returns
        ``{"traced": n newly traced, "trace_s": [...] per epoch, "bytes": cache size}``."""
        from tqdm.auto import tqdm

        tun = self._tunnel(tunnel)
        progress = boolean("progress", progress)
        n = len(self.trajectory)
        ks = range(n) if epochs is None else sequence("epochs", epochs)
        for k in ks:
            integer("epochs", k, minimum=0, maximum=n - 1)
        d = self.directory(tun)
        traced, times = 0, []
        for k in tqdm(
            ks, desc=f"ray tracing {self.label} ({self.variant(tun)})", disable=not progress
        ):
            fresh = not (d / f"epoch-{int(k):03d}.npz").is_file()
            e = self.epoch(int(k), tun)
            traced += fresh
            times.append(e["trace_s"])
        size = sum(f.stat().st_size for f in d.iterdir() if f.is_file())
        return {"traced": traced, "trace_s": times, "bytes": size, "directory": str(d)}
