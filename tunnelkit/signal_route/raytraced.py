"""The ray-traced channel on the signal route (``channel="sionna"``): a noisy SRS snapshot from a
traced noiseless tensor (:func:`tensor_snapshot`), a route's snapshot of one epoch
(:func:`raytraced_snapshot`) and a ray-traced route's own checks (:func:`check_raytraced`)."""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, instance, rng_or_error, sequence
from ..arrays import ArrayGeometry
from ..channel import (
    ChannelSnapshot,
    SRSConfig,
    add_noise,
    check_calibration,
    check_clock_bias,
    sample_clock_bias,
)
from ..constants import db2lin
from ..rt.cache import RayTracedChannel

__all__ = ["tensor_snapshot"]


def tensor_snapshot(
    H0,
    config: SRSConfig,
    rng: np.random.Generator,
    *,
    paths=(),
    clock_bias: float | None = None,
    snr_offset_db: float = 0.0,
    calibration=None,
) -> ChannelSnapshot:
    """A noisy snapshot from a noiseless tensor ``H0`` (M, Nf, Nt) given for a unit transmit
    power and no clock bias (a ray-traced channel, :mod:`tunnelkit.rt.cache`): scaled by
    ``sqrt(P_t)``, the clock bias (drawn from ``rng`` if None, as in
    :func:`~tunnelkit.channel.synthesize`) applied
    as ``exp(-j 2 pi s Df b)`` on tone ``s`` (eq. 1's ``tau_l = d_l / c + b`` for every path),
    ``calibration`` (M,) per element, then CN(0, N0) noise (``snr_offset_db`` as in
    :func:`~tunnelkit.channel.synthesize`). ``paths``: the true paths recorded in the snapshot (model "exact")."""
    if not isinstance(config, SRSConfig):
        raise TypeError(f"config: expected a channel.SRSConfig, got {type(config).__name__}")
    H0 = np.asarray(H0)
    if H0.ndim != 3 or not np.all(np.isfinite(H0)):
        raise ValueError(f"H0: expected a finite 3-D tensor, got shape {H0.shape}")
    rng = rng_or_error("rng", rng)
    paths = sequence("paths", paths, empty=True)  # empty: no true path recorded (the default)
    off = float(finite_array("snr_offset_db", snr_offset_db, ndim=0))
    cal = check_calibration(calibration, H0.shape[0])
    if clock_bias is None:
        clock_bias = sample_clock_bias(rng, config.clock_bias_sigma, config.clock_bias_limit)
    bias = check_clock_bias(clock_bias, config)
    ramp = np.exp(-2j * np.pi * config.tone_spacing * np.arange(H0.shape[1]) * bias)
    H = np.sqrt(config.tx_power) * H0 * ramp[None, :, None]
    if cal is not None:
        H = cal[:, None, None] * H
    n0 = config.noise_power / float(db2lin(off))
    return ChannelSnapshot(add_noise(H, n0, rng), n0, bias, "exact", tuple(paths), config)


def raytraced_snapshot(
    route, k: int, arr: ArrayGeometry, paths, rng: np.random.Generator, tunnel=None, **kw
) -> ChannelSnapshot:
    """The SRS snapshot of epoch ``k`` on ``route``'s ray-traced channel (``channel="sionna"``,
    what ``SignalRoute.raytraced_snapshot`` returns): the cached noiseless tensor (LoS left out unless "los" is in ``kinds``), clock bias, this
    route's calibration and SNR offset, noise (:func:`tensor_snapshot`);
    ``paths`` (the true paths) are recorded in the snapshot."""
    instance("arr", arr, ArrayGeometry)
    paths = sequence("paths", paths, empty=True)  # empty: no true path recorded
    if route.raytraced is None:
        raise ValueError("channel: this route has no ray-traced channel (channel='image')")
    name, H0 = route.raytraced.tensor(
        k, tunnel=route.tunnel if tunnel is None else tunnel, los="los" in route.kinds
    )
    if name != arr.name:
        raise RuntimeError(f"ray-traced epoch {k} is for array {name!r}, not {arr.name!r}")
    return tensor_snapshot(
        H0,
        route.config,
        rng,
        paths=paths,
        snr_offset_db=route.snr_offset_db,
        calibration=route.calibration.get(arr.name),
        **kw,
    )


def check_raytraced(route) -> None:
    """A ray-traced route's own checks (:class:`~tunnelkit.signal_route.route.SignalRoute` with
    ``raytraced``): a :class:`~tunnelkit.rt.cache.RayTracedChannel`, no synthetic diffuse
    multipath, the exact synthesis model."""
    instance("raytraced", route.raytraced, RayTracedChannel)
    if route.impairments.dmc is not None:
        raise ValueError(
            "impairments: dmc (synthetic diffuse multipath) cannot be added to the "
            "ray-traced channel, which has its own diffuse power"
        )
    if route.options.model != "exact":
        raise ValueError(
            f"model: {route.options.model!r} is a synthesis model of the image channel "
            "(channel='image'); the ray-traced channel (channel='sionna') synthesises "
            "every epoch from the tracer's paths"
        )
