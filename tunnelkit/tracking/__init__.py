"""Trackers and their small roles (motion models, gates, associators, initiators, deleters).

Interchangeable algorithms sit in :mod:`tunnelkit.tracking.registry`, grouped by family (the
setting they solve), so notebooks, tests and the command line loop over them::

    from tunnelkit.tracking import registry
    for name, make in registry.family("jiang2023").items(): ...

Every filter follows one protocol (:mod:`tunnelkit.tracking.protocol`): ``predict(*inputs)``,
``update(z)``, ``step`` (both), and an inspectable ``x`` and ``P``.
"""

from .._lazy import lazy_exports
from . import registry

# families -> modules that register them; imported on first lookup so `import tunnelkit` stays light
registry.provide("jiang2023", "tunnelkit.tracking.virtual_station")  # TSWLS, EKF, UKF
registry.provide("jiang2023", "tunnelkit.tracking.upf")  # UPF
registry.provide("halili2022", "tunnelkit.tracking.doppler")  # KF/EKF on Doppler and ToA
registry.provide("italiano2026", "tunnelkit.tracking.javelin.tracker")  # JAVELIN
registry.provide("italiano2026", "tunnelkit.tracking.javelin.tenfiloc")  # TeNFiLoc

# a subpackage by its own name (``tk.tracking.javelin``) loads on first use: building a signal
# route reads the measurement container (``tracking.measurements``) without loading a tracker;
# the protocol (``Filter``) loads when a caller checks a filter against it
_EXPORTS: dict[str, str] = {"Filter": "protocol"}
__all__ = sorted([*_EXPORTS, "registry"])
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
