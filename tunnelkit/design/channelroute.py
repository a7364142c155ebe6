"""The channel route of a design's array: the signal route the Monte-Carlo drives
(:meth:`tunnelkit.design.DesignSetup.signal_route`), on the image or the ray-traced channel, and
the ray-tracing settings a setup switched to the ray-traced channel takes from its scenario.
"""

from __future__ import annotations

from ..scenarios import load_scenario
from ..signal_route import RouteOptions, SignalRoute

#: nothing exported: the bodies of DesignSetup.signal_route and of variant's switch to the
#: ray-traced channel, on what they checked
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


def scenario_rt_settings(name: str):
    """The ray-tracing settings (:class:`tunnelkit.rt.RTSettings`) of scenario ``name`` (its
    ``[raytracing]``), which :meth:`~tunnelkit.design.DesignSetup.variant` takes when a setup
    switches to the ray-traced channel; a ``ValueError`` naming ``channel`` if it does not load."""
    from ..rt import RTSettings

    try:
        sc = load_scenario(name)
    except (FileNotFoundError, KeyError, ValueError) as exc:
        raise ValueError(
            f"channel: 'sionna' needs the ray-tracing settings of scenario "
            f"{name!r}, which does not load ({exc})"
        ) from None
    return RTSettings.from_scenario(sc)
