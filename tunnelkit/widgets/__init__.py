"""Interactive explorers (ipywidgets + plotly FigureWidget), one module per notebook.

Each explorer is built on a pure callback ``params -> plotly Figure`` that tests call without a
kernel; the widget only wires sliders to it. Sliders use ``continuous_update=False`` and the figure
is built with its initial state before it is displayed (a FigureWidget changed before the page
connects shows stale in Voila).
"""

from .._lazy import lazy_exports

_EXPORTS = {
    "Explorer": "base",
    "cpd_explorer": "cpd",
    "curvature_figure": "cpd",
    "curvature_study": "cpd",
    "crlb_explorer": "crlb",
    "crlb_figure": "crlb",
    "design_explorer": "design",
    "design_figure": "design",
    "doppler_explorer": "doppler",
    "doppler_figure": "doppler",
    "epoch_explorer": "javelin",
    "epoch_view": "javelin",
    "mmax_explorer": "mmax",
    "mmax_figure": "mmax",
    "upf_explorer": "tracking",
    "upf_figure": "tracking",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
