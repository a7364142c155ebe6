"""Tables: shown as HTML in a notebook, exportable as a plotly table whose height fits its rows.

A :class:`TableFigure` is a ``go.Figure`` holding one ``go.Table`` (so ``.data[0].cells.values``,
``write_image`` and the lecture tools work as for any figure) whose notebook display is a plain
HTML ``<table>``: selectable text, right-aligned numbers, headers never clipped, no blank space
below the last row. ``.show()`` displays the same HTML.
"""

from __future__ import annotations

import html
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import plotly.graph_objects as go

from .._validate import callable_, instance, sequence, text
from ..report import Report

__all__ = ["TableFigure", "report_table", "table"]

_ROW_PX, _HEADER_PX, _CHAR_PX, _TITLE_PX = 22, 26, 7.2, 36


def _fmt_default(v: Any) -> str:
    if v is None:
        return "-"
    if isinstance(v, float | np.floating):
        return f"{v:.4g}" if np.isfinite(v) else "-"
    return str(v)


def _numeric(text: str) -> bool:
    try:
        float(text.replace("−", "-"))
    except ValueError:
        return False
    return True


class TableFigure(go.Figure):
    """A plotly table figure that a notebook displays as an HTML table (see module docstring)."""

    def __init__(
        self,
        columns: Sequence[str],
        cells: Sequence[Sequence[str]],
        title: str = "",
        notes: Sequence[str] = (),
    ):
        columns = [str(c) for c in sequence("columns", columns, empty=True)]
        cells = [
            [str(v) for v in sequence("cells", col, empty=True)]
            for col in sequence("cells", cells, empty=True)
        ]
        if len(cells) != len(columns):
            raise ValueError(f"cells: expected {len(columns)} columns of cells, got {len(cells)}")
        title = text("title", title, empty=True)
        notes = sequence("notes", notes, empty=True)
        n_rows = len(cells[0]) if cells else 0
        super().__init__(
            go.Table(
                header={"values": columns, "align": "left", "fill_color": "#f0f0f0"},
                cells={"values": cells, "align": "left", "height": _ROW_PX},
            )
        )
        self.update_layout(
            title=title or None,
            height=_table_height(columns, cells, n_rows, bool(title)),
            margin={"l": 10, "r": 10, "t": _TITLE_PX + 4 if title else 4, "b": 4},
        )
        self._tk_columns, self._tk_cells, self._tk_title = columns, cells, title
        self._tk_notes = [str(n) for n in notes]

    def to_html_table(self) -> str:
        """The table as an HTML fragment (a caption, a header row, one row per row)."""
        cols, cells = self._tk_columns, self._tk_cells
        num = [all(_numeric(v) or v == "-" for v in col) and any(col) for col in cells]

        def td(v: str, right: bool, tag: str = "td") -> str:
            style = ' style="text-align:right"' if right else ' style="text-align:left"'
            return f"<{tag}{style}>{html.escape(v)}</{tag}>"

        head = "".join(td(c, num[i], "th") for i, c in enumerate(cols))
        rows = "".join(
            "<tr>" + "".join(td(cells[i][r], num[i]) for i in range(len(cols))) + "</tr>"
            for r in range(len(cells[0]) if cells else 0)
        )
        cap = (
            f'<caption style="caption-side:top;text-align:left;font-weight:600">'
            f"{html.escape(self._tk_title)}</caption>"
            if self._tk_title
            else ""
        )
        notes = "".join(f"<li>{html.escape(n)}</li>" for n in self._tk_notes)
        return (
            f'<table class="tk-table">{cap}<thead><tr>{head}</tr></thead>'
            f"<tbody>{rows}</tbody></table>"
            + (f'<ul class="tk-notes">{notes}</ul>' if notes else "")
        )

    def _repr_html_(self) -> str:
        return self.to_html_table()

    def _repr_mimebundle_(self, include=None, exclude=None, **kwargs):
        title = f"{self._tk_title}\n" if self._tk_title else ""
        text = title + " | ".join(self._tk_columns)
        return {"text/html": self.to_html_table(), "text/plain": text}

    def _ipython_display_(self) -> None:
        from IPython.display import HTML, display

        display(HTML(self.to_html_table()))

    def show(self, *args, **kwargs) -> None:
        """Display the HTML table (as the notebook's output for this call)."""
        self._ipython_display_()


def _table_height(columns, cells, n_rows: int, titled: bool, width: int = 900) -> int:
    """Pixel height of the plotly table: title + header + rows, rows taller where text wraps."""
    if not columns:
        return 80
    col_px = max((width - 20) / len(columns), 40.0)
    per_line = max(int(col_px / _CHAR_PX), 1)

    def lines(text: str) -> int:
        return max(math.ceil(len(text) / per_line), 1)

    header = _HEADER_PX * max(lines(c) for c in columns)
    rows = sum(_ROW_PX * max(lines(col[r]) for col in cells) for r in range(n_rows))
    return int(header + rows + (_TITLE_PX + 4 if titled else 4) + 8)


def table(
    columns: Sequence[str],
    rows: Sequence[Sequence[Any]],
    *,
    title: str = "",
    fmt: Callable[[Any], str] = _fmt_default,
    notes: Sequence[str] = (),
) -> TableFigure:
    """A :class:`TableFigure` from row sequences, each value formatted by ``fmt``; ``notes`` are
    listed under the HTML table."""
    columns = sequence("columns", columns, empty=True)
    rows = sequence("rows", rows, empty=True)
    title = text("title", title, empty=True)
    fmt = callable_("fmt", fmt)
    notes = sequence("notes", notes, empty=True)
    for i, r in enumerate(rows):
        if isinstance(r, str | bytes) or not isinstance(r, Sequence | np.ndarray):
            raise TypeError(f"rows: row {i} is a {type(r).__name__}, expected a sequence")
        if len(r) != len(columns):
            raise ValueError(f"rows: row {i} has {len(r)} values for {len(columns)} columns")
    cells = [[fmt(r[i]) for r in rows] for i in range(len(columns))]
    return TableFigure(columns, cells, title, notes)


def report_table(report) -> TableFigure:
    """A :class:`tunnelkit.reproduce.Report` (what ``tunnelkit reproduce`` prints as text) as a
    table: its title with its settings, its rows, its notes."""
    instance("report", report, Report)
    meta = ", ".join(f"{k}: {v}" for k, v in report.meta.items())
    title = f"{report.title} ({meta})" if meta else report.title
    return table(report.columns, report.rows, title=title, notes=report.notes)
