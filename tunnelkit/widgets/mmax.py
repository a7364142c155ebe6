"""Notebook 02 explorer: is the SR-NF model valid for this array? Sliders for the geometry,
the tolerance, the carrier and M; one figure with the top view (Fig. 2), the phase mismatch
across the aperture, Mmax vs R and the verdict.

Figure layout (stable, for tests and lecture scripts):

* ``layout.title.text`` is the verdict line; it starts with ``"SR-NF valid"`` or
  ``"SR-NF not valid"``. ``layout.title.subtitle.text`` lists the bounds.
* ``layout.meta`` is a dict: ``verdict`` (the same text), ``valid`` (bool), ``mismatch`` (exact
  max |phase mismatch| [rad] for M), ``mmax_exact``, ``mmax_eq25``, ``mmax_eq37``,
  ``mmax_nonparaxial``, ``paraxial_ratio``, ``M``, ``eps_phi``.
* traces, in this order (``name`` in brackets): panel (a), axes x/y, top view:
  0 wall, 1 BS array, 2 UE, 3 VUE, 4 true paths, 5 paths from the VUE, 6 SR-NF model paths,
  7 reflector p0; panel (b), axes x2/y2, |phase mismatch| [rad] vs antenna position [cm]:
  8 exact (``"exact"``), 9 eq. 33, 10 2nd order non-paraxial, 11 eps_phi; panel (c), axes x3/y3
  (log-log), Mmax vs R: 12 exact (ULA), 13 eq. 25, 14 eq. 37, 15 2nd order, 16 Fraunhofer law,
  17 this M, 18 this design (star; green valid, red not).
* ``layout.annotations`` 0-2 are the panel labels "(a)", "(b)", "(c)".
"""

from __future__ import annotations

import ipywidgets as widgets
import plotly.graph_objects as go

from .. import fresnel
from .._validate import real
from ..plots.fresnel import geometry_traces, mismatch_traces, mmax_range_traces
from .base import Explorer, float_slider, int_slider, slider_value

__all__ = ["TRACE_INDEX", "Y_U_MARGIN", "mmax_explorer", "mmax_figure", "verdict"]

#: the explorer keeps the UE at least this far [m] inside the wall (y_u <= W - Y_U_MARGIN)
Y_U_MARGIN = 0.05

#: where each curve lives in ``mmax_figure(...).data``
TRACE_INDEX = {
    "wall": 0,
    "array": 1,
    "ue": 2,
    "vue": 3,
    "true_paths": 4,
    "vue_paths": 5,
    "sr_paths": 6,
    "reflector": 7,
    "mismatch_exact": 8,
    "mismatch_eq33": 9,
    "mismatch_second_order": 10,
    "eps": 11,
    "mmax_exact": 12,
    "mmax_eq25": 13,
    "mmax_eq37": 14,
    "mmax_second_order": 15,
    "fraunhofer": 16,
    "this_M": 17,
    "this_design": 18,
}


def verdict(
    M: int, R: float, W: float, y_u: float, fc: float, eps_phi: float, *, z_u: float = 0.0
) -> tuple[bool, str, float, int]:
    """``(valid, text, mismatch, mmax_exact)`` for an ``M``-element ULA, from the exact mismatch.

    ``text`` starts with ``"SR-NF valid"`` or ``"SR-NF not valid"``.
    """
    mis = fresnel.phase_mismatch(M, R, W, y_u, fc, z_u=z_u)
    mx = fresnel.mmax_exact(R, W, y_u, fc, eps_phi, z_u=z_u)
    valid = mis <= eps_phi
    word, sign = ("valid", "≤") if valid else ("not valid", ">")
    text = f"SR-NF {word} for M = {M}: exact mismatch {mis:.3g} rad {sign} ε_Φ = {eps_phi:.3g} rad"
    return valid, text, mis, mx


def mmax_figure(
    R: float = 3.5,
    W: float = 3.0,
    y_u: float = 2.5,
    z_u: float = 0.0,
    eps_phi: float = 0.15,
    fc: float = 5.9e9,
    M: int = 10,
) -> go.Figure:
    """The explorer's figure for one set of slider values (pure; no kernel needed).

    Panels: (a) top view of Fig. 2 (the 2-D geometry; ``z_u`` enters (b), (c) and the verdict),
    (b) |phase mismatch| across the ULA, (c) Mmax vs R on log-log axes; the title is the
    verdict. See the module docstring for where each piece lives.
    """
    valid, text, mis, mx = verdict(M, R, W, y_u, fc, eps_phi, z_u=z_u)
    eq25 = fresnel.mmax_2d(R, W, y_u, fc, eps_phi)
    eq37 = fresnel.mmax_3d([R, 2 * W - y_u, z_u], fc, eps_phi)
    second = fresnel.mmax_nonparaxial(R, W, y_u, fc, eps_phi, z_u=z_u)
    par = fresnel.paraxial_ratio(R, W, y_u)
    traces = [
        *geometry_traces(M, R, W, y_u, fc, xaxis="x", yaxis="y", legend="legend"),
        *mismatch_traces(
            M, R, W, y_u, fc, eps_phi, z_u=z_u, xaxis="x2", yaxis="y2", legend="legend2"
        ),
        *mmax_range_traces(
            R,
            W,
            y_u,
            fc,
            eps_phi,
            M,
            z_u=z_u,
            exact_here=mx,
            xaxis="x3",
            yaxis="y3",
            legend="legend3",
        ),
    ]
    note = "outside" if par > 0.3 else "inside"
    reach = fresnel.aperture(M, fc)
    wall_note = f" · ⚠ the {reach:.2f} m array reaches the wall" if reach >= W else ""
    sub = (
        f"Mmax: exact {mx} (ULA) · eq. 25: {eq25:.2f} · eq. 37: {eq37:.2f} · 2nd order: "
        f"{second:.2f} — (2W − y_u)/R = {par:.2f} ({note} eq. 25's paraxial assumption){wall_note}"
    )
    legend = {"bgcolor": "rgba(255,255,255,0.7)", "font": {"size": 10}}
    label = {
        "xref": "paper",
        "yref": "paper",
        "showarrow": False,
        "font": {"size": 13},
        "xanchor": "left",
        "yanchor": "bottom",
    }
    layout = {
        "title": {
            "text": text,
            "subtitle": {"text": sub},
            "x": 0.01,
            "xanchor": "left",
            "font": {"size": 16, "color": "#2ca02c" if valid else "#d62728"},
        },
        "height": 820,  # no fixed width: the figure takes its output area's width
        "margin": {"l": 60, "r": 20, "t": 100, "b": 50},
        "xaxis": {
            "domain": [0.0, 0.78],
            "anchor": "y",
            "title": {"text": "x along the tunnel [m]"},
        },
        "yaxis": {"domain": [0.58, 1.0], "anchor": "x", "title": {"text": "y across [m]"}},
        "xaxis2": {
            "domain": [0.0, 0.36],
            "anchor": "y2",
            "title": {"text": "antenna position y_m [cm]"},
        },
        "yaxis2": {"domain": [0.0, 0.44], "anchor": "x2", "title": {"text": "|Δφ_m| [rad]"}},
        "xaxis3": {
            "domain": [0.44, 0.78],
            "anchor": "y3",
            "type": "log",
            "title": {"text": "R [m]"},
        },
        "yaxis3": {"domain": [0.0, 0.44], "anchor": "x3", "type": "log", "title": {"text": "Mmax"}},
        # legends anchored to the figure's right edge: inside it at any width (over the plot's
        # margin when the output area is narrow, never clipped)
        "legend": {**legend, "x": 1.0, "y": 1.0, "xanchor": "right", "yanchor": "top"},
        "legend2": {**legend, "x": 0.01, "y": 0.44, "xanchor": "left", "yanchor": "top"},
        "legend3": {**legend, "x": 1.0, "y": 0.44, "xanchor": "right", "yanchor": "top"},
        "annotations": [
            {**label, "x": 0.0, "y": 1.0, "text": "(a) top view (Fig. 2)"},
            {**label, "x": 0.0, "y": 0.445, "text": "(b) phase mismatch across the aperture"},
            {**label, "x": 0.44, "y": 0.445, "text": "(c) Mmax vs R"},
        ],
        "meta": {
            "verdict": text,
            "valid": bool(valid),
            "mismatch": mis,
            "mmax_exact": mx,
            "mmax_eq25": eq25,
            "mmax_eq37": eq37,
            "mmax_nonparaxial": second,
            "paraxial_ratio": par,
            "M": int(M),
            "eps_phi": float(eps_phi),
        },
    }
    return go.Figure({"data": traces, "layout": layout})


def mmax_explorer(
    R: float = 3.5,
    W: float = 3.0,
    y_u: float = 2.5,
    z_u: float = 0.0,
    eps_phi: float = 0.15,
    fc: float = 5.9e9,
    M: int = 10,
) -> Explorer:
    """Sliders for R, W, y_u, z_u, eps_phi, M and a carrier preset, redrawing :func:`mmax_figure`.

    The slider ranges cannot reach a value that raises: R >= 1 m, eps_phi >= 0.01 rad, M >= 2,
    and y_u's maximum follows W (``y_u <= W - Y_U_MARGIN``), clamped before the figure redraws.
    """
    presets = list(fresnel.FC_PRESETS.items())
    if fc not in fresnel.FC_PRESETS.values():
        raise ValueError(f"fc: choose one of the presets {[v for _, v in presets]} Hz, got {fc}")
    W = slider_value("W", W, 1.0, 10.0)
    y_u = real("y_u", y_u)
    if not y_u <= W - Y_U_MARGIN:
        raise ValueError(f"y_u: must be <= W - {Y_U_MARGIN} m for the explorer, got {y_u}")
    controls = {
        "R": float_slider("R [m]", R, 1.0, 150.0, 0.5, name="R"),
        "W": float_slider("W [m]", W, 1.0, 10.0, 0.1, name="W"),
        "y_u": float_slider("y_u [m]", y_u, -8.0, W - Y_U_MARGIN, 0.05, name="y_u"),
        "z_u": float_slider("z_u [m]", z_u, -5.0, 5.0, 0.1, name="z_u"),
        "eps_phi": float_slider("ε_Φ [rad]", eps_phi, 0.01, 1.0, 0.01, name="eps_phi"),
        "fc": widgets.Dropdown(
            options=presets, value=fc, description="fc", layout={"width": "200px"}
        ),
        "M": int_slider("M", M, 2, 256, name="M"),
    }

    def clamp_y_u(change) -> None:  # registered before the Explorer's redraw hook: runs first
        controls["y_u"].max = change["new"] - Y_U_MARGIN

    controls["W"].observe(clamp_y_u, names="value")
    return Explorer(mmax_figure, controls, columns=4)
