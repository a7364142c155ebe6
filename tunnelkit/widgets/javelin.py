"""Epoch-by-epoch explorer of a JAVELIN run (notebook 04): slide over time and watch the
measurements, gates, associations, births and deaths."""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from .._checks import attributes
from .._validate import choice, integer
from ..plots.javelin import epoch_figure
from .base import Explorer, int_slider

__all__ = ["epoch_explorer", "epoch_view"]


def _drive_and_evaluation(drive, evaluation) -> None:
    attributes("drive", drive, ("truth", "sources", "base_station"), "a simulation.DriveData")
    attributes("evaluation", evaluation, ("run",), "a simulation.Evaluation")


def epoch_view(drive, evaluation, k: int, plane: str = "yz") -> go.Figure:
    """Pure callback: the figure of epoch ``k`` of ``evaluation`` (with reports) on ``drive``."""
    _drive_and_evaluation(drive, evaluation)
    integer("k", k, minimum=0), choice("plane", plane, ("yz", "xy"))
    reps = evaluation.run.reports if evaluation.run is not None else []
    if not reps:
        raise ValueError("evaluation: run the tracker with keep_reports=True to explore epochs")
    k = int(np.clip(k, 0, len(reps) - 1))
    src = drive.sources[k] if drive.sources else None
    return epoch_figure(
        reps[k], truth=drive.truth[k], base_station=drive.base_station, true_vues=src, plane=plane
    )


def epoch_explorer(drive, evaluation, *, k: int = 0) -> Explorer:
    """A slider over epochs and a cross-section / top-view switch around :func:`epoch_view`."""
    _drive_and_evaluation(drive, evaluation)
    integer("k", k, minimum=0)
    import ipywidgets as widgets

    n = len(evaluation.run.reports) if evaluation.run is not None else 1
    plane = widgets.ToggleButtons(
        options=[("cross-section", "yz"), ("top view", "xy")], value="yz", description="view"
    )

    def cb(k: int, plane: str) -> go.Figure:
        return epoch_view(drive, evaluation, k, plane)

    return Explorer(cb, {"k": int_slider("epoch k", k, 0, max(n - 1, 0)), "plane": plane})
