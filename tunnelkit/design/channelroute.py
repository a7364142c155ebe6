"""The channel route of a design's array: the signal route the Monte-Carlo drives
(:meth:`tunnelkit.design.DesignSetup.signal_route`), on the image or the ray-traced channel.
"""

from __future__ import annotations

from ..signal_route import RouteOptions, SignalRoute

#: nothing exported: the body of DesignSetup.signal_route, on a setup and arrays it placed
__all__: list[str] = []


def channel_route(setup, spec, arrays) -> SignalRoute:
    """The measurement route of ``spec`` (an ArraySpec) placed on ``setup``'s mounts as
    ``arrays``, as the Monte-Carlo drives it: each epoch's paths carry the CRLB at their
    estimate, and Algorithm 1 drops only what no clock bias explains."""
    raytraced = None
    if setup.channel == "sionna":
        from ..rt import RayTracedChannel

        raytraced = RayTracedChannel(
            setup.tunnel,
            arrays,
            setup.trajectory,
            setup.config,
            setup.rt_settings,
            label=f"{setup.name}-design-{spec.label}",
        )
    return SignalRoute(
        setup.tunnel,
        arrays,
        setup.trajectory,
        setup.config,
        kinds=setup.kinds,
        raytraced=raytraced,
        options=RouteOptions(report_covariance=True, bias_aware_delay_check=True),
    )
