"""Plotly figure builders, one module per notebook, re-exported here.

Notebooks call these instead of carrying plotting boilerplate; each builder is a pure
``data -> go.Figure`` function so it can be tested without a kernel.
"""

from .._lazy import lazy_exports

_EXPORTS = {
    "COLORS": "common",
    "cdf_figure": "common",
    "line_figure": "common",
    "design_answer_figure": "design",
    "route_figure": "design",
    "size_figure": "design",
    "approach_cdfs": "doppler",
    "doppler_delay_figure": "doppler",
    "drive_topview": "doppler",
    "error_time_figure": "doppler",
    "information_figure": "doppler",
    "pcrlb_figure": "doppler",
    "profiles_figure": "doppler",
    "regime_figure": "doppler",
    "efficiency_figure": "efficiency",
    "derivation_figure": "fresnel",
    "fresnel_topview": "fresnel",
    "mismatch_figure": "fresnel",
    "mmax_range_figure": "fresnel",
    "ratio_map_figure": "fresnel",
    "epoch_figure": "javelin",
    "javelin_table_figure": "javelin",
    "tracks_count_figure": "javelin",
    "trajectories_figure": "javelin",
    "TableFigure": "tables",
    "report_table": "tables",
    "table": "tables",
    "tunnel_topview": "topview",
    "bound_ratio_figure": "tracking",
    "particle_cloud_figure": "tracking",
    "rmse_bound_figure": "tracking",
    "table_figure": "tracking",
    "tracks_figure": "tracking",
    "factors_figure": "tunnel3d",
    "paths_table_figure": "tunnel3d",
    "tunnel3d_figure": "tunnel3d",
    "wave_origins_figure": "tunnel3d",
}


__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
