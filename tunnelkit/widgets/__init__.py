"""Interactive explorers (ipywidgets + plotly FigureWidget), one module per notebook.

Each explorer is built on a pure callback ``params -> plotly Figure`` that tests call without a
kernel; the widget only wires sliders to it. Sliders use ``continuous_update=False`` and the figure
is built with its initial state before it is displayed (a FigureWidget changed before the page
connects shows stale in Voila).
"""

from .base import Explorer
from .crlb import crlb_explorer, crlb_figure

__all__ = ["Explorer", "crlb_explorer", "crlb_figure"]
