"""A table of results with notes (:class:`Report`), rendered as plain text or JSON.

The common output of ``tunnelkit reproduce`` targets and of design tables such as
:func:`tunnelkit.fresnel.design_report`: a title, column names, rows of values, notes and free
metadata. Non-finite floats print as ``-`` in the text table and as ``null`` in the JSON.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from ._validate import record

__all__ = ["Report"]


@dataclass
class Report:
    """A table of results with notes; renders as text or JSON."""

    title: str
    columns: Sequence[str]
    rows: list[Sequence[Any]]
    notes: list[str] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        record(self, may_be_empty=("rows", "notes"))
        for name in ("columns", "notes"):
            bad = [c for c in getattr(self, name) if not isinstance(c, str)]
            if bad:
                raise TypeError(f"{name}: expected text items, got {bad[0]!r}")
        for i, row in enumerate(self.rows):
            if isinstance(row, str) or not isinstance(row, Sequence):
                raise TypeError(f"rows: row {i} is a {type(row).__name__}, expected a sequence")

    def records(self) -> list[dict[str, Any]]:
        """Rows as dicts keyed by column name."""
        return [dict(zip(self.columns, r)) for r in self.rows]

    def to_json(self) -> str:
        """Machine-readable form: title, meta, columns, rows (as records) and notes."""

        def clean(v):
            if isinstance(v, float) and not math.isfinite(v):
                return None
            return v

        recs = [{k: clean(v) for k, v in r.items()} for r in self.records()]
        return json.dumps(
            {
                "title": self.title,
                "meta": self.meta,
                "columns": list(self.columns),
                "rows": recs,
                "notes": self.notes,
            },
            indent=2,
        )

    def to_table(self) -> str:
        """Plain-text table for a terminal."""

        def fmt(v):
            if v is None:
                return "-"
            if isinstance(v, float):
                return "-" if not math.isfinite(v) else f"{v:.4g}"
            return str(v)

        cells = [[fmt(v) for v in r] for r in self.rows]
        widths = [
            max(len(str(c)), *(len(r[i]) for r in cells)) if cells else len(str(c))
            for i, c in enumerate(self.columns)
        ]
        line = "  ".join(str(c).ljust(w) for c, w in zip(self.columns, widths))
        out = [self.title, "=" * len(self.title)]
        out += [f"{k}: {v}" for k, v in self.meta.items()]
        out += ["", line, "-" * len(line)]
        out += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
        if self.notes:
            out += [""] + [f"* {n}" for n in self.notes]
        return "\n".join(out)
