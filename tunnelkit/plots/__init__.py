"""Plotly figure builders, one module per notebook, re-exported here.

Notebooks call these instead of carrying plotting boilerplate; each builder is a pure
``data -> go.Figure`` function so it can be tested without a kernel.
"""

from .common import (
    COLORS,
    cdf_figure,
    line_figure,
)
from .design import (
    design_answer_figure,
    route_figure,
    size_figure,
)
from .doppler import (
    approach_cdfs,
    doppler_delay_figure,
    drive_topview,
    error_time_figure,
    information_figure,
    pcrlb_figure,
    profiles_figure,
    regime_figure,
)
from .efficiency import (
    efficiency_figure,
)
from .fresnel import (
    derivation_figure,
    fresnel_topview,
    mismatch_figure,
    mmax_range_figure,
    ratio_map_figure,
)
from .javelin import (
    epoch_figure,
    javelin_table_figure,
    tracks_count_figure,
    trajectories_figure,
)
from .tables import (
    TableFigure,
    report_table,
    table,
)
from .topview import (
    tunnel_topview,
)
from .tracking import (
    bound_ratio_figure,
    particle_cloud_figure,
    rmse_bound_figure,
    table_figure,
    tracks_figure,
)
from .tunnel3d import (
    factors_figure,
    paths_table_figure,
    tunnel3d_figure,
    wave_origins_figure,
)

__all__ = [
    "COLORS",
    "TableFigure",
    "approach_cdfs",
    "bound_ratio_figure",
    "cdf_figure",
    "derivation_figure",
    "design_answer_figure",
    "doppler_delay_figure",
    "drive_topview",
    "efficiency_figure",
    "epoch_figure",
    "error_time_figure",
    "factors_figure",
    "fresnel_topview",
    "information_figure",
    "javelin_table_figure",
    "line_figure",
    "mismatch_figure",
    "mmax_range_figure",
    "particle_cloud_figure",
    "paths_table_figure",
    "pcrlb_figure",
    "profiles_figure",
    "ratio_map_figure",
    "regime_figure",
    "report_table",
    "rmse_bound_figure",
    "route_figure",
    "size_figure",
    "table",
    "table_figure",
    "tracks_count_figure",
    "tracks_figure",
    "trajectories_figure",
    "tunnel3d_figure",
    "tunnel_topview",
    "wave_origins_figure",
]
