"""Notebook 08 explorer: carrier, bandwidth, array size, tilt and mount height -> the position error
bound along the tunnel, the SR-NF overlay and the smallest array meeting the target.

:func:`design_figure` is the pure callback (bounds only, vectorised: no Monte-Carlo). The explorer
adds a button that runs a JAVELIN Monte-Carlo for the current design with a progress bar.

Figure layout (stable, for tests and lecture scripts): ``layout.title.text`` starts with
``"Recommended: "`` followed by the array label or ``"none"``; ``layout.meta`` holds ``array``,
``n_elements``, ``peb_median_m``, ``srnf_valid_share``, ``met_share``, ``recommended``,
``fits`` (False when the array does not fit at this mount); traces as in
:func:`tunnelkit.plots.design.route_traces`.
"""

from __future__ import annotations

from functools import lru_cache

import ipywidgets as widgets
import numpy as np
import plotly.graph_objects as go

from .. import design
from ..plots.design import route_figure
from .base import Explorer, float_slider, int_slider

__all__ = ["MAX_POINTS", "SIZES", "DesignExplorer", "design_explorer", "design_figure"]

#: square URAs the recommendation searches, smallest first
SIZES = (2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32)

#: the explorer evaluates at most this many epochs, evenly spread along the route
MAX_POINTS = 24


@lru_cache(maxsize=8)
def _base(scenario: str) -> design.DesignSetup:
    return design.DesignSetup.from_scenario(scenario)


def design_figure(
    fc_ghz: float = 28.0,
    bandwidth_mhz: float = 400.0,
    n: int = 8,
    tilt_deg: float = 20.0,
    mount_height: float = 5.8,
    *,
    scenario: str = "example-rectangular-28ghz",
    target: float = 0.2,
    share: float = 0.9,
    eps_phi: float = 0.15,
) -> go.Figure:
    """PEB of an ``n x n`` URA along the route, SR-NF failures marked, and the recommendation.

    Pure: the same arguments give the same figure. A design that does not fit (array outside the
    tunnel at this mount) gives an empty figure whose title says so instead of raising.
    """
    try:
        setup = _base(scenario).variant(
            fc=fc_ghz * 1e9,
            bandwidth=bandwidth_mhz * 1e6,
            tilt_deg=tilt_deg,
            mount_height=mount_height,
        )
        spec = design.ArraySpec(int(n), int(n))
        T = len(setup.trajectory)
        ep = np.unique(np.linspace(0, T - 1, min(T, MAX_POINTS)).round().astype(int))
        b = design.route_bounds(setup, spec, eps_phi=eps_phi, epochs=ep)
    except ValueError as exc:
        return go.Figure(
            layout={
                "title": {"text": f"Recommended: none — {exc}", "font": {"size": 12}},
                "height": 620,
                "autosize": True,
                "meta": {"fits": False, "recommended": None},
            }
        )
    rec, _ = design.smallest_meeting(
        setup,
        [f"{k}x{k}" for k in SIZES],
        target=target,
        share=share,
        eps_phi=eps_phi,
        epochs=ep,
    )
    met = float(np.mean((b.peb <= target) & b.srnf_valid))
    med = float(np.median(b.peb))
    if rec is None:
        title = (
            f"Recommended: none — no square URA up to {SIZES[-1]}x{SIZES[-1]} meets PEB ≤ "
            f"{100 * target:g} cm with SR-NF valid on {100 * share:.0f} % of the route"
        )
    else:
        title = (
            f"Recommended: {rec.label} — the smallest square URA with PEB ≤ {100 * target:g} cm "
            f"and SR-NF valid on ≥ {100 * share:.0f} % of the route"
        )
    sub = (
        f"{spec.label} at {fc_ghz:g} GHz, {bandwidth_mhz:g} MHz, tilt {tilt_deg:g}°, mount "
        f"{mount_height:g} m: median PEB {100 * med:.3g} cm · SR-NF valid "
        f"{100 * b.srnf_valid.mean():.0f} % · target met {100 * met:.0f} % · aperture "
        f"{100 * spec.aperture(setup.fc):.3g} cm"
    )
    meta = {
        "array": spec.label,
        "n_elements": spec.n_elements,
        "peb_median_m": med,
        "srnf_valid_share": float(b.srnf_valid.mean()),
        "met_share": met,
        "recommended": None if rec is None else rec.label,
        "fits": True,
    }
    return route_figure(b, target=target, title=title, subtitle=sub, meta=meta)


class DesignExplorer(Explorer):
    """The sliders and figure of :class:`~tunnelkit.widgets.base.Explorer`, plus a Monte-Carlo
    button (JAVELIN on the current design, progress bar, result printed below)."""

    def __init__(self, callback, controls, *, scenario: str, runs: int, seed: int) -> None:
        super().__init__(callback, controls, columns=3)
        self.scenario, self.runs, self.seed = scenario, runs, seed
        self.button = widgets.Button(
            description=f"Monte-Carlo ({runs} drives)", icon="play", layout={"width": "220px"}
        )
        self.output = widgets.Output()
        self.button.on_click(self._run)
        self.widget = widgets.VBox([*self.widget.children, self.button, self.output])

    def run_monte_carlo(self) -> dict:
        """JAVELIN RMSE (95 % CI) of the current design; what the button runs."""
        v = self.values
        setup = _base(self.scenario).variant(
            fc=v["fc_ghz"] * 1e9,
            bandwidth=v["bandwidth_mhz"] * 1e6,
            tilt_deg=v["tilt_deg"],
            mount_height=v["mount_height"],
        )
        return design.javelin_rmse(setup, f"{v['n']}x{v['n']}", self.runs, self.seed, progress=True)

    def _run(self, _button) -> None:  # pragma: no cover - needs a browser click
        self.output.clear_output()
        with self.output:
            try:
                res = self.run_monte_carlo()
            except ValueError as exc:
                print(f"Monte-Carlo not run: {exc}")
                return
            print(monte_carlo_summary(res, self.runs))


def monte_carlo_summary(res: dict, runs: int) -> str:
    """One line for :func:`tunnelkit.design.javelin_rmse`'s result: whole-drive RMSE with its
    interval and, when the drives outlast the start-up, the settled RMSE against the PEB."""
    lo, hi = res["ci95_m"]
    text = (
        f"JAVELIN 2-D RMSE {100 * res['rmse_m']:.3g} cm, 95 % CI [{100 * lo:.3g}, "
        f"{100 * hi:.3g}] cm over {runs} drives"
    )
    if res.get("rmse_settled_m") is not None:
        text += (
            f"; after the first {design.SETTLE_S:g} s {1000 * res['rmse_settled_m']:.3g} mm, "
            f"{res['rmse_settled_m'] / res['peb_rms_settled_m']:.3g} x the RMS PEB"
        )
    return text


def design_explorer(
    scenario: str = "example-rectangular-28ghz",
    *,
    fc_ghz: float = 28.0,
    bandwidth_mhz: float = 400.0,
    n: int = 8,
    tilt_deg: float = 20.0,
    mount_height: float = 5.8,
    target: float = 0.2,
    share: float = 0.9,
    runs: int = 10,
    seed: int = 0,
) -> DesignExplorer:
    """Sliders for carrier, bandwidth, array size, tilt and mount height redrawing
    :func:`design_figure`; a button runs ``runs`` JAVELIN drives on the current design."""
    from functools import partial

    height = float(_base(scenario).tunnel.height)
    if not 0.5 <= mount_height < height:
        raise ValueError(f"mount_height: must lie in [0.5, {height:g}) m, got {mount_height}")
    controls = {
        "fc_ghz": float_slider("fc [GHz]", fc_ghz, 1.0, 60.0, 0.5),
        "bandwidth_mhz": widgets.Dropdown(
            options=[20.0, 50.0, 100.0, 200.0, 400.0, 800.0],
            value=bandwidth_mhz,
            description="bandwidth [MHz]",
            style={"description_width": "initial"},
            layout={"width": "220px"},
        ),
        "n": int_slider("array n × n", n, 2, 32),
        "tilt_deg": float_slider("down-tilt [°]", tilt_deg, 0.0, 60.0, 1.0),
        "mount_height": float_slider(
            "mount height [m]", mount_height, 0.5, round(height - 0.05, 2), 0.05
        ),
    }
    cb = partial(design_figure, scenario=scenario, target=target, share=share)
    return DesignExplorer(cb, controls, scenario=scenario, runs=runs, seed=seed)
