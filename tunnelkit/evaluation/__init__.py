"""Estimates against the truth (notebook 03, benchmarks): matching, tables, RMSE studies with
bounds.

``matching`` (:func:`match_paths`, :func:`match_points`: the Hungarian assignment of estimates to
true paths, all a signal route's epoch needs) · ``tables`` (errors in units of the CRLB, rows per
path, :func:`rmse_study`) · ``scenes`` (:class:`Scene`, :func:`random_scene`: free-space test
scenes). Each name loads its submodule on first use.
"""

from __future__ import annotations

from .._lazy import lazy_exports

_EXPORTS = {
    "match_paths": "matching",
    "match_points": "matching",
    "Scene": "scenes",
    "random_scene": "scenes",
    "bound_errors": "tables",
    "comparison_rows": "tables",
    "normalized_errors": "tables",
    "path_rows": "tables",
    "rmse_study": "tables",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
