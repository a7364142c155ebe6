"""Published numbers from the papers' tables (``data/reference/*.csv``)."""

from __future__ import annotations

import csv

from .scenarios import data_dir

__all__ = ["available", "load"]


def available() -> list[str]:
    """Names of the reference tables."""
    return sorted(p.stem for p in (data_dir() / "reference").glob("*.csv"))


def load(name: str) -> list[dict[str, str | float | None]]:
    """Rows of a reference table as dicts; numeric cells become floats, empty cells ``None``."""
    path = data_dir() / "reference" / f"{name}.csv"
    if not path.is_file():
        raise ValueError(
            f"name: unknown reference table {name!r}; available: {', '.join(available())}"
        )
    rows = []
    with path.open(newline="") as fh:
        for row in csv.DictReader(fh):
            out: dict[str, str | float | None] = {}
            for k, v in row.items():
                if v is None or v == "":
                    out[k] = None
                    continue
                try:
                    out[k] = float(v)
                except ValueError:
                    out[k] = v
            rows.append(out)
    return rows
