"""Registry of interchangeable estimators, grouped by family (``"jiang2023"``, ``"halili2022"``, ...).

Register a factory (a class or a function returning a configured estimator) with::

    @register("jiang2023", "UKF")
    class VsUKF: ...

and loop with ``family("jiang2023")`` -> ``{"TSWLS": ..., "EKF": ..., "UKF": ..., "UPF": ...}`` in
registration order. Modules that register are imported on first lookup of their family.

**One call protocol per family.** Every member of a family is built and run the same way, so a
loop over ``family(...)`` needs no case for any member (``tests/test_registry.py`` builds and runs
every member through it). Each member's ``name`` attribute is its registered name.

``"jiang2023"`` (virtual-station ranges and bearings; :mod:`tunnelkit.tracking.virtual_station`,
:mod:`tunnelkit.tracking.upf`)
    Members are :class:`~tunnelkit.tracking.virtual_station.EstimatorBase` subclasses. One track:
    ``est = cls(model, x0, P0, rng=rng, **options)`` with a ``VsModel``, the prior mean ``x0``
    (4,) and covariance ``P0`` (4, 4) and a ``numpy.random.Generator`` (the UPF draws from it,
    the others accept and ignore it); then ``est.step(z, first=(k == 0))`` per epoch -> the
    state (4,) (``z`` (2N,), or ``None`` / NaN for a missed epoch), or ``est.predict()`` and
    ``est.update(z)``; ``est.x``, ``est.P``, ``est.position``. Many runs at once:
    ``cls.run(model, Z, x0, P0, rng=rng, **options)`` -> estimates (R, T, 4) for ``Z``
    (R, T, 2N) and ``x0`` (R, 4) (``virtual_station.run_estimator`` checks the inputs first).

``"halili2022"`` (Doppler and ToA from one roadside unit; :mod:`tunnelkit.tracking.doppler`)
    ``trk = cls(setup, fix, sigma_hz=..., q=..., adaptive=..., **kw)`` with a ``DopplerSetup``
    and a ``GnssFix``; keywords a member does not use are ignored, so one set of keywords serves
    the whole family (``doppler.run_approaches``). ``trk.run(meas)`` -> ``Track`` over a whole
    ``DopplerToaMeasurements`` stream (epoch 0 is the GNSS fix), or ``trk.step(doppler, toa)`` -> the
    position (2,) of one further epoch; ``trk.speed()``, ``trk.n_rejected``.

``"italiano2026"`` (JAVELIN, TeNFiLoc; :mod:`tunnelkit.tracking.javelin`)
    Build for a simulated drive with ``cls.for_drive(drive, design=None)`` (JAVELIN takes a
    :class:`~tunnelkit.tracking.javelin.roles.JavelinDesign`, TeNFiLoc none), run with
    ``trk.track(drive)`` -> ``(estimates (T, 3), details)`` (the ``JavelinRun``, or which epochs
    had a fix). ``Javelin.step(paths, speed, heading, dt)`` (``predict(speed, heading, dt)``
    then ``update(paths)``) and ``TeNFiLoc.locate(paths)`` are the per-epoch calls under it.

Under the families, every filter (Jiang's, Halili's Doppler and range filters, JAVELIN) follows
the one filter protocol of :mod:`tunnelkit.tracking.protocol`: ``predict(*inputs)``,
``update(z)``, ``step`` (both), ``x`` and ``P``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from .._validate import text

__all__ = ["families", "family", "get", "provide", "register"]

_REG: dict[str, dict[str, Callable[..., Any]]] = {}
#: family -> modules to import before the family is looked up (keeps ``import tunnelkit`` light)
_PROVIDERS: dict[str, list[str]] = {}


def provide(family_name: str, module: str) -> None:
    """Declare that importing ``module`` registers members of ``family_name``."""
    text("family_name", family_name), text("module", module)
    _PROVIDERS.setdefault(family_name, [])
    if module not in _PROVIDERS[family_name]:
        _PROVIDERS[family_name].append(module)


def register(family_name: str, name: str):
    """Decorator registering ``obj`` as ``name`` in ``family_name``."""
    text("family_name", family_name), text("name", name)

    def deco(obj):
        fam = _REG.setdefault(family_name, {})
        if name in fam and fam[name] is not obj:
            raise ValueError(f"name: {name!r} registered twice in family {family_name!r}")
        fam[name] = obj
        return obj

    return deco


def _load(family_name: str) -> None:
    for mod in _PROVIDERS.get(family_name, []):
        importlib.import_module(mod)


def families() -> list[str]:
    """Known family names."""
    return sorted(set(_REG) | set(_PROVIDERS))


def family(family_name: str) -> dict[str, Callable[..., Any]]:
    """All members of a family, in registration order."""
    _load(family_name)
    if family_name not in _REG:
        raise ValueError(f"family_name: unknown family {family_name!r}; known: {families()}")
    return dict(_REG[family_name])


def get(family_name: str, name: str) -> Callable[..., Any]:
    """One member, e.g. ``get("jiang2023", "UPF")``; imports the family's modules only until one
    has registered ``name``."""
    for mod in _PROVIDERS.get(family_name, []):
        if name in _REG.get(family_name, {}):
            return _REG[family_name][name]
        importlib.import_module(mod)
    fam = family(family_name)
    if name not in fam:
        raise ValueError(f"name: {name!r} is not in family {family_name!r}; members: {list(fam)}")
    return fam[name]
