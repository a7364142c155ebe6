"""Generated argument contracts for every public callable of ``tunnelkit``.

Nothing here lists callables. :func:`public_callables` walks every public module (no leading
underscore) and takes what its ``__all__`` exports: functions, classes (their constructor) and the
public methods a class defines. For each parameter :func:`bad_values` derives bad inputs from the
signature (annotation, default, a valid value): wrong type, NaN, +-inf, zero, negative, huge,
empty, wrong shape, wrong dtype, complex where real. Each case calls the callable with valid
arguments (:mod:`contract_values`) except that one parameter and classifies what happens:

* ``clear``      ValueError/TypeError whose message names the parameter;
* ``unclear``    ValueError/TypeError that does not name it;
* ``silent``     returned without an error;
* ``crash``      any other exception (IndexError, ZeroDivisionError, MemoryError, ...);
* ``hang``       still running when the call's time box ran out;
* ``documented`` a result the table ``DOCUMENTED`` allows, with its reason.

Cases run in a forked child per module (an address-space limit, a time box per call, a restart
after a death) so that a hang, a memory blow-up or global state changed by one case cannot spoil
the others.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import math
import multiprocessing as mp
import pkgutil
import re
import signal
import types
import typing
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

OUTCOMES = ("clear", "unclear", "silent", "crash", "hang", "documented")
CALL_TIMEOUT_S = 1.0  # time box of one call (validation is at the boundary: instant)
CHILD_LIMIT_BYTES = 3 * 1024**3  # address space a module's child may add
MAX_CASES_PER_PARAMETER = 8

# --- which callables ------------------------------------------------------------------------


@dataclass(frozen=True)
class Target:
    """One public callable: a function, a class (its constructor) or a public method."""

    name: str  # module.qualname
    module: str  # the public module it is reached from first
    obj: object
    owner: type | None = None  # the class of a method
    kind: str = "function"  # function | class | method | classmethod | staticmethod | property


# exceptions and warnings take a message; nothing to validate
_SKIP_BASES = (BaseException,)


def public_modules() -> list[str]:
    import tunnelkit

    names = ["tunnelkit"]
    for info in pkgutil.walk_packages(tunnelkit.__path__, "tunnelkit."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        names.append(info.name)
    return sorted(names)


def public_callables() -> list[Target]:
    """Every function, class and public method exported by a public tunnelkit module."""
    seen: dict[int, Target] = {}
    for modname in public_modules():
        mod = importlib.import_module(modname)
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if not getattr(obj, "__module__", "").startswith("tunnelkit"):
                continue
            if id(obj) in seen:
                continue
            qual = f"{obj.__module__}.{obj.__qualname__}"
            if inspect.isclass(obj):
                if issubclass(obj, _SKIP_BASES):
                    seen[id(obj)] = Target(qual, modname, obj, kind="exception")
                    continue
                if getattr(obj, "_is_protocol", False):  # an interface: its members are stubs
                    seen[id(obj)] = Target(qual, modname, obj, kind="protocol")
                    continue
                seen[id(obj)] = Target(qual, modname, obj, kind="class")
                for attr, raw in vars(obj).items():
                    if attr.startswith("_"):
                        continue
                    if isinstance(raw, staticmethod):
                        kind = "staticmethod"
                    elif isinstance(raw, classmethod):
                        kind = "classmethod"
                    elif inspect.isfunction(raw):
                        kind = "method"
                    elif isinstance(raw, property):
                        kind = "property"
                    else:
                        continue
                    seen[id(raw)] = Target(f"{qual}.{attr}", modname, raw, owner=obj, kind=kind)
            else:
                seen[id(obj)] = Target(qual, modname, obj)
    return sorted(seen.values(), key=lambda t: t.name)


def function_of(target: Target):
    """The callable whose signature the cases follow (unbound for a method)."""
    if target.kind == "class":
        return target.obj
    if target.kind in ("classmethod", "staticmethod"):
        return getattr(target.owner, target.name.rsplit(".", 1)[1])
    return target.obj


def parameters(target: Target) -> list[inspect.Parameter]:
    """The parameters a caller chooses (no self/cls, no *args/**kwargs)."""
    if target.kind in ("exception", "property", "protocol"):
        return []
    fn = function_of(target)
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return []
    out = []
    for i, p in enumerate(sig.parameters.values()):
        if target.kind == "method" and i == 0:
            continue  # self
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        out.append(p)
    return out


def hints(target: Target) -> dict[str, object]:
    fn = function_of(target)
    try:
        if inspect.isclass(fn):
            init = fn.__init__
            h = typing.get_type_hints(init) if inspect.isfunction(init) else {}
            try:
                h = {**typing.get_type_hints(fn), **h}
            except Exception:
                pass
            return h
        return typing.get_type_hints(fn)
    except Exception:
        return {}


# --- bad values --------------------------------------------------------------------------------

NAN, INF = float("nan"), float("inf")


@dataclass(frozen=True)
class Bad:
    kind: str  # type | nan | inf | zero | negative | huge | empty | shape | dtype | complex
    # | physical (outside a declared physical range or budget)
    label: str
    value: object = field(compare=False)


def _strip_optional(tp) -> tuple[object, bool]:
    """(annotation without None, whether None is allowed)."""
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        allows_none = len(args) < len(typing.get_args(tp))
        if len(args) == 1:
            return args[0], allows_none
        return typing.Union[tuple(args)], allows_none  # noqa: UP007
    return tp, tp is None or tp is type(None)


def _members(tp) -> tuple:
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        return typing.get_args(tp)
    return (tp,)


def value_kind(tp, valid) -> str:
    """A coarse kind for generating bad values: float, int, bool, str, array, rng, seq, map,
    callable, object, any."""
    members = _members(tp) if tp is not inspect.Parameter.empty else ()
    plain = {typing.get_origin(m) or m for m in members}
    if plain & {np.random.Generator} and plain & {int}:
        return "seed"
    if np.random.Generator in plain:
        return "rng"
    if np.ndarray in plain or (plain and valid is not None and isinstance(valid, np.ndarray)):
        return "array"
    if bool in plain:
        return "bool"
    if float in plain:
        return "float"
    if int in plain:
        return "int"
    if str in plain and len(plain) == 1:
        return "str"
    if plain & {list, tuple, typing.Sequence, __import__("collections.abc").abc.Sequence}:
        return "seq"
    if plain & {dict, typing.Mapping, __import__("collections.abc").abc.Mapping}:
        return "map"
    if plain & {__import__("collections.abc").abc.Callable, typing.Callable}:
        return "callable"
    # no annotation: go by the valid value
    if isinstance(valid, bool | np.bool_):
        return "bool"
    if isinstance(valid, int | np.integer):
        return "int"
    if isinstance(valid, float | np.floating):
        return "float"
    if isinstance(valid, str):
        return "str"
    if isinstance(valid, np.ndarray):
        return "array"
    if isinstance(valid, np.random.Generator):
        return "rng"
    if isinstance(valid, list | tuple):
        if valid and all(isinstance(v, int | float) and not isinstance(v, bool) for v in valid):
            return "array"
        return "seq"
    if isinstance(valid, dict):
        return "map"
    if valid is not None and callable(valid) and not inspect.isclass(type(valid)):
        return "callable"
    if valid is not None and type(valid).__module__.startswith("tunnelkit"):
        return "object"
    return "any"


def _array_bads(valid) -> list[Bad]:
    a = np.asarray(valid)
    out = [Bad("type", "str", "x")]
    if a.dtype.kind in "iuf" and a.size:
        f = a.astype(float)
        g = f.copy()
        g.flat[0] = NAN
        out.append(Bad("nan", "nan", g))
        g = f.copy()
        g.flat[-1] = INF
        out.append(Bad("inf", "inf", g))
        c = f.astype(complex)
        c.flat[0] += 1j
        out.append(Bad("complex", "complex", c))
        out.append(Bad("dtype", "text-dtype", f.astype(str)))
    elif a.dtype.kind == "c" and a.size:
        g = a.copy()
        g.flat[0] = complex(NAN, 0)
        out.append(Bad("nan", "nan", g))
        out.append(Bad("dtype", "real-dtype", np.abs(a)))
    out.append(Bad("empty", "empty", np.zeros((0,) * max(a.ndim, 1))))
    out.append(Bad("shape", "extra-axis", a[None, None] if a.ndim else np.zeros((2, 2, 2))))
    return out


def bad_values(p: inspect.Parameter, tp, valid) -> list[Bad]:
    """Bad values for one parameter, at most ``MAX_CASES_PER_PARAMETER``."""
    core, allows_none = _strip_optional(tp) if tp is not inspect.Parameter.empty else (tp, False)
    if p.default is None:
        allows_none = True
    kind = value_kind(core, valid)
    out: list[Bad] = []
    if kind == "float":
        out = [
            Bad("type", "str", "1.0"),
            Bad("nan", "nan", NAN),
            Bad("inf", "inf", INF),
            Bad("inf", "-inf", -INF),
            Bad("complex", "complex", 1.0 + 1.0j),
            Bad("zero", "zero", 0.0),
            Bad("negative", "negative", -1.0),
            Bad("huge", "huge", 1e300),
        ]
    elif kind == "int":
        out = [
            Bad("type", "float", 2.5),
            Bad("type", "str", "2"),
            Bad("nan", "nan", NAN),
            Bad("type", "bool", True),
            Bad("zero", "zero", 0),
            Bad("negative", "negative", -1),
            Bad("huge", "huge", 10**12),
        ]
    elif kind == "bool":
        out = [Bad("type", "str", "no"), Bad("type", "int", 2), Bad("nan", "nan", NAN)]
    elif kind == "str":
        out = [Bad("type", "int", 42), Bad("empty", "empty", ""), Bad("type", "unknown", "\x00?")]
    elif kind in ("rng", "seed"):
        out = [Bad("type", "str", "rng"), Bad("type", "float", 0.5)]
        if kind == "rng":
            out.append(Bad("type", "int-seed", 0))
    elif kind == "array":
        out = _array_bads(valid) if valid is not None else [Bad("type", "str", "x")]
    elif kind == "seq":
        out = [Bad("type", "int", 42), Bad("type", "str-items", [object()])]
        if not (isinstance(valid, list | tuple) and len(valid) == 0):
            out.append(Bad("empty", "empty", []))
    elif kind == "map":
        out = [Bad("type", "int", 42), Bad("type", "list", [1, 2])]
    elif kind == "callable":
        out = [Bad("type", "int", 42)]
    elif kind == "object":
        out = [Bad("type", "str", "x"), Bad("type", "int", 42)]
    else:  # any: a wrong type at least
        out = [Bad("type", "object", object())]
    if not allows_none and kind != "any":
        out.append(Bad("type", "None", None))
    out = out[:MAX_CASES_PER_PARAMETER]
    if kind in ("float", "int", "array"):
        out += physical_bads(p.name, kind, valid)
    return out


# --- physical probes: generated from the package's declared ranges ----------------------------


@functools.cache
def _quantities() -> tuple:
    """(parameter-name pattern, [(label, value)]) per physical quantity: values outside the range
    :mod:`tunnelkit._physical` declares for it (a car faster than any vehicle, a carrier in GHz,
    a subcarrier spacing in kHz, a time step or an entry-fix spread no motion model holds), and a
    size no memory budget allows for a count a user controls."""
    from tunnelkit import _physical as ph

    return (
        (
            r"fc|fc_hz|f_c|carrier|carrier_hz|carrier_frequency|frequency_hz",
            [("GHz-for-Hz", 28.0), ("above-range", ph.CARRIER_HZ[1] * 10)],
        ),
        (
            r"scs|scs_hz|subcarrier|subcarrier_hz|subcarrier_spacing|delta_f",
            [("kHz-for-Hz", 120.0), ("above-range", ph.SUBCARRIER_HZ[1] * 10)],
        ),
        (
            r"tone_spacing",
            [("kHz-for-Hz", 120.0), ("above-range", ph.TONE_SPACING_HZ[1] * 10)],
        ),
        (
            r"speed|speeds|speed_mps|velocity|v0|v_max|max_speed",
            [("faster-than-a-vehicle", 2 * ph.MAX_SPEED), ("light", 3e8)],
        ),
        (r"dt|step_s|epoch_s|period_s|interval_s", [("step-too-long", 100 * ph.MAX_STEP_S)]),
        (
            r"start_sigma|sigma_p0|sigma_p0_ue|start_sigma_m",
            [("spread-too-wide", 100 * ph.MAX_START_SPREAD_M)],
        ),
        (r"tx_power_dbm|power_dbm", [("above-range", 10 * ph.TX_POWER_DBM[1])]),
        (r"spacing|element_spacing|spacing_m", [("above-range", 10 * ph.MAX_SPACING_M)]),
        (
            r"runs|n_runs|units|n_units|n_boot|n_tones|n_bins|n_epochs|reps|n_particles"
            r"|particles|drives|drives_per_unit|n_draws|n_samples|trials|n_paths|n_grid|nf|nt"
            r"|batch|epochs|size|n_symbols",
            [("beyond-budget", 10**10)],
        ),
    )


def physical_bads(name: str, kind: str, valid) -> list[Bad]:
    """The physical probes of parameter ``name`` (:func:`_quantities`), shaped like ``valid``
    (an array parameter gets the value in every element); none for other names."""
    out = []
    for pattern, values in _quantities():
        if not re.fullmatch(pattern, name):
            continue
        for label, value in values:
            if kind == "int" and not float(value).is_integer():
                continue
            if label == "beyond-budget" and kind != "int":
                continue  # a count only (an array named "particles" holds the samples)
            if kind == "array":
                a = np.asarray(valid) if valid is not None else None
                if a is None or a.dtype.kind not in "iuf" or not a.size:
                    continue
                value = np.full(a.shape, value, dtype=float)
            elif kind == "int":
                value = int(value)
            out.append(Bad("physical", label, value))
    return out


# --- one case ---------------------------------------------------------------------------------


@dataclass
class Case:
    """One generated call. ``aliases``: other names the error may give for ``param`` (a helper
    whose ``name`` argument says which caller's parameter it checks names that one)."""

    id: str
    target: str
    param: str
    bad: Bad
    call: Callable[[], object]
    aliases: tuple[str, ...] = ()


def names_parameter(message: str, name: str) -> bool:
    """True when ``message`` names ``name`` as a whole word (``--n-runs`` counts for n_runs)."""
    pats = {name, name.replace("_", "-")}
    return any(
        re.search(rf"(?<![A-Za-z0-9_]){re.escape(n)}(?![A-Za-z0-9_])", message) for n in pats
    )


class _TimeBox(BaseException):
    pass


#: whether the running call's time box went off (a library that runs Python callbacks, such as
#: Dr.Jit's loops under the ray tracer, may catch the _TimeBox and raise its own error instead)
_FIRED = [False]


def _alarm(signum, frame):
    _FIRED[0] = True
    raise _TimeBox


def classify(call: Callable[[], object], param: str, aliases=()) -> tuple[str, str]:
    """(outcome, detail) of one call, time-boxed; an error naming ``param`` or one of
    ``aliases`` is clear."""
    old = signal.signal(signal.SIGALRM, _alarm)
    _FIRED[0] = False
    signal.setitimer(signal.ITIMER_REAL, CALL_TIMEOUT_S)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            np.seterr(all="ignore")
            call()
    except _TimeBox:
        return "hang", f"still running after {CALL_TIMEOUT_S:g} s"
    except (ValueError, TypeError) as exc:
        msg = str(exc)
        if any(names_parameter(msg, n) for n in (param, *aliases)):
            return "clear", f"{type(exc).__name__}: {msg[:160]}"
        return "unclear", f"{type(exc).__name__}: {msg[:160]}"
    except Exception as exc:
        if _FIRED[0]:  # the time box went off inside a library that wrapped it
            return "hang", f"still running after {CALL_TIMEOUT_S:g} s ({type(exc).__name__})"
        return "crash", f"{type(exc).__name__}: {str(exc)[:160]}"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    return "silent", "returned without an error"


def run_cases(cases: list[Case], child_timeout: float = 4 * CALL_TIMEOUT_S + 30) -> list[tuple]:
    """Run ``cases`` in forked children (one at a time, restarted after a death or a hang);
    [(case id, outcome, detail)] in order."""
    ctx = mp.get_context("fork")
    results: dict[int, tuple[str, str]] = {}
    start = 0
    while start < len(cases):
        recv, send = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_child, args=(cases, start, send))
        proc.start()
        send.close()
        current = start
        while True:
            if not recv.poll(child_timeout):
                proc.kill()
                results[current] = ("hang", f"child stuck over {child_timeout:g} s")
                break
            try:
                msg = recv.recv()
            except EOFError:
                if current < len(cases) and current not in results:
                    results[current] = ("crash", f"child died (exit code {proc.exitcode})")
                break
            if msg[0] == "start":
                current = msg[1]
            elif msg[0] == "done":
                results[msg[1]] = (msg[2], msg[3])
                current = msg[1] + 1
                if current >= len(cases):
                    break
        proc.join()
        recv.close()
        start = current + 1 if current in results else current
        if start <= current and current in results:
            start = current + 1
    return [(c.id, *results[i]) for i, c in enumerate(cases)]


def _vm_size() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def _child(cases, start, conn) -> None:
    import resource

    lim = _vm_size() + CHILD_LIMIT_BYTES
    resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
    for i in range(start, len(cases)):
        conn.send(("start", i))
        try:
            outcome, detail = classify(cases[i].call, cases[i].param, cases[i].aliases)
        except _TimeBox:  # the alarm went off while the call was being disarmed
            outcome, detail = "hang", f"still running after {CALL_TIMEOUT_S:g} s"
        conn.send(("done", i, outcome, detail))
    conn.close()


def chunks(cases: list[Case]) -> Iterator[list[Case]]:
    """Cases grouped by the module of their callable (a fresh child per module)."""
    groups: dict[str, list[Case]] = {}
    for c in cases:
        groups.setdefault(c.target.rsplit(".", 1)[0], []).append(c)
    yield from groups.values()


def isfinite_number(x) -> bool:
    return isinstance(x, int | float) and math.isfinite(x)
