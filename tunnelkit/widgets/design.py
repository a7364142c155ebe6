"""Notebook 08 explorer: carrier, bandwidth, array size, tilt, mount height and the impairments
(per-element phase and gain calibration error, diffuse multipath share, spatial wideband) -> the
ideal position error bound and the predicted error along the tunnel, the SR-NF overlay and the
smallest square array predicted to meet the target.

:func:`design_figure` is the pure callback (bound and prediction only, vectorised: no
Monte-Carlo); its smallest array is a prediction (:func:`tunnelkit.design.smallest_meeting`), not
a decision: the explorer adds a button that runs the design's Monte-Carlo over manufactured units
(the tracker on the bound-driven route under the same impairments) for the current design.

Figure layout (stable, for tests and lecture scripts): ``layout.title.text`` starts with
``"Predicted to meet: "`` followed by the array label or ``"none"``; ``layout.meta`` holds
``array``, ``n_elements``, ``peb_median_m``, ``predicted_median_m``, ``srnf_valid_share``,
``met_share`` (share of the route where the prediction meets the target), ``predicted``, ``fits``
(False when the array does not fit at this mount); traces as in
:func:`tunnelkit.plots.design.route_traces`.
"""

from __future__ import annotations

from functools import lru_cache

import ipywidgets as widgets
import numpy as np
import plotly.graph_objects as go

from .._validate import integer, positive, probability, real, text
from ..budget import check_bytes
from ..montecarlo import RUN_BYTES
from ..plots.design import route_figure
from .base import Explorer, checkbox, float_slider, int_slider

__all__ = ["MAX_POINTS", "SIZES", "DesignExplorer", "design_explorer", "design_figure"]

#: square URAs the recommendation searches, smallest first
SIZES = (2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32)

#: the explorer evaluates at most this many epochs, evenly spread along the route
MAX_POINTS = 24


#: the bandwidths the explorer's dropdown offers [MHz]
BANDWIDTHS_MHZ = (20.0, 50.0, 100.0, 200.0, 400.0, 800.0)


@lru_cache(maxsize=8)
def _base(scenario: str):
    """The scenario's :class:`~tunnelkit.design.DesignSetup` (the design loaded on first use)."""
    from .. import design

    return design.DesignSetup.from_scenario(scenario)


def design_figure(
    fc_ghz: float = 28.0,
    bandwidth_mhz: float = 400.0,
    n: int = 8,
    tilt_deg: float = 20.0,
    mount_height: float = 5.8,
    phase_error_deg: float = 0.0,
    gain_error_db: float = 0.0,
    dmc_share: float = 0.0,
    wideband: bool = False,
    *,
    scenario: str = "example-rectangular-28ghz",
    target: float = 0.2,
    share: float = 0.9,
    eps_phi: float = 0.15,
) -> go.Figure:
    """PEB and predicted error of an ``n x n`` URA along the route under the impairments, SR-NF
    failures marked (information: the design's tracker does not need it), and the smallest
    square array predicted to meet the target (a prediction, not a decision).

    Pure: the same arguments give the same figure. A design that does not fit (array outside the
    tunnel at this mount) gives an empty figure whose title says so instead of raising.
    """
    from .. import design

    wideband = checkbox("", wideband, name="wideband").value
    # the arguments are checked here, before the "does not fit" figure below catches ValueError
    fc_ghz, bandwidth_mhz = positive("fc_ghz", fc_ghz), positive("bandwidth_mhz", bandwidth_mhz)
    n = integer("n", n, minimum=1)
    tilt_deg, mount_height = real("tilt_deg", tilt_deg), positive("mount_height", mount_height)
    eps_phi = positive("eps_phi", eps_phi)
    target = positive("target", target)  # before the bounds: a bad value costs no computation
    share = probability("share", share, open_interval=False)
    imp = design.DesignImpairments(
        phase_error_deg=phase_error_deg,
        gain_error_db=gain_error_db,
        spatial_wideband=bool(wideband),
        dmc_share=dmc_share,
    )
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
        g = design.route_geometry(setup, spec, epochs=ep)
        b = design.route_bounds(setup, spec, eps_phi=eps_phi, geometry=g)
        a = design.predicted_error(setup, spec, imp, geometry=g)
    except ValueError as exc:
        return go.Figure(
            layout={
                "title": {"text": f"Predicted to meet: none — {exc}", "font": {"size": 12}},
                "height": 620,
                "autosize": True,
                "meta": {"fits": False, "predicted": None},
            }
        )
    rec, _ = design.smallest_meeting(
        setup,
        [f"{k}x{k}" for k in SIZES],
        target=target,
        share=share,
        impairments=imp,
        eps_phi=eps_phi,
        epochs=ep,
    )
    met = float(np.mean(a.predicted <= target))
    med = float(np.median(b.peb))
    med_a = float(np.median(a.predicted))
    if rec is None:
        title = (
            f"Predicted to meet: none — no square URA up to {SIZES[-1]}x{SIZES[-1]} has a "
            f"predicted error ≤ {100 * target:g} cm on {100 * share:.0f} %"
        )
    else:
        title = (
            f"Predicted to meet: {rec.label} — smallest square URA predicted ≤ "
            f"{100 * target:g} cm on {100 * share:.0f} % (a prediction)"
        )
    sub = (
        f"{spec.label}, {fc_ghz:g} GHz, {bandwidth_mhz:g} MHz, {phase_error_deg:g}°/"
        f"{gain_error_db:g} dB, diffuse {100 * dmc_share:g} %: median PEB {100 * med:.3g} cm, "
        f"predicted {100 * med_a:.3g} cm · met {100 * met:.0f} % · SR-NF (eq. 51) "
        f"{100 * b.srnf_valid.mean():.0f} %"
    )
    meta = {
        "array": spec.label,
        "n_elements": spec.n_elements,
        "peb_median_m": med,
        "predicted_median_m": med_a,
        "srnf_valid_share": float(b.srnf_valid.mean()),
        "met_share": met,
        "predicted": None if rec is None else rec.label,
        "fits": True,
    }
    label = "ideal" if imp.ideal else "impaired"
    return route_figure(
        b, target=target, predicted={label: a}, title=title, subtitle=sub, meta=meta
    )


class DesignExplorer(Explorer):
    """The sliders and figure of :class:`~tunnelkit.widgets.base.Explorer`, plus a Monte-Carlo
    button (JAVELIN on the current design, progress bar, result printed below)."""

    def __init__(
        self,
        callback,
        controls,
        *,
        scenario: str,
        units: int,
        seed: int,
        target: float = 0.2,
        share: float = 0.9,
    ) -> None:
        text("scenario", scenario), integer("units", units, minimum=1)
        check_bytes("units", 2 * units * RUN_BYTES, f"{units} units x 2 drives")
        integer("seed", seed, minimum=0), positive("target", target)
        probability("share", share, open_interval=False)
        super().__init__(callback, controls, columns=3)
        self.scenario, self.units, self.seed = scenario, units, seed
        self.target, self.share = target, share
        self.button = widgets.Button(
            description=f"Monte-Carlo ({units} units)", icon="play", layout={"width": "220px"}
        )
        self.output = widgets.Output()
        self.button.on_click(self._run)
        self.widget = widgets.VBox([*self.widget.children, self.button, self.output])

    def run_monte_carlo(self):
        """The design's Monte-Carlo of the current design under the current impairments (the
        tracker on the bound-driven route, :func:`tunnelkit.design.design_sweep` on this one
        array, ``units`` manufactured units of two drives, one batch): its
        :class:`~tunnelkit.design.DesignRow`, unit yield and error quantile with their
        intervals; what the button runs."""
        from .. import design

        v = self.values
        setup = _base(self.scenario).variant(
            fc=v["fc_ghz"] * 1e9,
            bandwidth=v["bandwidth_mhz"] * 1e6,
            tilt_deg=v["tilt_deg"],
            mount_height=v["mount_height"],
        )
        imp = design.DesignImpairments(
            phase_error_deg=v["phase_error_deg"],
            gain_error_db=v["gain_error_db"],
            spatial_wideband=bool(v["wideband"]),
            dmc_share=v["dmc_share"],
        )
        rep = design.design_sweep(
            setup,
            [f"{v['n']}x{v['n']}"],
            target=self.target,
            share=self.share,
            impairments=imp,
            units=self.units,
            max_units=self.units,
            seed=self.seed,
            progress=True,
        )
        return rep.rows[0]

    def _run(self, _button) -> None:  # pragma: no cover - needs a browser click
        self.output.clear_output()
        with self.output:
            try:
                res = self.run_monte_carlo()
            except ValueError as exc:
                print(f"Monte-Carlo not run: {exc}")
                return
            print(monte_carlo_summary(res))


def monte_carlo_summary(row) -> str:
    """One line for a :class:`tunnelkit.design.DesignRow` with Monte-Carlo units: its verdict,
    the unit yield and the pooled error quantile with their 95 % intervals, the prediction and
    the PEB beside them."""
    if row.status == "error":
        return f"Monte-Carlo not run: {row.reason}"
    if row.error_p90_m is None:
        return f"{row.array}: {row.status} — {row.reason}"
    lo, hi = row.error_p90_ci95_m
    ylo, yhi = row.unit_yield_ci95
    return (
        f"{row.array}: {row.status} — {100 * row.unit_yield:.3g} % of {row.units} units meet "
        f"the target (95 % CI [{100 * ylo:.3g}, {100 * yhi:.3g}] %); tracker error quantile "
        f"{100 * row.error_p90_m:.3g} cm, 95 % CI [{100 * lo:.3g}, {100 * hi:.3g}] cm over "
        f"{row.runs} drives; predicted {100 * row.predicted_p90_m:.3g} cm (not a bound), ideal "
        f"PEB {100 * row.peb_p90_m:.3g} cm"
    )


def design_explorer(
    scenario: str = "example-rectangular-28ghz",
    *,
    fc_ghz: float = 28.0,
    bandwidth_mhz: float = 400.0,
    n: int = 8,
    tilt_deg: float = 20.0,
    mount_height: float = 5.8,
    phase_error_deg: float = 0.0,
    gain_error_db: float = 0.0,
    dmc_share: float = 0.0,
    wideband: bool = False,
    target: float = 0.2,
    share: float = 0.9,
    units: int = 10,
    seed: int = 0,
) -> DesignExplorer:
    """Sliders for carrier, bandwidth, array size, tilt, mount height and the impairments
    redrawing :func:`design_figure`; a button runs ``units`` manufactured units (two drives each)
    of the design's tracker on the current design."""
    from functools import partial

    if not isinstance(scenario, str) or not scenario:
        raise TypeError(f"scenario: expected a scenario name, got {scenario!r}")
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    units = integer("units", units, minimum=1)
    seed = integer("seed", seed, minimum=0)
    if bandwidth_mhz not in BANDWIDTHS_MHZ:
        raise ValueError(
            f"bandwidth_mhz: choose one of {list(BANDWIDTHS_MHZ)}, got {bandwidth_mhz!r}"
        )
    mount_height = real("mount_height", mount_height)
    height = float(_base(scenario).tunnel.height)
    if not 0.5 <= mount_height < height:
        raise ValueError(f"mount_height: must lie in [0.5, {height:g}) m, got {mount_height}")
    controls = {
        "fc_ghz": float_slider("fc [GHz]", fc_ghz, 1.0, 60.0, 0.5, name="fc_ghz"),
        "bandwidth_mhz": widgets.Dropdown(
            options=list(BANDWIDTHS_MHZ),
            value=bandwidth_mhz,
            description="bandwidth [MHz]",
            style={"description_width": "initial"},
            layout={"width": "220px"},
        ),
        "n": int_slider("array n × n", n, 2, 32, name="n"),
        "tilt_deg": float_slider("down-tilt [°]", tilt_deg, 0.0, 60.0, 1.0, name="tilt_deg"),
        "mount_height": float_slider(
            "mount height [m]", mount_height, 0.5, round(height - 0.05, 2), 0.05
        ),
        "phase_error_deg": float_slider(
            "phase error [°]", phase_error_deg, 0.0, 3.0, 0.1, name="phase_error_deg"
        ),
        "gain_error_db": float_slider(
            "gain error [dB]", gain_error_db, 0.0, 0.5, 0.05, name="gain_error_db"
        ),
        "dmc_share": float_slider("diffuse share", dmc_share, 0.0, 0.3, 0.01, name="dmc_share"),
        "wideband": checkbox("spatial wideband", wideband, name="wideband"),
    }
    cb = partial(design_figure, scenario=scenario, target=target, share=share)
    return DesignExplorer(
        cb, controls, scenario=scenario, units=units, seed=seed, target=target, share=share
    )
