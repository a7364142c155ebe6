"""Notebook 03 explorer: what the curvature estimate measures as the array grows (M and SNR sliders).

:func:`curvature_figure` is the pure callback: for an ``n x n`` URA it traces the paths of one
epoch, picks the strongest road-marking (or road) reflection, and shows

* left: TLS curvature estimates ``kappa`` (eq. 17-20) from seeded noisy snapshots of the *exact*
  channel, against the two candidates — the distance to the reflection point (the SR-NF model's
  ``kappa``, eq. 51) and the distance to the VUE (the true wavefront centre);
* right: the largest SR-NF phase mismatch over the aperture, ``k0 max_m |delta_m - delta_m^SR|``,
  against the tolerance ``eps_Phi`` of Theorem 3.1 / 3.4 (notebook 02): below it the SR-NF model is
  an adequate description (M <= Mmax), above it the channel is only explained by the VUE.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from .._validate import integer, positive, real
from ..constants import C
from .base import Explorer, float_slider, int_slider

__all__ = ["cpd_explorer", "curvature_figure", "curvature_study"]

_KINDS = ("los", "wall", "road", "rrm")
#: array sides n of the mismatch-vs-M curve (right panel)
_SIDES = range(2, 21)


@lru_cache(maxsize=4)
def _route(scenario: str):
    from ..signal_route import SignalRoute

    return SignalRoute.from_scenario(scenario)


def _paths_for(side: int, k: int, scenario: str):
    from .. import propagation
    from ..arrays import make_array

    route = _route(scenario)
    ue = route.trajectory.position[k]
    base = propagation.select_array(route.arrays, ue)
    arr = make_array(
        side,
        side,
        fc=route.config.fc,
        azimuth=base.azimuth,
        elevation=base.elevation,
        origin=base.origin,
        name=base.name,
    )
    paths = propagation.trace_paths(
        route.tunnel, arr, ue, route.trajectory.velocity[k], fc=route.config.fc, kinds=_KINDS
    )
    return route, arr, paths


def _target(paths):
    refl = [p for p in paths if p.kind == "reflection"]
    if not refl:
        raise ValueError("k: no reflected path at this epoch")
    rrm = [p for p in refl if p.surface_kind == "rrm"]
    return max(rrm or refl, key=lambda p: abs(p.gain))


def mismatch(path, fc: float) -> float:
    """Largest SR-NF phase mismatch over the aperture [rad]: ``2 pi fc / c max|delta - delta_SR|``."""
    return float(2 * np.pi * fc / C * np.max(np.abs(path.delta("exact") - path.delta("srnf"))))


@lru_cache(maxsize=32)
def _mismatch_curve(k: int, scenario: str) -> tuple[float, ...]:
    """:func:`mismatch` of the target path for every side in ``_SIDES`` (slider-independent)."""
    fc = _route(scenario).config.fc
    return tuple(mismatch(_target(_paths_for(s, k, scenario)[2]), fc) for s in _SIDES)


def curvature_study(
    side: int,
    snr_offset_db: float = 0.0,
    k: int = 12,
    *,
    n_snapshots: int = 4,
    n_tones: int | None = None,
    scenario: str = "italiano2026-straight",
    seed: int = 0,
    refine: str = "joint",
) -> dict:
    """Numbers behind :func:`curvature_figure`: kappa estimates, both candidates, the mismatch.

    ``refine`` picks the extraction route (default the paper's, whose eq. 17-18 TLS the figure
    shows; ``"ml"`` the joint maximum-likelihood fit, which needs more antennas than paths)."""
    from ..channel import synthesize

    side = integer("side", side, minimum=2, maximum=64)
    real("snr_offset_db", snr_offset_db)
    k = integer("k", k, minimum=0)
    n_snapshots = integer("n_snapshots", n_snapshots, minimum=1, maximum=1000)
    if n_tones is not None:
        n_tones = integer("n_tones", n_tones, minimum=2)
    seed = integer("seed", seed, minimum=0)
    if not isinstance(scenario, str) or not scenario:
        raise TypeError(f"scenario: expected a scenario name, got {scenario!r}")
    n_epochs = len(_route(scenario).trajectory)
    if k >= n_epochs:
        raise ValueError(f"k: the route has {n_epochs} epochs (0 .. {n_epochs - 1}), got {k}")
    route, arr, paths = _paths_for(side, k, scenario)
    tgt = _target(paths)
    cfg = route.config
    kap = []
    for r in np.random.default_rng(seed).spawn(n_snapshots):
        snap = synthesize(
            paths, cfg, r, clock_bias=0.0, snr_offset_db=snr_offset_db, n_tones=n_tones
        )
        est = route.extract(snap.H, arr, len(paths), refine=refine)
        j = int(np.argmin(np.linalg.norm(est.direction - tgt.direction_local, axis=1)))
        kap.append(est.kappa_nf[j])
    return {
        "kappa": np.array(kap),
        "kappa_vue": tgt.length,
        "kappa_reflection": tgt.kappa_srnf,
        "mismatch": mismatch(tgt, cfg.fc),
        "surface": tgt.surface,
        "M": arr.M,
    }


def _verdicts(st: dict, eps_phi: float = 0.15) -> str:
    """Two separate verdicts for a :func:`curvature_study` result: the channel (is the SR-NF model
    within ``eps_phi`` of the exact one?) and the estimates (does their spread resolve the VUE
    from the reflection point?)."""
    channel = (
        "channel SR-NF within eps_Phi (M <= Mmax)"
        if st["mismatch"] <= eps_phi
        else "channel not SR-NF: only the VUE explains it (M > Mmax)"
    )
    kap = np.asarray(st["kappa"], dtype=float)
    kap = kap[np.isfinite(kap) & (kap > 0)]
    gap = abs(st["kappa_vue"] - st["kappa_reflection"])
    if kap.size == 0:
        estimate = "TLS: no curvature (far-field fallback)"
    elif np.ptp(kap) > gap / 2:
        estimate = f"TLS spread {kap.min():.1f}-{kap.max():.1f} m resolves neither"
    else:
        near = "VUE" if abs(np.median(kap) - st["kappa_vue"]) < gap / 2 else "reflection point"
        if (
            abs(np.median(kap) - st["kappa_vue"]) >= gap / 2
            and abs(np.median(kap) - st["kappa_reflection"]) >= gap / 2
        ):
            near = "neither"
        estimate = f"TLS kappa {np.median(kap):.1f} m: {near}"
    return f"{channel}; {estimate}"


def curvature_figure(
    side: int = 10,
    snr_offset_db: float = 0.0,
    k: int = 12,
    *,
    eps_phi: float = 0.15,
    n_snapshots: int = 4,
    n_tones: int | None = None,
    scenario: str = "italiano2026-straight",
) -> go.Figure:
    """The explorer's pure callback (see the module docstring)."""
    eps_phi = positive("eps_phi", eps_phi)
    st = curvature_study(
        side, snr_offset_db, k, n_snapshots=n_snapshots, n_tones=n_tones, scenario=scenario
    )
    fig = make_subplots(
        rows=1,
        cols=2,
        column_widths=[0.55, 0.45],
        horizontal_spacing=0.12,
        subplot_titles=(
            f"TLS kappa, {st['surface']} path, M = {st['M']}",
            "max SR-NF phase mismatch",
        ),
    )
    n = np.arange(st["kappa"].size)
    fig.add_scatter(
        x=n,
        y=st["kappa"],
        mode="markers",
        name="TLS kappa (exact channel)",
        marker={"size": 9, "color": "#1f77b4"},
        row=1,
        col=1,
    )
    for y, name, col in (
        (st["kappa_vue"], "distance to VUE", "#2ca02c"),
        (st["kappa_reflection"], "distance to reflection point (eq. 51)", "#d62728"),
    ):
        fig.add_scatter(
            x=[-0.5, n[-1] + 0.5],
            y=[y, y],
            mode="lines",
            name=name,
            line={"color": col, "dash": "dash"},
            row=1,
            col=1,
        )
    fig.add_scatter(
        x=np.array(_SIDES) ** 2,
        y=list(_mismatch_curve(k, scenario)),
        mode="lines+markers",
        name="max phase mismatch",
        line={"color": "#9467bd"},
        row=1,
        col=2,
    )
    fig.add_scatter(
        x=[4, 400],
        y=[eps_phi, eps_phi],
        mode="lines",
        name="eps_Phi",
        line={"color": "black", "dash": "dot"},
        row=1,
        col=2,
    )
    fig.add_scatter(
        x=[st["M"]],
        y=[st["mismatch"]],
        mode="markers",
        name="this array",
        marker={"size": 13, "color": "#ff7f0e"},
        row=1,
        col=2,
    )
    fig.update_xaxes(title_text="snapshot", row=1, col=1)
    fig.update_yaxes(title_text="kappa [m]", row=1, col=1)
    fig.update_xaxes(title_text="M = n x n", type="log", row=1, col=2)
    fig.update_yaxes(title_text="max phase mismatch [rad]", type="log", row=1, col=2)
    fig.update_layout(
        title={
            "text": f"epoch {k}, SNR offset {snr_offset_db:+.0f} dB: {_verdicts(st, eps_phi)}",
            "font": {"size": 14},
        },
        height=420,
        margin={"l": 60, "r": 20, "t": 90, "b": 50},
        legend={"orientation": "h", "y": -0.25},
    )
    return fig


def cpd_explorer(**kw) -> Explorer:
    """Sliders: array side n (M = n^2), SNR offset [dB], epoch k; see :func:`curvature_figure`."""
    return Explorer(
        lambda side, snr_offset_db, k: curvature_figure(side, snr_offset_db, k, **kw),
        {
            "side": int_slider("array side n (M = n²)", 10, 2, 20),
            "snr_offset_db": float_slider("SNR offset [dB]", 0.0, -20.0, 40.0, 5.0),
            "k": int_slider("epoch k", 12, 0, 28),
        },
    )
