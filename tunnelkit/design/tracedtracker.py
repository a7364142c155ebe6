"""The ray-traced channel's trackers by name: which one a design sweep runs, checked once.

The names only (the trackers themselves are :mod:`tunnelkit.design.traced`'s, loaded with the
traced route): a sweep's arguments are checked before any array is prepared.
"""

from __future__ import annotations

from .._validate import choice

__all__ = ["TRACED_TRACKERS", "checked_tracker"]

#: the traced route's trackers (``tunnelkit design --traced-tracker``): ``"paths"`` every path
#: the geometry test keeps, told this array's long-run RMS errors
#: (:func:`tunnelkit.design.traced.traced_javelin`); ``"los"`` the path taken for the line of
#: sight alone, told its sigmas by its measured elevation from this array's survey
#: (:func:`tunnelkit.design.tracedlos.los_javelin`, :mod:`tunnelkit.design.los`); ``"auto"``
#: per array the one whose told model predicts the smaller RMS error over the route (the
#: posterior CRLB of what it is told: :mod:`tunnelkit.design.tracedbounds`, a prediction), the
#: default there (a sweep's ``traced_tracker=None``; ``"paths"`` on every other route);
#: ``"direct"`` the line of sight's tracker fed the direct fit, every atom of the visibility
#: model tied to one UE position and started from the tracker's own prediction
#: (:mod:`tunnelkit.design.traceddirect`; several seconds per epoch, never chosen by ``"auto"``)
TRACED_TRACKERS = ("paths", "los", "auto", "direct")


def checked_tracker(traced_tracker: str, mode: str, channel: str) -> str:
    """``traced_tracker`` checked: one of :data:`TRACED_TRACKERS`, and any but ``"paths"``
    only on the ray-traced channel's channel route (``mode`` "channel", ``channel`` "sionna"):
    refused naming both otherwise."""
    from ..signal_route.route import CHANNELS
    from .trackerfix import MODES

    traced_tracker = choice("traced_tracker", traced_tracker, TRACED_TRACKERS)
    mode, channel = choice("mode", mode, MODES), choice("channel", channel, CHANNELS)
    if traced_tracker != "paths" and (mode != "channel" or channel != "sionna"):
        raise ValueError(
            f"traced_tracker: {traced_tracker!r} tracks on the ray-traced channel's channel route "
            f"(mode 'channel' with channel 'sionna'), got mode {mode!r} with channel {channel!r}"
        )
    return traced_tracker
