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
from _lecture import list_notebooks

# Everything measured in one pass; boxes in page coordinates.
MEASURE = """() => {
  const tol = 1;
  const box = e => { const r = e.getBoundingClientRect();
    return {l: r.left, r: r.right, t: r.top, b: r.bottom, w: r.width, h: r.height}; };
  const inside = (a, o) => a.l >= o.l - tol && a.r <= o.r + tol && a.t >= o.t - tol && a.b <= o.b + tol;
  const overlap = (a, b) => Math.min(a.r, b.r) - Math.max(a.l, b.l) > tol
                         && Math.min(a.b, b.b) - Math.max(a.t, b.t) > tol;
  const problems = [];
  let figures = 0;
  document.querySelectorAll('.js-plotly-plot').forEach((p, i) => {
    const svg = p.querySelector('svg.main-svg');
    if (!svg || p.offsetParent === null) return;
    figures += 1;
    // the visible part of the figure: its SVG cut by every ancestor that clips or scrolls, and by
    // the page width (a figure wider than its output area is cut there)
    const fb = box(svg);
    fb.r = Math.min(fb.r, document.documentElement.clientWidth);
    for (let a = p.parentElement; a && a !== document.body; a = a.parentElement) {
      const cs = getComputedStyle(a);
      if (cs.overflowX !== 'visible') { const ab = box(a); fb.l = Math.max(fb.l, ab.l); fb.r = Math.min(fb.r, ab.r); }
      if (cs.overflowY !== 'visible') { const ab = box(a); fb.t = Math.max(fb.t, ab.t); fb.b = Math.min(fb.b, ab.b); }
    }
    if (fb.r < box(svg).r - tol) problems.push(`${p._fullLayout && p._fullLayout.title ? p._fullLayout.title.text : p.id}: ` +
      `figure ${box(svg).w.toFixed(0)} px wide, cut at ${(fb.r - fb.l).toFixed(0)} px by its output area`);
    const lay = p._fullLayout || {};
    const name = ((lay.title && lay.title.text) || p.id || `figure ${i}`).replace(/<[^>]+>/g, '').slice(0, 70);
    const titles = [];
    const add = (kind, el) => {
      const txt = (el.textContent || '').trim();
      if (!txt) return;
      const b = box(el);
      if (b.w === 0 || b.h === 0) return;
      titles.push({kind, txt: txt.slice(0, 40), b});
    };
    p.querySelectorAll('.g-gtitle text.gtitle, .g-gtitle text.gtitle-subtitle').forEach(e => add('title', e));
    p.querySelectorAll('[class*="g-"][class*="title"] text[class$="title"]').forEach(e => {
      if (!e.classList.contains('gtitle') && !e.classList.contains('gtitle-subtitle')) add('axis title', e);
    });
    p.querySelectorAll('g.annotation text.annotation-text').forEach(e => add('annotation', e));
    const legends = [];
    p.querySelectorAll('g.infolayer > g[class^="legend"]').forEach(g => {
      const bg = g.querySelector('rect.bg');
      if (!bg) return;
      const b = box(bg);
      if (b.w === 0 || b.h === 0) return;
      legends.push({cls: g.getAttribute('class'), b});
      if (!inside(b, fb)) problems.push(`${name}: ${g.getAttribute('class')} box ` +
        `[${b.l.toFixed(0)},${b.r.toFixed(0)}]x[${b.t.toFixed(0)},${b.b.toFixed(0)}] outside the figure ` +
        `[${fb.l.toFixed(0)},${fb.r.toFixed(0)}]x[${fb.t.toFixed(0)},${fb.b.toFixed(0)}]`);
    });
    // titles: figure title, subtitle, axis titles; annotations count when they sit above a subplot
    // (subplot titles from make_subplots are annotations anchored at the bottom of their text)
    const subplotTitles = new Set((lay.annotations || [])
      .filter(a => a.xref === 'paper' && a.yref === 'paper' && a.yanchor === 'bottom' && a.showarrow === false)
      .map(a => String(a.text).replace(/<[^>]+>/g, '').trim().slice(0, 40)));
    const tt = titles.filter(t => t.kind !== 'annotation' || subplotTitles.has(t.txt));
    tt.forEach(t => {
      if (!inside(t.b, fb)) problems.push(`${name}: ${t.kind} "${t.txt}" overflows the figure`);
    });
    for (let a = 0; a < tt.length; a++) {
      for (let c = a + 1; c < tt.length; c++) {
        if (overlap(tt[a].b, tt[c].b))
          problems.push(`${name}: ${tt[a].kind} "${tt[a].txt}" overlaps ${tt[c].kind} "${tt[c].txt}"`);
      }
      legends.forEach(l => {
        if (overlap(tt[a].b, l.b)) problems.push(`${name}: ${tt[a].kind} "${tt[a].txt}" overlaps ${l.cls}`);
      });
    }
  });
  return {figures, problems};
}"""


@pytest.mark.parametrize("width", [1400, 900])
@pytest.mark.parametrize("chapter", [nb.stem for nb in list_notebooks()])
def test_legends_and_titles_fit_their_figures(chapter, width, site_url, watched, artifacts):
    page = watched.page
    page.set_viewport_size({"width": width, "height": 1000})
    page.goto(site_url + f"{chapter}.html", wait_until="load")
    page.wait_for_selector(".js-plotly-plot .main-svg", timeout=30_000)
    page.wait_for_load_state("networkidle")
    page.wait_for_timeout(300)  # plotly's responsive relayout after the first paint
    result = page.evaluate(MEASURE)
    page.screenshot(path=str(artifacts / f"layout-{chapter}-{width}.png"), full_page=True)
    assert result["figures"] >= 1, f"{chapter}: no rendered figure"
    assert result["problems"] == [], f"{chapter} at {width} px:\n" + "\n".join(result["problems"])


# The figures as plotly.js holds them in the page (typed arrays turned into lists), for the three
# defects no layout box shows: a trace fully hidden under another, a legend entry repeated, a
# colour used in a panel but absent from its legend (tools/figcheck.py).
FIGURES = """() => [...document.querySelectorAll('.js-plotly-plot')].map(p => {
  const arr = v => (v && typeof v !== 'string' && v.length !== undefined) ? Array.from(v) : v;
  const pick = (o, keys) => { const r = {}; keys.forEach(k => { if (o && o[k] !== undefined
      && (typeof o[k] !== 'object' || o[k] === null)) r[k] = o[k]; }); return r; };
  const data = (p.data || []).map(t => {
    const r = pick(t, ['type', 'name', 'mode', 'showlegend', 'visible', 'legendgroup', 'legend',
                       'xaxis', 'yaxis', 'scene']);
    ['x', 'y', 'z'].forEach(k => { if (t[k] !== undefined) r[k] = arr(t[k]); });
    r.line = pick(t.line, ['color', 'width', 'dash']);
    r.marker = pick(t.marker, ['color', 'size', 'symbol']);
    if (t.marker && typeof t.marker.color !== 'string' && t.marker.color !== undefined)
      r.marker.color = arr(t.marker.color);
    return r;
  });
  const lay = p.layout || {};
  const title = lay.title && (lay.title.text || lay.title);
  return {data, layout: {showlegend: lay.showlegend, colorway: lay.colorway,
                         title: {text: typeof title === 'string' ? title : ''}}};
})"""


@pytest.mark.parametrize("chapter", [nb.stem for nb in list_notebooks()])
def test_no_hidden_trace_no_repeated_legend_entry_no_unnamed_colour(chapter, site_url, watched):
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "figcheck", Path(__file__).resolve().parents[2] / "tools" / "figcheck.py"
    )
    figcheck = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(figcheck)
    page = watched.page
    page.goto(site_url + f"{chapter}.html", wait_until="load")
    page.wait_for_selector(".js-plotly-plot .main-svg", timeout=30_000)
    figures = page.evaluate(FIGURES)
    assert figures and any(fig["data"] for fig in figures), f"{chapter}: no figure data read"
    problems = [
        p
        for i, fig in enumerate(figures)
        for p in figcheck.figure_problems(
            fig, f"figure {i} ({fig['layout']['title']['text'][:50]})"
        )
    ]
    assert problems == [], f"{chapter}:\n" + "\n".join(problems)
