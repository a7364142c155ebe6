"""What a design is made of: candidate arrays and a scenario reduced to tunnel, mounts, route
and radio.

:class:`ArraySpec` (and :func:`parse_array`, ``"8x8"`` or ``"16"``) names a candidate array;
:class:`DesignSetup` holds the tunnel, the base-station :class:`Mount` points, the route and the
SRS configuration, and places a candidate array on every mount.

Conventions: a scenario file's ``base_station.position`` plus an array's ``offset`` is that
array's reference antenna ``p_0`` (element 0, a corner), everywhere (the scenario checker, the
channel, the lessons, the design). A design's :class:`Mount` is the **centre** of the scenario's
array, so the scenario's own array sits in the design exactly where the file puts it, and every
candidate array is centred on that point, its reference antenna where that puts it
(``mount_height`` moves the centre). Every element must lie inside the tunnel.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from .. import propagation
from .._physical import carrier
from .._validate import choice, finite_array, instance, integer, positive, record
from ..arrays import ArrayGeometry, rotation, ura
from ..channel import SRSConfig
from ..constants import wavelength
from ..scenarios import Scenario, Trajectory, load_scenario
from ..signal_route import CHANNELS
from .geometry import KINDS

__all__ = ["ArraySpec", "DesignSetup", "Mount", "parse_array"]


@dataclass(frozen=True)
class ArraySpec:
    """A candidate array: ``rows x cols`` elements (``rows = 1``: a ULA across the tunnel),
    spacing ``spacing_wl`` wavelengths (0.5 by default)."""

    rows: int
    cols: int
    spacing_wl: float = 0.5

    def __post_init__(self) -> None:
        integer("rows", self.rows, minimum=1)
        integer("cols", self.cols, minimum=1)
        positive("spacing_wl", self.spacing_wl)
        if self.rows * self.cols < 2:
            raise ValueError("arrays: an array needs at least 2 elements")

    @property
    def label(self) -> str:
        """``"8x8"`` for a URA, ``"16"`` for a ULA."""
        return str(self.cols) if self.rows == 1 else f"{self.rows}x{self.cols}"

    @property
    def n_elements(self) -> int:
        return self.rows * self.cols

    def spacing(self, fc: float) -> float:
        """Element spacing [m] at ``fc``."""
        return self.spacing_wl * wavelength(fc)

    def local(self, fc: float) -> np.ndarray:
        """Element positions (M, 3) in the array's local frame, element 0 at the origin."""
        return ura(self.rows, self.cols, self.spacing(fc))

    def aperture(self, fc: float) -> float:
        """Largest distance between two elements [m] (the diagonal of a URA)."""
        return self.spacing(fc) * float(np.hypot(self.rows - 1, self.cols - 1))


_SPEC = re.compile(r"\s*(\d+)\s*(?:[xX×]\s*(\d+))?\s*")


def parse_array(spec, spacing_wl: float = 0.5) -> ArraySpec:
    """``"8x8"`` -> 8 x 8 URA, ``"16"`` -> 16-element ULA, an :class:`ArraySpec` passes through.

    Anything else raises ``ValueError`` naming ``spec`` (the parameter every design function
    passes it on from).
    """
    if isinstance(spec, ArraySpec):
        return spec
    text = spec
    if not isinstance(text, str):
        raise TypeError(f"spec: expected a string such as '8x8', got {type(text).__name__}")
    m = _SPEC.fullmatch(text)
    if not m:
        raise ValueError(
            f"spec: cannot read {text!r}; expected N (a ULA) or NxM (a URA), e.g. 16 or 8x8"
        )
    rows, cols = (1, int(m.group(1))) if m.group(2) is None else (int(m.group(1)), int(m.group(2)))
    if rows < 1 or cols < 1 or rows * cols < 2:
        raise ValueError(f"spec: {text!r} has fewer than 2 elements")
    return ArraySpec(rows, cols, spacing_wl)


# --- the setup: tunnel, mount, route, radio -----------------------------------------------------


@dataclass(frozen=True)
class Mount:
    """Where one array hangs: its centre (3,) and boresight azimuth/elevation [rad]."""

    name: str
    centre: np.ndarray
    azimuth: float
    elevation: float

    def __post_init__(self) -> None:
        record(self, shapes={"centre": (3,)})


@dataclass(frozen=True)
class DesignSetup:
    """A scenario reduced to what a design needs: tunnel, mounts, route and radio.

    Build with :meth:`from_scenario` (overriding carrier, bandwidth, tilt, mount height);
    :meth:`arrays` places a candidate array on every mount (validated inside the tunnel).
    ``channel`` is the channel source of :meth:`signal_route` (the Monte-Carlo's ``"channel"``
    mode): ``"image"`` (eq. 1) or ``"sionna"`` (the ray-traced channel with ``rt_settings``,
    cached per scenario and array, :class:`tunnelkit.rt.cache.RayTracedChannel`).
    """

    name: str
    tunnel: object
    mounts: tuple[Mount, ...]
    trajectory: object
    config: object
    kinds: tuple[str, ...] = KINDS
    channel: str = "image"
    rt_settings: object = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise TypeError(f"name: expected the scenario's name, got {self.name!r}")
        if not isinstance(self.tunnel, propagation.Tunnel3D):
            raise TypeError(
                f"tunnel: expected a propagation.Tunnel3D, got {type(self.tunnel).__name__}"
            )
        if not isinstance(self.mounts, tuple) or not self.mounts:
            raise TypeError(f"mounts: expected a non-empty tuple of Mount, got {self.mounts!r:.60}")
        for i, m in enumerate(self.mounts):
            if not isinstance(m, Mount):
                raise TypeError(f"mounts[{i}]: expected a Mount, got {type(m).__name__}")
        if not isinstance(self.trajectory, Trajectory):
            raise TypeError(
                f"trajectory: expected a scenarios.Trajectory, got {type(self.trajectory).__name__}"
            )
        if not isinstance(self.config, SRSConfig):
            raise TypeError(
                f"config: expected a channel.SRSConfig, got {type(self.config).__name__}"
            )
        kinds = self.kinds
        if not isinstance(kinds, tuple) or not kinds:
            raise TypeError(f"kinds: expected a non-empty tuple of path kinds, got {kinds!r:.60}")
        for k in kinds:
            choice("kinds", k, propagation.PATH_KINDS)
        choice("channel", self.channel, CHANNELS)
        if self.rt_settings is not None:
            from ..rt import RTSettings  # the ray tracer loads only for a "sionna" channel

            instance("rt_settings", self.rt_settings, RTSettings)

    @classmethod
    def from_scenario(
        cls,
        scenario,
        *,
        fc: float | None = None,
        bandwidth: float | None = None,
        tilt_deg: float | None = None,
        mount_height: float | None = None,
        channel: str = "image",
    ) -> DesignSetup:
        """From a scenario name/path or a loaded scenario.

        ``fc`` [Hz] and ``bandwidth`` [Hz] replace the radio's (the SRS keeps its subcarrier
        spacing and comb and fills the band: ``n_rb = floor(bandwidth / (12 scs))``);
        ``tilt_deg`` (down-tilt, every array: elevation ``-tilt``) and ``mount_height`` [m]
        (every array's centre height) move the mount. ``channel``: "image" or "sionna" (the
        ray-traced channel, settings from the scenario's ``[raytracing]``).
        """
        sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
        if not isinstance(sc, Scenario):
            raise TypeError(
                f"scenario: expected a name or a Scenario, got {type(scenario).__name__}"
            )
        tun = sc.tunnel()
        if not isinstance(tun, propagation.Tunnel3D):
            raise ValueError(
                f"scenario: {sc.name!r} has a 2-D tunnel; the design needs a 3-D tunnel "
                "(semicircular, rectangular or horseshoe)"
            )
        mounts = tuple(  # the centre of the scenario's array (module docstring)
            Mount(a.name, a.world.mean(axis=0), a.azimuth, a.elevation)
            for a in propagation.scenario_arrays(sc)
        )
        choice("channel", channel, CHANNELS)
        rts = None
        if channel == "sionna":
            from ..rt import RTSettings

            rts = RTSettings.from_scenario(sc)
        setup = cls(
            sc.name,
            tun,
            mounts,
            sc.trajectory(tun),
            SRSConfig.from_scenario(sc),
            channel=channel,
            rt_settings=rts,
        )
        return setup.variant(
            fc=fc, bandwidth=bandwidth, tilt_deg=tilt_deg, mount_height=mount_height
        )

    def variant(
        self,
        *,
        fc: float | None = None,
        bandwidth: float | None = None,
        tilt_deg: float | None = None,
        mount_height: float | None = None,
        channel: str | None = None,
    ) -> DesignSetup:
        """A copy with another carrier, bandwidth, down-tilt, mount height or channel source
        (``None`` keeps). ``channel="sionna"`` on a setup without ray-tracing settings takes
        them from the scenario of the setup's name (its ``[raytracing]``)."""
        rts = self.rt_settings
        if channel is not None:
            choice("channel", channel, CHANNELS)
            if channel == "sionna" and rts is None:
                from .channelroute import scenario_rt_settings  # the ray tracer's, when asked for

                rts = scenario_rt_settings(self.name)
        else:
            channel = self.channel
        if mount_height is not None:
            _mount_height_inside(self, float(finite_array("mount_height", mount_height, ndim=0)))
        cfg = self.config
        if fc is not None:
            cfg = replace(cfg, fc=carrier("fc", fc))
        if bandwidth is not None:
            bw = positive("bandwidth", bandwidth)
            n_rb = int(np.floor(bw / (12 * cfg.scs) * (1 + 1e-9)))
            if n_rb < 1:
                raise ValueError(f"bandwidth: {bw:g} Hz is narrower than one resource block")
            cfg = replace(cfg, bandwidth=bw, n_rb=n_rb)
        mounts = []
        for m in self.mounts:
            el, centre = m.elevation, m.centre
            if tilt_deg is not None:
                t = float(finite_array("tilt_deg", tilt_deg, ndim=0))
                if not -90.0 <= t <= 90.0:
                    raise ValueError(f"tilt_deg: must lie in [-90, 90] deg, got {t}")
                el = -np.radians(t)
            if mount_height is not None:
                centre = centre.copy()
                centre[2] = float(finite_array("mount_height", mount_height, ndim=0))
            if not np.all(self.tunnel.contains(centre, margin=0.0)):
                raise ValueError(
                    f"mount: the base-station mount {centre.round(3).tolist()} of array "
                    f"{m.name!r} lies outside the tunnel"
                )
            mounts.append(Mount(m.name, centre, m.azimuth, float(el)))
        return replace(self, mounts=tuple(mounts), config=cfg, channel=channel, rt_settings=rts)

    @property
    def fc(self) -> float:
        return float(self.config.fc)

    def signal_route(self, spec):
        """The measurement route of ``spec`` on this design as the Monte-Carlo drives it
        (:class:`tunnelkit.signal_route.SignalRoute`): each epoch's paths carry the CRLB at their
        estimate, and Algorithm 1 drops only what no clock bias explains."""
        from .channelroute import channel_route  # the route loads when a design drives it

        spec = parse_array(spec)
        return channel_route(self, spec, self.arrays(spec))

    def arrays(self, spec) -> list[ArrayGeometry]:
        """``spec`` placed, centred, on every mount; refused (``ValueError`` naming ``arrays``,
        the array, the mount and how many elements lie outside) if any element falls outside
        the tunnel's exact cross-section at its mount (facets included)."""
        spec = parse_array(spec)
        loc = spec.local(self.fc)
        out = []
        for m in self.mounts:
            rot = rotation(m.azimuth, m.elevation)
            origin = m.centre - rot @ loc.mean(axis=0)
            inside = self.tunnel.contains(origin + loc @ rot.T, margin=0.0)
            if not np.all(inside):
                raise ValueError(
                    f"arrays: the {spec.label} array ({spec.aperture(self.fc):.3f} m diagonal at "
                    f"{self.fc / 1e9:g} GHz) on mount {m.name!r}, centred at "
                    f"{m.centre.round(3).tolist()}, does not fit inside the tunnel cross-section: "
                    f"{int((~inside).sum())} of {spec.n_elements} elements outside; choose a "
                    "smaller array or move the mount"
                )
            out.append(
                _placed(spec, self.fc, tuple(origin.tolist()), m.azimuth, m.elevation, m.name)
            )
        return out


def _mount_height_inside(setup: DesignSetup, h: float) -> None:
    """Refuse a mount height that puts a mount's centre outside the tunnel (``mount_height``)."""
    for m in setup.mounts:
        centre = np.array([m.centre[0], m.centre[1], h])
        if not np.all(setup.tunnel.contains(centre, margin=0.0)):
            raise ValueError(
                f"mount_height: {h:g} m puts the base-station mount of array {m.name!r} at "
                f"{centre.round(3).tolist()}, outside the tunnel"
            )


@lru_cache(maxsize=64)
def _placed(spec: ArraySpec, fc: float, origin: tuple, azimuth: float, elevation: float, name: str):
    """An :class:`ArrayGeometry` (cached: its constructor checks every pair of elements)."""
    return ArrayGeometry(spec.local(fc), np.array(origin), azimuth, elevation, name=name)
