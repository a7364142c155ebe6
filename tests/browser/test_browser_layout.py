"""Test 3: every plotly figure of the static site fits: legends and titles inside, titles apart.

Measured in the DOM of each chapter page (quick mode) at a wide (1400 px) and a narrow (900 px)
viewport, as a laptop's JupyterLab output area is, per figure:

* the figure is not wider than its output area (a fixed-width figure is cut there);
* each legend box (``g.legend*`` > ``rect.bg``) lies inside the visible figure (its SVG, cut by
  any clipping ancestor and the page) — a legend pushed past the edge is clipped ("wa" for "wall");
* each title — the figure title and subtitle, subplot titles (annotations anchored at their
  bottom above a subplot, ``xref=yref="paper"``) and axis titles — lies inside the visible figure;
* no two titles overlap, and no title overlaps a legend.

A tolerance of 1 px absorbs sub-pixel rounding. The screenshots of each chapter go to
build/artifacts/ (``layout-<chapter>-<width>.png``).
"""

from __future__ import annotations

import pytest
from _lecture import list_notebooks, resolve_notebook

from .pages import NARROW, WIDE


@pytest.mark.parametrize("width", [WIDE, NARROW])
@pytest.mark.parametrize("chapter", [nb.stem for nb in list_notebooks()])
def test_legends_and_titles_fit_their_figures(chapter, width, chapter_pages):
    result = chapter_pages.get(resolve_notebook(chapter), width)["layout"]
    assert result["figures"] >= 1, f"{chapter}: no rendered figure"
    assert result["problems"] == [], f"{chapter} at {width} px:\n" + "\n".join(result["problems"])


@pytest.mark.parametrize("chapter", [nb.stem for nb in list_notebooks()])
def test_no_hidden_trace_no_repeated_legend_entry_no_unnamed_colour(chapter, chapter_pages):
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "figcheck", Path(__file__).resolve().parents[2] / "tools" / "figcheck.py"
    )
    figcheck = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(figcheck)
    figures = chapter_pages.get(resolve_notebook(chapter))["data"]
    assert figures and any(fig["data"] for fig in figures), f"{chapter}: no figure data read"
    problems = [
        p
        for i, fig in enumerate(figures)
        for p in figcheck.figure_problems(
            fig, f"figure {i} ({fig['layout']['title']['text'][:50]})"
        )
    ]
    assert problems == [], f"{chapter}:\n" + "\n".join(problems)
