"""Interactive explorers (ipywidgets + plotly FigureWidget), one module per notebook.

Each explorer is built on a pure callback ``params -> plotly Figure`` that tests call without a
kernel; the widget only wires sliders to it. Sliders use ``continuous_update=False`` and the figure
is built with its initial state before it is displayed (a FigureWidget changed before the page
connects shows stale in Voila).
"""

from .base import (
    Explorer,
)
from .cpd import (
    cpd_explorer,
    curvature_figure,
    curvature_study,
)
from .crlb import (
    crlb_explorer,
    crlb_figure,
)
from .design import (
    design_explorer,
    design_figure,
)
from .doppler import (
    doppler_explorer,
    doppler_figure,
)
from .javelin import (
    epoch_explorer,
    epoch_view,
)
from .mmax import (
    mmax_explorer,
    mmax_figure,
)
from .tracking import (
    upf_explorer,
    upf_figure,
)

__all__ = [
    "Explorer",
    "cpd_explorer",
    "crlb_explorer",
    "crlb_figure",
    "curvature_figure",
    "curvature_study",
    "design_explorer",
    "design_figure",
    "doppler_explorer",
    "doppler_figure",
    "epoch_explorer",
    "epoch_view",
    "mmax_explorer",
    "mmax_figure",
    "upf_explorer",
    "upf_figure",
]
