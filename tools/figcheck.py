"""Three figure defects a reader sees but no layout box shows, found in a plotly figure's JSON.

* **a trace fully hidden under another**: two visible traces on the same axes with the same
  points (within 0.3 % of the data's span, a pixel or two), where the later one is drawn at least as wide, with the same dash (lines) or at least
  as large (markers): the earlier one cannot be seen at all (EKF under UKF);
* **a legend entry repeated**: two legend entries with the same text in one legend;
* **a colour absent from the legend**: a trace left out of the legend whose colour no legend
  entry has, in a figure that has a legend (a panel's line the reader cannot name).

``figure_problems(fig)`` takes the figure as a dict (``fig.to_plotly_json()``, a notebook's
``application/vnd.plotly.v1+json`` output, or what plotly.js holds in the page) and returns one
line per problem. ``python tools/figcheck.py NOTEBOOK.ipynb ...`` checks executed notebooks.
"""

from __future__ import annotations

import base64
import json
import sys
from pathlib import Path

import numpy as np

#: plotly's default colorway, which fills a trace's colour when the figure gives none
COLORWAY = ["#636efa", "#EF553B", "#00cc96", "#ab63fa", "#FFA15A", "#19d3f3", "#FF6692",
            "#B6E880", "#FF97FF", "#FECB52"]  # fmt: skip
_LINE_TYPES = {"scatter", "scattergl", "scatter3d", "scatterpolar"}


def _visible(t: dict) -> bool:
    return t.get("visible", True) is True


def _in_legend(t: dict, n_traces: int) -> bool:
    if "showlegend" in t:
        return bool(t["showlegend"])
    # plotly's default: a lone trace has no legend entry; colour scales (heatmaps) never do
    return n_traces > 1 and t.get("type", "scatter") in _LINE_TYPES | {"bar", "box", "histogram"}


def _mode(t: dict) -> str:
    return t.get("mode", "lines" if t.get("type", "scatter") in _LINE_TYPES else "")


def _colour(t: dict, i: int, colorway: list[str]) -> str | None:
    for key in ("line", "marker"):
        c = t.get(key, {}).get("color")
        if isinstance(c, str):
            return c.lower().replace(" ", "")
        if c is not None:
            return None  # an array of colours (a colour scale): not one legend colour
    if t.get("type", "scatter") in _LINE_TYPES:
        return colorway[i % len(colorway)].lower()
    return None


def _points(t: dict):
    out = []
    for key in ("x", "y", "z"):
        v = t.get(key)
        if v is None:
            continue
        if isinstance(v, dict) and "bdata" in v:  # plotly's binary encoding of an array
            arr = np.frombuffer(base64.b64decode(v["bdata"]), dtype=np.dtype(v["dtype"]))
            shape = v.get("shape")
            if isinstance(shape, str):
                shape = tuple(int(n) for n in shape.split(","))
            out.append(arr.astype(float).reshape(shape) if shape else arr.astype(float))
            continue
        try:
            out.append(np.asarray(v, dtype=float))
        except (TypeError, ValueError):
            out.append(tuple(map(str, v)))
    return out


def _same_points(a: dict, b: dict) -> bool:
    pa, pb = _points(a), _points(b)
    if len(pa) != len(pb) or not pa:
        return False
    for u, v in zip(pa, pb, strict=True):
        if isinstance(u, np.ndarray) and isinstance(v, np.ndarray):
            if u.shape != v.shape:
                return False
            both = np.concatenate([u.ravel(), v.ravel()])
            both = both[np.isfinite(both)]
            span = float(np.ptp(both)) if both.size else 0.0
            # within 0.3 % of the data's span: less than a pixel or two on a figure
            if not np.allclose(u, v, equal_nan=True, rtol=0, atol=3e-3 * span + 1e-300):
                return False
        elif isinstance(u, np.ndarray) or isinstance(v, np.ndarray) or u != v:
            return False
    return True


def _covers(later: dict, earlier: dict) -> bool:
    """Whether ``later``, drawn over ``earlier`` at the same points, hides it entirely."""
    m_late, m_early = _mode(later), _mode(earlier)
    if "lines" in m_early:
        if "lines" not in m_late:
            return False
        le, ll = earlier.get("line", {}), later.get("line", {})
        if le.get("dash", "solid") != ll.get("dash", "solid"):
            return False
        if ll.get("width", 2) < le.get("width", 2):
            return False
    if "markers" in m_early:
        if "markers" not in m_late:
            return False
        me, ml = earlier.get("marker", {}), later.get("marker", {})
        if me.get("symbol", "circle") != ml.get("symbol", "circle") or ml.get("size", 6) < me.get(
            "size", 6
        ):
            return False
    return bool(m_early)


def figure_problems(fig: dict, name: str = "figure") -> list[str]:
    """The three defects of the module docstring, one line each."""
    data = [t for t in fig.get("data", [])]
    layout = fig.get("layout", {})
    colorway = layout.get("colorway") or layout.get("template", {}).get("layout", {}).get(
        "colorway", COLORWAY
    )
    out = []
    axes = lambda t: (t.get("xaxis", "x"), t.get("yaxis", "y"), t.get("scene", ""))  # noqa: E731
    shown = [(i, t) for i, t in enumerate(data) if _visible(t)]
    for a, (i, early) in enumerate(shown):
        for j, late in shown[a + 1 :]:
            if axes(early) == axes(late) and _same_points(early, late) and _covers(late, early):
                out.append(
                    f"{name}: trace {early.get('name', i)!r} is hidden under "
                    f"{late.get('name', j)!r} (same points, drawn over it)"
                )
    if layout.get("showlegend") is False:
        return out
    in_legend = [(i, t) for i, t in shown if _in_legend(t, len(data)) and t.get("name")]
    seen: dict[tuple, str] = {}
    for _i, t in in_legend:
        key = (t.get("legend", "legend"), t["name"])
        if key in seen:
            out.append(f"{name}: legend entry {t['name']!r} repeated")
        seen[key] = t["name"]
    if not in_legend:
        return out
    legend_colours = {_colour(t, i, colorway) for i, t in in_legend}
    for i, t in shown:
        if _in_legend(t, len(data)) or t.get("type", "scatter") not in _LINE_TYPES:
            continue
        c = _colour(t, i, colorway)
        if c is not None and c not in legend_colours:
            out.append(
                f"{name}: trace {t.get('name', i)!r} in colour {c} has no legend entry of that colour"
            )
    return out


def notebook_problems(path: Path) -> list[str]:
    """``figure_problems`` of every plotly output of an executed notebook."""
    nb = json.loads(Path(path).read_text())
    out = []
    for n, cell in enumerate(nb.get("cells", [])):
        for o in cell.get("outputs", []):
            fig = o.get("data", {}).get("application/vnd.plotly.v1+json")
            if fig:
                title = fig.get("layout", {}).get("title", {})
                title = title.get("text", "") if isinstance(title, dict) else str(title)
                out += figure_problems(fig, f"{Path(path).name} cell {n} ({title[:50]})")
    return out


if __name__ == "__main__":
    problems = [p for f in sys.argv[1:] for p in notebook_problems(Path(f))]
    print("\n".join(problems) or "no figure problems")
    sys.exit(1 if problems else 0)
