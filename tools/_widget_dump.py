"""The last cell ``execute`` (tools/_lecture.py) appends to a notebook it runs: it prints the final
figure of every live plotly FigureWidget, by model id. The saved widget state alone can be stale:
a FigureWidget sends later changes as deltas, not in its state.
"""

from __future__ import annotations

import json

MARK = "@@tunnelkit-figure-widgets@@"
SOURCE = f"""
import json as _json
import sys as _sys
_figs = {{}}
if "plotly.basewidget" in _sys.modules:
    import plotly.io as _pio
    from ipywidgets.widgets import widget as _w
    _inst = getattr(_w, "_instances", None) or getattr(_w.Widget, "widgets", {{}})
    _base = _sys.modules["plotly.basewidget"].BaseFigureWidget
    _figs = {{k: _json.loads(_pio.to_json(v, validate=False))
             for k, v in list(_inst.items()) if isinstance(v, _base)}}
print("{MARK}" + _json.dumps(_figs))
"""


def add_widget_dump(nb) -> None:
    """Append the dump cell to a notebook about to run."""
    import nbformat

    nb.cells.append(nbformat.v4.new_code_cell(SOURCE))


def take_widget_dump(nb) -> dict:
    """Take the dump cell (run) off the notebook; model id -> figure, as it printed them."""
    dump = nb.cells.pop()
    text = "".join(o.get("text", "") for o in dump.get("outputs", []) if o.get("name") == "stdout")
    return json.loads(text.split(MARK, 1)[1]) if MARK in text else {}
