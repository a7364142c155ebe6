"""Plotly figure builders, one module per notebook, re-exported here.

Notebooks call these instead of carrying plotting boilerplate; each builder is a pure
``data -> go.Figure`` function so it can be tested without a kernel.
"""

from .common import COLORS, cdf_figure, line_figure
from .topview import tunnel_topview

__all__ = ["COLORS", "cdf_figure", "line_figure", "tunnel_topview"]
