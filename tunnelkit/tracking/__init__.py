"""Trackers and their small roles (motion models, gates, associators, initiators, deleters).

Interchangeable algorithms sit in :mod:`tunnelkit.tracking.registry`, grouped by family (the
setting they solve), so notebooks, tests and the command line loop over them::

    from tunnelkit.tracking import registry
    for name, make in registry.family("jiang2023").items(): ...
"""

from . import registry

__all__ = ["registry"]
