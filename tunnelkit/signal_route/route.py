"""The route itself (:class:`SignalRoute`): scenario objects built once, then per epoch
propagation -> channel tensor -> extraction -> Algorithm 1."""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import numpy as np

from .. import propagation
from .._validate import (
    choice,
    instance,
    integer,
    real,
    rng_or_error,
    sequence,
)
from ..arrays import ArrayGeometry
from ..channel import ChannelSnapshot, Impairments, SRSConfig, synthesize
from ..constants import C
from ..propagation import PATH_KINDS, Tunnel3D
from ..scenarios import Scenario, Trajectory, load_scenario
from .measurements import Epoch
from .options import MAX_SECOND_ORDER, RouteOptions

__all__ = ["CHANNELS", "MAX_SECOND_ORDER", "RouteOptions", "SignalRoute"]


#: channel sources of a route: ``"image"`` (eq. 1 from the image method's first-order paths) or
#: ``"sionna"`` (the tensor of every path Sionna RT traces per element, :mod:`tunnelkit.rt.cache`)
CHANNELS = ("image", "sionna")


def check_arrays(arrays) -> None:
    """A non-empty list of ArrayGeometry with distinct names (calibration is keyed by name)."""
    names = {}
    for i, a in enumerate(sequence("arrays", arrays)):
        if instance(f"arrays[{i}]", a, ArrayGeometry).name in names:
            raise ValueError(
                f"arrays: arrays[{i}] and arrays[{names[a.name]}] are both named {a.name!r}; "
                "names must be distinct (the calibration is keyed by name)"
            )
        names[a.name] = i


@dataclass
class SignalRoute:
    """Scenario objects built once; :meth:`epoch` runs propagation -> channel -> extraction.

    ``kinds`` selects path families (see :func:`tunnelkit.propagation.trace_paths`);
    ``n_paths=None`` means L known (the number of traced paths, as in the paper).
    ``impairments`` (off by default) adds what eq. 1 leaves out (:class:`tunnelkit.channel.Impairments`);
    build an impaired route with :meth:`with_impairments`, which draws each array's calibration
    error once (``calibration``: array name -> (M,) complex gains).
    ``raytraced`` (None by default: the image channel, eq. 1 from the image method's paths): a
    :class:`tunnelkit.rt.cache.RayTracedChannel` makes this a ray-traced route (:attr:`channel`
    ``"sionna"``, :data:`CHANNELS`): each epoch's noiseless tensor is every path Sionna RT
    returns per element, specular of any order and diffuse, traced once and cached, with the
    clock bias and the noise drawn on it per run. The true paths (``Epoch.paths``, the number of
    paths to extract, the matching) stay the image method's first-order specular paths; the LoS
    filter of ``kinds`` and the epoch's ``tunnel`` (road markings removed) apply to the ray
    tracer too, the other ``kinds`` filters do not. On it the spatial-wideband term is in the
    tensor by construction and ``impairments.dmc`` is refused (the ray tracer has its own
    diffuse power). ``options`` (:class:`~tunnelkit.signal_route.options.RouteOptions`, all off
    by default): the synthesis model, second-order nuisance paths, reported covariances and the
    fit's judging; change them with :meth:`with_options`.
    """

    tunnel: object
    arrays: list
    trajectory: object
    config: SRSConfig
    kinds: tuple[str, ...] = ("los", "wall", "ceiling", "road", "rrm")
    snr_offset_db: float = 0.0
    impairments: Impairments = field(default_factory=Impairments)
    calibration: dict = field(default_factory=dict)
    raytraced: object = field(default=None, repr=False)
    options: RouteOptions = field(default_factory=RouteOptions)

    def __post_init__(self) -> None:
        instance("tunnel", self.tunnel, Tunnel3D)
        check_arrays(self.arrays)
        instance("trajectory", self.trajectory, Trajectory)
        instance("config", self.config, SRSConfig)
        for k in sequence("kinds", self.kinds):
            choice("kinds", k, PATH_KINDS)
        real("snr_offset_db", self.snr_offset_db)
        instance("impairments", self.impairments, Impairments)
        instance("calibration", self.calibration, dict)
        if self.calibration:
            from ..calibration import check_route_calibration  # loaded with a calibration

            check_route_calibration(self.calibration, {a.name: a.M for a in self.arrays})
        opts = instance("options", self.options, RouteOptions)
        budget = opts.bias_budget
        if budget is not None and budget.exists.shape[0] != len(self.trajectory):
            raise ValueError(
                f"bias_budget: {budget.exists.shape[0]} epochs, the trajectory has "
                f"{len(self.trajectory)}"
            )
        if self.raytraced is not None:
            from .raytraced import check_raytraced  # the ray tracer loads only when asked for

            check_raytraced(self)
        elif opts.diffuse_floor:
            raise ValueError(
                "diffuse_floor: only the ray-traced channel (channel='sionna') has diffuse "
                "power, not the image channel (channel='image')"
            )

    @property
    def channel(self) -> str:
        """The route's channel source (:data:`CHANNELS`): ``"sionna"`` with a ray-traced channel
        attached (:attr:`raytraced`), else ``"image"``."""
        return "image" if self.raytraced is None else "sionna"

    def with_options(self, **changes) -> SignalRoute:
        """A copy of this route with ``changes`` to its :class:`RouteOptions`
        (``route.with_options(second_order=2)``); checked as a new route is."""
        unknown = sorted(set(changes) - {f.name for f in fields(RouteOptions)})
        if unknown:
            raise TypeError(
                f"{', '.join(unknown)}: not a route option; the options are "
                f"{', '.join(f.name for f in fields(RouteOptions))}"
            )
        return replace(self, options=replace(self.options, **changes))

    @property
    def min_d(self) -> float:
        """Algorithm 1's delay check ``d >= min_d`` on this route: 0 as printed, ``-c b_max`` with
        ``bias_aware_delay_check``."""
        return -C * self.config.clock_bias_limit if self.options.bias_aware_delay_check else 0.0

    def with_impairments(self, impairments: Impairments, rng: np.random.Generator) -> SignalRoute:
        """A copy of this route whose arrays carry ``impairments``: each array's calibration error
        drawn once from ``rng`` (in the order of ``arrays``), the same in every epoch."""
        if not isinstance(impairments, Impairments):
            raise TypeError(
                f"impairments: expected a channel.Impairments, got {type(impairments).__name__}"
            )
        rng = rng_or_error("rng", rng)
        cal = {a.name: impairments.draw(rng, a.M) for a in self.arrays}
        cal = {k: v for k, v in cal.items() if v is not None}
        return replace(self, impairments=impairments, calibration=cal)

    @classmethod
    def from_scenario(
        cls, scenario, *, channel: str = "image", rt_settings=None, cache_dir=None, **kw
    ) -> SignalRoute:
        """Build from a scenario name or a loaded :class:`tunnelkit.scenarios.Scenario`;
        ``channel="sionna"`` attaches the scenario's ray-traced channel (settings from its
        ``[raytracing]`` section unless ``rt_settings`` is given, cache under ``cache_dir``,
        :mod:`tunnelkit.rt.cache`)."""
        sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
        if not isinstance(sc, Scenario):
            raise TypeError(
                f"scenario: expected a name or a Scenario, got {type(scenario).__name__}"
            )
        rt_kw = (rt_settings, cache_dir)
        if choice("channel", channel, CHANNELS) != "sionna" and rt_kw != (None, None):
            raise ValueError("rt_settings, cache_dir: only used with channel='sionna'")
        tun = sc.tunnel()
        arrays = propagation.scenario_arrays(sc)
        traj = sc.trajectory(tun)
        config = SRSConfig.from_scenario(sc)
        if channel == "sionna":
            from ..rt import RayTracedChannel, RTSettings

            settings = RTSettings.from_scenario(sc) if rt_settings is None else rt_settings
            kw["raytraced"] = RayTracedChannel(
                tun, arrays, traj, config, settings, label=sc.name, cache_dir=cache_dir
            )
        return cls(tun, arrays, traj, config, **kw)

    def paths(self, k: int, tunnel=None) -> tuple[ArrayGeometry, list]:
        """The array facing the vehicle and the true paths at epoch ``k`` (first order, then the
        strongest ``second_order`` second-order paths)."""
        k = integer("k", k, minimum=0)
        if k >= len(self.trajectory):
            raise ValueError(f"k: epoch {k} beyond the trajectory ({len(self.trajectory)} epochs)")
        ue, vel = self.trajectory.position[k], self.trajectory.velocity[k]
        arr = propagation.select_array(self.arrays, ue)
        tun = self.tunnel if tunnel is None else tunnel
        if not self.options.second_order:
            return arr, propagation.trace_paths(
                tun, arr, ue, vel, fc=self.config.fc, kinds=self.kinds
            )
        every = propagation.trace_paths(
            tun, arr, ue, vel, fc=self.config.fc, kinds=self.kinds, order=2
        )
        first = [p for p in every if p.kind != propagation.SECOND_ORDER]
        second = [p for p in every if p.kind == propagation.SECOND_ORDER]
        second.sort(key=lambda p: -abs(p.gain))
        return arr, first + sorted(second[: self.options.second_order], key=lambda p: p.length)

    def snapshot(self, paths, arr: ArrayGeometry, rng: np.random.Generator, **kw):
        """The SRS tensor of ``paths`` at ``arr`` (:func:`tunnelkit.channel.synthesize`) with
        this route's model, SNR offset and impairments; ``kw`` (``clock_bias``, ...) passed on."""
        instance("arr", arr, ArrayGeometry)
        return synthesize(
            paths,
            self.config,
            rng,
            model=self.options.model,
            snr_offset_db=self.snr_offset_db,
            calibration=self.calibration.get(arr.name),
            spatial_wideband=self.impairments.spatial_wideband,
            dmc=self.impairments.dmc,
            **kw,
        )

    def raytraced_snapshot(
        self, k: int, arr: ArrayGeometry, paths, rng: np.random.Generator, tunnel=None, **kw
    ) -> ChannelSnapshot:
        """The SRS snapshot of epoch ``k`` on the ray-traced channel (``channel="sionna"``,
        :func:`tunnelkit.signal_route.raytraced.raytraced_snapshot`)."""
        from .raytraced import raytraced_snapshot

        return raytraced_snapshot(self, k, arr, paths, rng, tunnel, **kw)

    def ml_noise_power(self, k: int, snapshot: ChannelSnapshot, tunnel=None) -> float | None:
        """The noise power the ML extraction tests its fit against at epoch ``k``: ``None``
        (estimated from the tensor) unless ``diffuse_floor``, then the snapshot's noise power
        plus the transmit power times the epoch's diffuse power per element (ray tracer)."""
        k = integer("k", k, minimum=0, maximum=len(self.trajectory) - 1)
        if not isinstance(snapshot, ChannelSnapshot):
            raise TypeError(
                f"snapshot: expected a channel.ChannelSnapshot, got {type(snapshot).__name__}"
            )
        if tunnel is not None and type(tunnel) is not type(self.tunnel):
            raise TypeError(
                f"tunnel: expected a {type(self.tunnel).__name__}, got {type(tunnel).__name__}"
            )
        if not self.options.diffuse_floor:
            return None
        tun = self.tunnel if tunnel is None else tunnel
        p_diffuse = self.raytraced.epoch(k, tun)["power"]["diffuse"]
        return float(snapshot.noise_power + self.config.tx_power * p_diffuse)

    def extract(self, H, arr: ArrayGeometry, n_paths: int, **extract_kw):
        """:func:`tunnelkit.extraction.extract_paths` of ``H`` at ``arr`` with this route's
        radio (``refine``, ... in ``extract_kw``)."""
        from ..extraction import extract_paths

        instance("arr", arr, ArrayGeometry)
        return extract_paths(H, n_paths, arr, self.config, **extract_kw)

    def draw(self, k: int, rng: np.random.Generator, *, tunnel=None, clock_bias=None) -> tuple:
        """SRS slot ``k`` before any extraction, what :meth:`epoch` extracts from: the array, the
        true paths and the snapshot (traced, synthesised with noise and clock bias; every draw
        from ``rng`` the slot makes), ``(array, paths, snapshot)``."""
        rng = rng_or_error("rng", rng)
        arr, paths = self.paths(k, tunnel)
        if self.channel == "sionna":
            snap = self.raytraced_snapshot(k, arr, paths, rng, tunnel, clock_bias=clock_bias)
        else:
            snap = self.snapshot(paths, arr, rng, clock_bias=clock_bias)
        return arr, paths, snap

    def epoch(
        self,
        k: int,
        rng: np.random.Generator,
        *,
        n_paths: int | None = None,
        tunnel=None,
        clock_bias: float | None = None,
        **extract_kw,
    ) -> Epoch:
        """Simulate SRS slot ``k``: trace, synthesise (noise, clock bias), extract, Algorithm 1
        (:func:`tunnelkit.signal_route.epoch.run_epoch`)."""
        from .epoch import run_epoch

        return run_epoch(self, k, rng, n_paths, tunnel, clock_bias, extract_kw)
