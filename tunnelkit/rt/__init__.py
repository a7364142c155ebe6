"""A real ray tracer beside the image method: Sionna RT scenes, paths and an engine switch.

``tunnelkit.rt`` imports without Sionna; only the Sionna engine and scene loading need the
optional extra::

    pip install -e '.[rt]'                         # sionna-rt 2.2.0 (Mitsuba 3 / Dr.Jit)
    apt-get install libllvm19                      # Dr.Jit's CPU backend (Debian 12)

Dr.Jit's CPU (LLVM) backend needs LLVM 15 or newer, and LLVM 15/16 abort the process in the first
path computation ("LLVM ERROR: Cannot select ... fmaximum"). On import, when
``DRJIT_LIBLLVM_PATH`` is unset and Debian's ``libLLVM.so.19.1`` exists, this package points
Dr.Jit at it; :func:`require_sionna` then checks the LLVM that Dr.Jit actually loaded and raises a
clear error instead of letting LLVM abort.

    >>> from tunnelkit import rt
    >>> paths = rt.compute_paths(tun, arr, ue, vel, fc=5.9e9, engine="sionna")   # doctest: +SKIP
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path as FsPath

__all__ = [
    "ENGINES",
    "INSTALL_HINT",
    "MIN_LLVM",
    "RTUnavailableError",
    "compute_paths",
    "engine_for",
    "export_tunnel",
    "read_scene",
    "require_sionna",
    "sionna_available",
]

#: Engines :func:`compute_paths` accepts.
ENGINES = ("image", "sionna")
#: Oldest LLVM whose x86 backend lowers ``llvm.maximum`` (15 and 16 abort in the first solve).
MIN_LLVM = (17, 0, 0)
#: Where Debian 12 (bookworm) puts ``apt-get install libllvm19`` (multiarch directory).
DEBIAN_LLVM = next(
    iter(sorted(FsPath("/usr/lib").glob("*-linux-gnu/libLLVM.so.19.1"))),
    FsPath("/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"),
)
INSTALL_HINT = (
    "install the optional ray-tracing extra: `pip install -e '.[rt]'` (sionna-rt 2.2.0) and, on "
    "Debian/Ubuntu, `apt-get install libllvm19` (Dr.Jit's CPU backend; `make rt-deps` does both); "
    "if libLLVM is elsewhere set DRJIT_LIBLLVM_PATH to its libLLVM.so"
)

if not os.environ.get("DRJIT_LIBLLVM_PATH") and DEBIAN_LLVM.is_file():
    os.environ["DRJIT_LIBLLVM_PATH"] = str(DEBIAN_LLVM)


class RTUnavailableError(ImportError):
    """Sionna RT cannot run here: the extra is missing or Dr.Jit's LLVM is missing or too old."""


_checked: bool = False


def sionna_available() -> bool:
    """True when :func:`require_sionna` would succeed (never aborts the process)."""
    try:
        require_sionna()
    except RTUnavailableError:
        return False
    return True


_PROBE = (
    "import json, drjit as dr\n"
    "print(json.dumps([bool(dr.has_backend(dr.JitBackend.LLVM)), list(dr.detail.llvm_version())]))"
)
#: Seconds the child process may take to initialise Dr.Jit's LLVM backend.
PROBE_TIMEOUT = 60.0


def _query(dr) -> tuple[bool, tuple[int, ...]]:
    try:
        return bool(dr.has_backend(dr.JitBackend.LLVM)), tuple(
            int(v) for v in dr.detail.llvm_version()
        )
    except Exception:  # any failure here means "no usable backend"
        return False, (-1, -1, -1)


def _llvm_status() -> tuple[bool, tuple[int, ...]]:
    """(LLVM backend usable, LLVM version) as Dr.Jit sees them.

    Probed in a child process unless Dr.Jit is already imported here: Dr.Jit's initialisation
    with an unusable LLVM can hang (seen about 1 run in 30 with Debian's LLVM 14) or abort, and
    must not take this process with it.
    """
    dr = sys.modules.get("drjit", 0)
    if dr is None:  # import blocked (tests) = not installed
        raise ImportError("No module named 'drjit'")
    if dr != 0:
        return _query(dr)
    try:
        found = importlib.util.find_spec("drjit") is not None
    except (ImportError, ValueError):
        found = False
    if not found:
        raise ImportError("No module named 'drjit'")
    try:
        out = subprocess.run(
            [sys.executable, "-c", _PROBE],
            capture_output=True,
            text=True,
            timeout=PROBE_TIMEOUT,
            stdin=subprocess.DEVNULL,
        )
    except subprocess.TimeoutExpired:
        return False, (-2, -2, -2)
    lines = out.stdout.strip().splitlines()
    if out.returncode != 0 or not lines:
        return False, (-1, -1, -1)
    has, ver = json.loads(lines[-1])
    return bool(has), tuple(int(v) for v in ver)


def require_sionna() -> None:
    """Raise :class:`RTUnavailableError` (an ``ImportError``) with install instructions unless
    sionna-rt is importable and Dr.Jit runs on an LLVM >= 17.

    The LLVM that Dr.Jit loads is checked in a child process *before* Dr.Jit or ``sionna.rt`` is
    imported here, so a missing, too-old (LLVM 14: Dr.Jit refuses it, and its initialisation can
    hang) or crashing (LLVM 15/16: "Cannot select ... fmaximum") LLVM is an exception, never a
    process abort or hang.
    """
    global _checked
    if _checked:
        return
    try:
        has_llvm, ver = _llvm_status()
    except ImportError as exc:
        raise RTUnavailableError(
            f"the Sionna engine needs sionna-rt ({exc}); {INSTALL_HINT}"
        ) from None
    where = os.environ.get("DRJIT_LIBLLVM_PATH", "<unset: system search>")
    if ver[0] == -2:
        raise RTUnavailableError(
            f"Dr.Jit did not initialise its LLVM backend within {PROBE_TIMEOUT:g} s "
            f"(DRJIT_LIBLLVM_PATH={where}); it needs LLVM >= {MIN_LLVM[0]}; {INSTALL_HINT}"
        )
    if not has_llvm or ver[0] < 0:
        raise RTUnavailableError(
            f"Dr.Jit found no usable LLVM library (DRJIT_LIBLLVM_PATH={where}); it needs LLVM "
            f">= {MIN_LLVM[0]}; {INSTALL_HINT}"
        )
    if ver < MIN_LLVM:
        raise RTUnavailableError(
            f"Dr.Jit loaded LLVM {'.'.join(map(str, ver))} (DRJIT_LIBLLVM_PATH={where}); LLVM 15/16 "
            f"abort in Sionna's first path computation, need >= {MIN_LLVM[0]}; {INSTALL_HINT}"
        )
    try:
        import sionna.rt  # noqa: F401
    except ImportError as exc:
        raise RTUnavailableError(
            f"the Sionna engine needs sionna-rt ({exc}); {INSTALL_HINT}"
        ) from None
    _checked = True


from .mitsuba import MitsubaScene, SceneError, export_tunnel, read_scene  # noqa: E402

_ENGINE_CACHE: dict = {}


def engine_for(tunnel, *, fc: float, **options):
    """The :class:`~tunnelkit.rt.sionna_engine.SionnaEngine` for ``tunnel`` (cached: exporting and
    loading the scene is done once per tunnel object, or scene file, frequency and options)."""
    from .sionna_engine import SionnaEngine

    by_file = isinstance(tunnel, (str, os.PathLike))
    ident = str(FsPath(tunnel).resolve()) if by_file else id(tunnel)
    key = (ident, float(fc), tuple(sorted((k, str(v)) for k, v in options.items())))
    hit = _ENGINE_CACHE.get(key)
    if hit is not None and (by_file or hit[0] is tunnel):
        return hit[1]
    eng = SionnaEngine(tunnel, fc=fc, **options)
    _ENGINE_CACHE.clear()  # one scene at a time: each holds a Mitsuba scene in memory
    _ENGINE_CACHE[key] = (tunnel, eng)
    return eng


def compute_paths(
    tunnel,
    array,
    ue,
    ue_velocity=(0.0, 0.0, 0.0),
    *,
    fc: float,
    engine: str = "image",
    kinds: tuple[str, ...] = ("los", "wall", "ceiling", "road", "rrm"),
    front_only: bool = True,
    **options,
) -> list:
    """Paths from ``ue`` to ``array`` by the chosen ``engine``: "image" (default,
    :func:`tunnelkit.propagation.trace_paths`) or "sionna" (Sionna RT, same ``Path`` structure).

    ``options`` go to the Sionna engine (``samples_per_src``, ``max_num_paths_per_src``,
    ``workdir``); the image method takes none.
    """
    from .. import propagation

    if engine == "image":
        if options:
            raise TypeError(f"engine='image' takes no options, got {sorted(options)}")
        return propagation.trace_paths(
            tunnel, array, ue, ue_velocity, fc=fc, kinds=kinds, front_only=front_only
        )
    if engine == "sionna":
        return engine_for(tunnel, fc=fc, **options).trace(
            array, ue, ue_velocity, kinds=kinds, front_only=front_only
        )
    raise ValueError(f"engine: expected one of {ENGINES}, got {engine!r}")


from .cache import RayTracedChannel, default_cache_dir  # noqa: E402
from .compare import (  # noqa: E402
    compare_paths,
    lower_into_tunnel,
    plate_occluders,
    time_engines,
    worst_errors,
)
from .components import COMPONENTS, first_order_groups, tensor_components  # noqa: E402
from .elements import ElementPaths, element_tensor  # noqa: E402
from .settings import RTSettings  # noqa: E402

__all__ += [
    "COMPONENTS",
    "ElementPaths",
    "MitsubaScene",
    "RTSettings",
    "RayTracedChannel",
    "SceneError",
    "compare_paths",
    "default_cache_dir",
    "element_tensor",
    "first_order_groups",
    "lower_into_tunnel",
    "plate_occluders",
    "tensor_components",
    "time_engines",
    "worst_errors",
]
