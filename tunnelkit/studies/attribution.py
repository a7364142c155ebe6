"""Attribution: what eq. 1 misses on the ray-traced channel, and what each mechanism costs.

On the traced channel the ML route's first-order estimates are far off (notebook 07 section 7,
``docs/raytraced-channel.md``) while on eq. 1's own tensor it sits at its CRLB. The ray tracer
differs from eq. 1 by several mechanisms at once. :func:`attribution` switches them off in the
tracer one at a time (:data:`CONFIGURATIONS`, each an :class:`~tunnelkit.rt.settings.RTSettings`
over the scenario's own) and measures, per configuration, array and kind of first-order path:

* the **pseudo-true bias**: the parameters eq. 1 fits to the noiseless traced tensor
  (:func:`tunnelkit.studies.misspecified.pseudo_true`, started at the true paths) minus the
  image method's geometric truth: world azimuth and elevation [deg], the delay distance ``d``
  [m] (no clock bias in the noiseless tensor), the curvature radius ``kappa`` [m] (over the paths
  whose fitted curvature is not held at the far field; those are counted), and the residual's
  share of the tensor's power;
* the **estimator's errors** at the operating SNR: ``draws`` noisy snapshots per epoch
  (:meth:`SignalRoute.draw <tunnelkit.signal_route.SignalRoute.draw>`: the cached tensor, clock
  bias and noise drawn), the ML extraction with the image method's number of paths
  (:func:`tunnelkit.extraction.extract_paths`), its estimates matched to the true paths
  (:func:`tunnelkit.evaluation.match_paths`); RMS and median of |error| (``d`` with the drawn
  clock bias removed);
* what that costs in **position**: a one-epoch fix (:func:`one_epoch_fix`: weighted nonlinear
  least squares of the UE's horizontal position and the clock-bias range over the matched
  paths' azimuth, elevation and ``d``, each path through the true plane of its kind, the UE's
  height known, curvature not used, weights :data:`FIX_SIGMAS`) on the pseudo-true parameters
  (the position bias the model error alone leaves) and on each noisy extraction.

Two reference rows use eq. 1's own tensor of the image method's paths
(:func:`tunnelkit.channel.channel_tensor`): ``eq1`` as the estimator assumes it, and
``eq1+wideband`` with the spatial-wideband term (each element's own delay), which every
per-element or ``"centre"`` traced tensor carries and eq. 1 lacks. Routes are built only through
:meth:`SignalRoute.from_scenario <tunnelkit.signal_route.SignalRoute.from_scenario>`, one cache
directory per configuration (``<cache_dir>/attribution/<configuration>``), so each trace is kept.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from .._validate import (
    boolean,
    choice,
    finite_array,
    instance,
    integer,
    nonnegative,
    record,
    sequence,
    text,
)
from ..channel import channel_tensor
from ..constants import C
from ..evaluation import match_paths
from ..extraction import extract_paths, ml_truth
from ..rt import RTSettings, default_cache_dir
from ..scenarios import Scenario, load_scenario
from ..signal_route import SignalRoute
from ..signal_route.raytraced import tensor_snapshot
from .misspecified import pseudo_true
from .truth import angles_of_theta, path_differences, path_truth, world_angles

__all__ = [
    "CONFIGURATIONS",
    "FIX_SIGMAS",
    "KINDS",
    "REFERENCES",
    "Attribution",
    "AttributionRow",
    "ConfigSummary",
    "attribution",
    "config_settings",
    "one_epoch_fix",
    "scenario_with_array",
]

#: configuration -> (what it switches off, RTSettings overrides on the scenario's settings)
CONFIGURATIONS: dict[str, tuple[str, dict]] = {
    "scenario": ("nothing: the scenario's traced channel", {}),
    "no-diffuse": ("(a) diffuse scattering", {"scattering_coefficient": 0.0}),
    "depth-1": ("(b) second-order bounces", {"max_depth": 1}),
    "centre": (
        "(c) per-element tracing: one ray set, spherical waves",
        {"array_tracing": "centre"},
    ),
    "synthetic": (
        "(c') per-element tracing: Sionna's synthetic array (plane waves, one delay)",
        {"array_tracing": "synthetic"},
    ),
    "tr38901": (
        "(e) the pattern switched ON: 3GPP TR 38.901 elements",
        {"antenna_pattern": "tr38901"},
    ),
    "first-order": ("(a) + (b)", {"scattering_coefficient": 0.0, "max_depth": 1}),
    "first-order-metal": (
        "(a) + (b) + (d) the reflection coefficient's angle dependence (metal: |Gamma| ~ 1)",
        {
            "scattering_coefficient": 0.0,
            "max_depth": 1,
            "wall_material": "metal",
            "road_material": "metal",
        },
    ),
    "first-order-centre": (
        "(a) + (b) + (c)",
        {"scattering_coefficient": 0.0, "max_depth": 1, "array_tracing": "centre"},
    ),
    "diffuse-alone": (
        "all but (a): diffuse scattering alone on the clean first-order channel",
        {"max_depth": 1, "array_tracing": "centre"},
    ),
    "second-order-alone": (
        "all but (b): second-order bounces alone on the clean first-order channel",
        {"scattering_coefficient": 0.0, "array_tracing": "centre"},
    ),
    "all-off": (
        "(a) + (b) + (c) + (d)",
        {
            "scattering_coefficient": 0.0,
            "max_depth": 1,
            "array_tracing": "centre",
            "wall_material": "metal",
            "road_material": "metal",
        },
    ),
}
#: rows from eq. 1's own tensor of the image method's paths (module docstring)
REFERENCES = ("eq1", "eq1+wideband")
#: the kinds of first-order path, in the table's order
KINDS = ("los", "ceiling", "road", "rrm", "wall")
#: the one-epoch fix's standard deviations: azimuth, elevation [rad], ``d`` [m] (about the
#: pooled RMS errors of the traced 8 x 8 record, ``data/rt/design``: 10.7 deg, 8.3 deg, 1.16 m)
FIX_SIGMAS = (math.radians(10.0), math.radians(10.0), 1.0)


def measured_record(rec, counts: tuple[str, ...] = ()) -> None:
    """Check a record of measured magnitudes (RMS, median, share, time): every float field >= 0
    or NaN (nothing measured); ``counts`` integers >= 0 (the studies' records)."""
    floats = tuple(f.name for f in dataclasses.fields(rec) if f.type == "float")
    record(rec, allow_nan=floats, nonnegative=(*floats, *counts))


@dataclass(frozen=True)
class AttributionRow:
    """One configuration, array and kind of path (``"all"``: every kind pooled). Bias: the
    pseudo-true parameters minus the truth; errors: the noisy extraction's; each as the RMS
    and the median of |.| over the path-epochs (``kappa`` over the finite ones, ``far_field``
    counting the pseudo-true curvatures held at the far field); NaN where nothing was measured."""

    config: str
    array: str
    kind: str
    n_bias: int
    bias_phi_deg: float
    med_bias_phi_deg: float
    bias_psi_deg: float
    med_bias_psi_deg: float
    bias_d_m: float
    med_bias_d_m: float
    bias_kappa_m: float
    med_bias_kappa_m: float
    far_field: int
    n_err: int
    rms_phi_deg: float
    med_phi_deg: float
    rms_psi_deg: float
    med_psi_deg: float
    rms_d_m: float
    med_d_m: float
    rms_kappa_m: float
    med_kappa_m: float

    def __post_init__(self) -> None:
        measured_record(self, counts=("n_bias", "far_field", "n_err"))


@dataclass(frozen=True)
class ConfigSummary:
    """One configuration and array: the residual at the pseudo-true paths (its share of the
    tensor's power, median over epochs), the fits that reached a strict minimum, the one-epoch
    fix's horizontal error [m] on the pseudo-true parameters (RMS over epochs: the bias) and on
    the noisy extractions (RMS, median), the received power's shares (diffuse, second order and
    higher), the median trace time [s]."""

    config: str
    array: str
    residual_share: float
    converged: str
    fix_bias_m: float
    fix_bias_median_m: float
    fix_rms_m: float
    fix_median_m: float
    diffuse_share: float
    higher_share: float
    trace_s: float

    def __post_init__(self) -> None:
        measured_record(self)


@dataclass
class Attribution:
    """What :func:`attribution` measured: ``rows`` per kind, ``summary`` per configuration, and
    the run's provenance (``scenario``, ``arrays``, ``epochs``, ``draws``, ``seed``,
    ``settings``: configuration -> its RTSettings as a dict, ``wall_s``)."""

    rows: list[AttributionRow]
    summary: list[ConfigSummary]
    scenario: str
    arrays: tuple[str, ...]
    epochs: tuple[int, ...]
    draws: int
    seed: int
    settings: dict = field(default_factory=dict)
    wall_s: float = 0.0

    def __post_init__(self) -> None:
        for i, r in enumerate(sequence("rows", self.rows)):
            instance(f"rows[{i}]", r, AttributionRow)
        for i, r in enumerate(sequence("summary", self.summary)):
            instance(f"summary[{i}]", r, ConfigSummary)
        text("scenario", self.scenario)
        for a in sequence("arrays", self.arrays):
            text("arrays", a)
        for k in sequence("epochs", self.epochs):
            integer("epochs", k, minimum=0)
        integer("draws", self.draws, minimum=0)
        integer("seed", self.seed, minimum=0)
        instance("settings", self.settings, dict)
        nonnegative("wall_s", self.wall_s)

    def markdown(self) -> str:
        """The two tables (summary, then per kind) as markdown."""
        out = [
            "| configuration | array | residual / power | strict minima | fix bias RMS / median "
            "[m] | fix error RMS / median [m] | diffuse / 2nd+ power share |",
            "| --- | --- | --- | --- | --- | --- | --- |",
        ]
        for s in self.summary:
            out.append(
                f"| {s.config} | {s.array} | {_g(s.residual_share)} | {s.converged} | "
                f"{_f(s.fix_bias_m, 3)} / {_f(s.fix_bias_median_m, 3)} | {_f(s.fix_rms_m, 3)} / {_f(s.fix_median_m, 3)} | "
                f"{_f(s.diffuse_share, 4)} / {_f(s.higher_share, 3)} |"
            )
        out += [
            "",
            "| configuration | array | path | bias az RMS / med [deg] | bias el RMS / med [deg] | "
            "bias d RMS / med [m] | bias kappa RMS / med [m] (far field) | n | error az RMS / "
            "med [deg] | error el RMS / med [deg] | error d RMS / med [m] | error kappa RMS / med "
            "[m] |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        ]
        for r in self.rows:
            out.append(
                f"| {r.config} | {r.array} | {r.kind} | {_f(r.bias_phi_deg, 2)} / "
                f"{_f(r.med_bias_phi_deg, 2)} | {_f(r.bias_psi_deg, 2)} / "
                f"{_f(r.med_bias_psi_deg, 2)} | {_f(r.bias_d_m, 3)} / {_f(r.med_bias_d_m, 3)} | "
                f"{_f(r.bias_kappa_m, 1)} / {_f(r.med_bias_kappa_m, 1)} ({r.far_field} of "
                f"{r.n_bias}) | {r.n_err} | {_f(r.rms_phi_deg, 2)} / "
                f"{_f(r.med_phi_deg, 2)} | {_f(r.rms_psi_deg, 2)} / {_f(r.med_psi_deg, 2)} | "
                f"{_f(r.rms_d_m, 3)} / {_f(r.med_d_m, 3)} | {_f(r.rms_kappa_m, 1)} / "
                f"{_f(r.med_kappa_m, 1)} |"
            )
        return "\n".join(out)


def _f(x: float, n: int) -> str:
    return "-" if not np.isfinite(x) else f"{x:.{n}f}"


def _g(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{x:.3g}"


def scenario_with_array(scenario, shape: tuple[int, int]):
    """``scenario`` (a name or a loaded Scenario) with every base-station array of ``shape``
    (rows, columns) elements, mounted as the scenario mounts its own, named
    ``<name>-<rows>x<cols>`` (the ray-tracing cache's label)."""

    sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
    instance("scenario", sc, Scenario)
    shape = sequence("shape", shape)
    if len(shape) != 2:
        raise ValueError(f"shape: expected (rows, columns), got {shape!r}")
    rows, cols = (integer("shape", n, minimum=1, maximum=64) for n in shape)
    if rows * cols < 2:
        raise ValueError(f"shape: an array has at least 2 elements, got {rows} x {cols}")
    sec = copy.deepcopy(sc.sections)
    for a in sec["base_station"]["arrays"]:
        a["shape"] = [rows, cols]
    return dataclasses.replace(sc, sections=sec, name=f"{sc.name}-{rows}x{cols}")


def config_settings(base, name: str):
    """The :class:`~tunnelkit.rt.settings.RTSettings` of configuration ``name`` (a key of
    :data:`CONFIGURATIONS`): ``base`` with its overrides."""

    instance("base", base, RTSettings)
    choice("name", name, tuple(CONFIGURATIONS))
    return dataclasses.replace(base, **CONFIGURATIONS[name][1])


def _check_sigmas(sigmas) -> np.ndarray:
    sig = finite_array("sigmas", sigmas, shape=(3,))
    if np.any(sig <= 0):
        raise ValueError(f"sigmas: expected three positive numbers, got {sig.tolist()}")
    return sig


def one_epoch_fix(phi, psi, d, paths, ue, origin, sigmas=FIX_SIGMAS) -> np.ndarray:
    """Horizontal position error (2,) [m] of the one-epoch fix (module docstring) from path
    ``j``'s world azimuth ``phi[j]``, elevation ``psi[j]`` [rad] and delay distance ``d[j]``
    [m] (clock bias included), ``paths[j]`` the true path it is matched to (its wave origin is
    the UE mirrored in that path's plane; the LoS's is the UE), ``ue`` the true position (the
    start, and its height is taken as known), ``origin`` the array's reference antenna.
    ``sigmas``: (azimuth, elevation [rad], ``d`` [m]) weights. NaN with fewer than two paths."""
    from scipy.optimize import least_squares

    phi, psi, d = (finite_array(k, v, ndim=1) for k, v in (("phi", phi), ("psi", psi), ("d", d)))
    paths = sequence("paths", paths, empty=True)
    if not (len(paths) == phi.size == psi.size == d.size):
        raise ValueError("phi, psi, d, paths: expected one value per path")
    sig = _check_sigmas(sigmas)
    if len(paths) < 2:
        return np.full(2, np.nan)
    ue, o = finite_array("ue", ue, shape=(3,)), finite_array("origin", origin, shape=(3,))
    mirror = []  # (normal, point on the plane) per path, None for the LoS
    for p in paths:
        w = p.source - p.ue
        nw = float(np.linalg.norm(w))
        mirror.append(None if nw < 1e-6 else (w / nw, np.asarray(p.point, float)))

    def residuals(x):
        pos = np.array([x[0], x[1], ue[2]])
        out = []
        for j, m in enumerate(mirror):
            v = pos if m is None else pos - 2.0 * float((pos - m[1]) @ m[0]) * m[0]
            rel = v - o
            r = float(np.linalg.norm(rel))
            a, e = math.atan2(rel[1], rel[0]), math.asin(rel[2] / r)
            out += [
                float(np.angle(np.exp(1j * (phi[j] - a)))) / sig[0],
                (psi[j] - e) / sig[1],
                (d[j] - r - x[2]) / sig[2],
            ]
        return np.array(out)

    beta0 = float(np.median(d - np.array([p.length for p in paths])))
    x = least_squares(residuals, np.array([ue[0], ue[1], beta0]), method="lm").x
    return x[:2] - ue[:2]


def _rms(x) -> float:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x**2))) if x.size else float("nan")


def _med(x) -> float:
    x = np.abs(np.asarray(x, float))
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size else float("nan")


def _rows(config, array, bias: list, errs: list) -> list[AttributionRow]:
    """Rows per kind and ``"all"`` from ``(kind, (4,) bias)`` and ``(kind, (4,) error)``."""
    out = []
    kinds = [k for k in KINDS if any(b[0] == k for b in bias) or any(e[0] == k for e in errs)]
    for kind in [*kinds, "all"]:
        b = np.array([x[1] for x in bias if kind in ("all", x[0])]).reshape(-1, 4)
        e = np.array([x[1] for x in errs if kind in ("all", x[0])]).reshape(-1, 4)
        out.append(
            AttributionRow(
                config, array, kind, b.shape[0],
                *(f(b[:, i]) for i in range(4) for f in (_rms, _med)),
                int(np.sum(~np.isfinite(b[:, 3]))),
                e.shape[0],
                *(f(e[:, i]) for i in range(4) for f in (_rms, _med)),
            )
        )  # fmt: skip
    return out


def _extract(route, H, arr, L):

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fit's own test flags every traced epoch
        return extract_paths(H, L, arr, route.config)


def _measure(name, label, route, epochs, draws, rng, tensor_of, sigmas, progress) -> tuple:
    """One configuration on one array: rows and summary (module docstring). ``tensor_of(k,
    arr, paths)`` -> the noiseless tensor (transmit power included) and a noisy snapshot
    maker ``rng -> snapshot``."""

    cfg = route.config
    bias, errs, shares, conv, fix_b, fix_e = [], [], [], [], [], []
    for k in epochs:
        arr, paths = route.paths(k)
        H0, draw = tensor_of(k, arr, paths)
        tru = path_truth(paths, arr)
        kinds = [p.surface_kind for p in paths]
        pt = pseudo_true(H0, arr.local, cfg.fc, ml_truth(paths, arr, cfg),
                         noise_power=cfg.noise_power)  # fmt: skip
        est = angles_of_theta(pt["theta"], pt["mu_f"], arr, cfg)
        idx = np.arange(len(paths))
        for j, e in enumerate(path_differences(est, tru, idx, idx)):
            bias.append((kinds[j], e))
        shares.append(pt["residual_power"] / float(np.mean(np.abs(H0) ** 2)))
        conv.append(bool(pt["converged"]))
        ue = route.trajectory.position[k]
        dx = one_epoch_fix(est["phi"], est["psi"], est["d"], paths, ue, arr.origin, sigmas)
        fix_b.append(float(np.hypot(*dx)))
        for _ in range(draws):
            snap = draw(rng)
            fit = _extract(route, snap.H, arr, len(paths))
            u = arr.dir_to_world(fit.direction)
            phi, psi = world_angles(u)
            e = {"phi": phi, "psi": psi, "d": np.asarray(fit.d, float),
                 "kappa": np.where(np.isfinite(fit.kappa), fit.kappa, np.inf)}  # fmt: skip
            t = match_paths(fit.d, u, paths, clock_bias=snap.clock_bias)
            rows = np.flatnonzero(t >= 0)
            for r, x in zip(rows, path_differences(e, tru, rows, t[rows], C * snap.clock_bias),
                            strict=True):  # fmt: skip
                errs.append((kinds[t[r]], x))
            sel = [paths[t[r]] for r in rows]
            dx = one_epoch_fix(e["phi"][rows], e["psi"][rows], e["d"][rows], sel, ue,
                               arr.origin, sigmas)  # fmt: skip
            fix_e.append(float(np.hypot(*dx)))
        if progress:
            print(f"  {name} {label} epoch {k}: residual {shares[-1]:.3g}", flush=True)
    return _rows(name, label, bias, errs), (shares, conv, fix_b, fix_e)


def _summary(name, label, parts, powers, trace_s) -> ConfigSummary:
    shares, conv, fix_b, fix_e = parts
    return ConfigSummary(
        name, label, float(np.median(shares)), f"{sum(conv)} of {len(conv)}", _rms(fix_b), _med(fix_b),
        _rms(fix_e), _med(fix_e), *powers, trace_s,
    )  # fmt: skip


def attribution(
    scenario: str = "italiano2026-straight",
    *,
    arrays=((8, 8),),
    configs=None,
    references: bool = True,
    epochs=(0, 5, 10, 15, 20, 25),
    draws: int = 2,
    seed: int = 0,
    cache_dir=None,
    samples_per_src: int | None = None,
    sigmas=FIX_SIGMAS,
    progress: bool = False,
) -> Attribution:
    """The attribution table (module docstring) of ``scenario``'s drive at ``epochs`` for each
    array shape of ``arrays`` and each configuration of ``configs`` (names of
    :data:`CONFIGURATIONS`, all by default), with the :data:`REFERENCES` rows when
    ``references``; ``draws`` noisy snapshots per epoch (0: the bias alone), drawn from one
    generator seeded with ``seed`` per configuration and array (so every configuration sees the
    same clock biases and noise), ``cache_dir`` the root of the traces
    (:func:`tunnelkit.rt.default_cache_dir` by default; each configuration in
    ``attribution/<name>`` under it), ``samples_per_src`` the rays (the scenario's by default),
    ``sigmas`` the one-epoch fix's weights (:func:`one_epoch_fix`)."""
    from pathlib import Path

    t0 = time.perf_counter()
    sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
    configs = list(CONFIGURATIONS) if configs is None else list(sequence("configs", configs))
    for c in configs:
        if c not in CONFIGURATIONS:
            raise ValueError(f"configs: expected names of {list(CONFIGURATIONS)}, got {c!r}")
    references = boolean("references", references)
    draws = integer("draws", draws, minimum=0, maximum=100)
    seed = integer("seed", seed, minimum=0)
    boolean("progress", progress)
    _check_sigmas(sigmas)
    if cache_dir is not None and not isinstance(cache_dir, str | os.PathLike):
        raise TypeError(f"cache_dir: expected a directory path, got {type(cache_dir).__name__}")
    shapes = [tuple(sequence("arrays", a)) for a in sequence("arrays", arrays)]
    root = Path(default_cache_dir() if cache_dir is None else cache_dir) / "attribution"
    base = RTSettings.from_scenario(sc)
    if samples_per_src is not None:
        base = dataclasses.replace(base, samples_per_src=integer("samples_per_src",
                                                                 samples_per_src, minimum=100))  # fmt: skip
    T = len(sc.trajectory())
    ks = tuple(integer("epochs", k, minimum=0, maximum=T - 1) for k in sequence("epochs", epochs))
    if not ks:
        raise ValueError("epochs: expected at least one epoch")
    rows, summary, settings = [], [], {}
    for shape in shapes:
        sca = scenario_with_array(sc, shape)
        label = f"{shape[0]}x{shape[1]}"
        if references:
            img = SignalRoute.from_scenario(sca)
            amp = math.sqrt(img.config.tx_power)
            for name in REFERENCES:
                wb = name == "eq1+wideband"

                def tensor_of(k, arr, paths, wb=wb, img=img, amp=amp):
                    H = channel_tensor(paths, img.config, spatial_wideband=wb)
                    if not wb:
                        return H, lambda rng: img.draw(k, rng)[2]
                    return H, lambda rng: tensor_snapshot(H / amp, img.config, rng, paths=paths)

                r, parts = _measure(name, label, img, ks, draws, np.random.default_rng(seed),
                                    tensor_of, sigmas, progress)  # fmt: skip
                rows += r
                summary.append(_summary(name, label, parts, (0.0, 0.0), float("nan")))
        for name in configs:
            st = config_settings(base, name)
            settings[name] = dataclasses.asdict(st)
            route = SignalRoute.from_scenario(sca, channel="sionna", rt_settings=st,
                                              cache_dir=str(root / name))  # fmt: skip
            route.raytraced.prepare(epochs=ks, progress=progress)
            amp = math.sqrt(route.config.tx_power)

            def tensor_of(k, arr, paths, route=route, amp=amp):
                return amp * route.raytraced.tensor(k)[1], lambda rng: route.draw(k, rng)[2]

            r, parts = _measure(name, label, route, ks, draws, np.random.default_rng(seed),
                                tensor_of, sigmas, progress)  # fmt: skip
            rows += r
            pw = [route.raytraced.epoch(k)["power"] for k in ks]
            tot = [sum(p.values()) for p in pw]
            powers = (float(np.median([p["diffuse"] / t for p, t in zip(pw, tot, strict=True)])),
                      float(np.median([p["specular2+"] / t for p, t in zip(pw, tot, strict=True)])))  # fmt: skip
            trace_s = float(np.median([route.raytraced.epoch(k)["trace_s"] for k in ks]))
            summary.append(_summary(name, label, parts, powers, trace_s))
            del route
    return Attribution(
        rows, summary, sc.name, tuple(f"{a}x{b}" for a, b in shapes), ks, draws, seed, settings,
        time.perf_counter() - t0,
    )  # fmt: skip
