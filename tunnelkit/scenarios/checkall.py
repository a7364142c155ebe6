"""Every preset (or the files given) loaded and validated: :func:`check_all`, behind
``tunnelkit scenarios check``."""

from __future__ import annotations

from ..schema import ScenarioError
from .files import list_scenarios, load_scenario

__all__ = ["check_all"]


def check_all(paths=None) -> list[tuple[str, str | None]]:
    """``[(name, error or None), ...]`` for every preset (or the given names/paths)."""
    if paths is not None and (isinstance(paths, str | bytes) or not hasattr(paths, "__iter__")):
        raise TypeError(f"paths: expected a list of scenario names or paths, got {paths!r:.40}")
    out = []
    for n in list_scenarios() if paths is None else paths:
        try:
            load_scenario(n)
            out.append((str(n), None))
        except (ScenarioError, TypeError) as exc:
            out.append((str(n), str(exc)))
    return out
