"""The static site's chapter pages as the browser tests see them: each chapter opened once per
viewport width for the whole session, and everything the tests check on it recorded in that one
visit (the page as it opens is read before anything on it is clicked).

At 1400 px (``WIDE``): the rendered figures, whether plotly.js loaded, the layout measurement
(``MEASURE``), the figures' data (``FIGURES``), the state of the exercises' solutions and then,
after a click on the first one's summary, what it shows, the console errors and the requests
aborted. At 900 px: the layout measurement. Screenshots go to build/artifacts/ as before
(``site-NN*.png``, ``layout-NN-WIDTH.png``, ``solutions-site-NN*.png``).
"""

from __future__ import annotations

import contextlib
from pathlib import Path

import nbformat
from playwright.sync_api import TimeoutError as PlaywrightTimeout

from tunnelkit.solutions import CSS_CLASS, solution_id

from .conftest import watched_page

WIDE, NARROW = 1400, 900
SOLUTION = "solution"

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


# For each selector: how many elements match, how many of the outputs inside them are on screen
# (a box with a size and not inside a closed <details>), whether each sits in a closed
# <details class="tk-solution">, how many hold a solution's collapsed output (it ran) and their text.
STATE = """sels => sels.map(sel => {
  const cells = [...document.querySelectorAll(sel)];
  const outs = cells.flatMap(c => [...c.querySelectorAll('.jp-OutputArea-output')]);
  const shown = outs.filter(o => {
    const r = o.getBoundingClientRect();
    return r.width > 0 && r.height > 0 && o.checkVisibility();
  });
  return {sel, cells: cells.length, outputs: outs.length, shown: shown.length,
          closed: cells.filter(c => { const d = c.closest('details.tk-solution');
                                      return d && !d.open; }).length,
          ran: cells.filter(c => c.querySelector('details.OUTPUT_CLASS')).length,
          text: cells.map(c => c.textContent).join(' ')};
})""".replace("OUTPUT_CLASS", CSS_CLASS)


def solution_cells(path) -> list[tuple[int, str, str]]:
    """(position, cell id, solution id) of every solution cell of a notebook."""
    nb = nbformat.read(path, as_version=4)
    return [
        (i, c.get("id", ""), solution_id(c.source))
        for i, c in enumerate(nb.cells)
        if SOLUTION in c.get("metadata", {}).get("tags", [])
    ]


def open_first(page, selector: str) -> int:
    """Click the first solution's summary; the number of its outputs now on screen."""
    page.locator(selector).locator("xpath=ancestor::details[1]/summary").click()
    with contextlib.suppress(PlaywrightTimeout):  # the caller's assert says what did not happen
        page.wait_for_function(
            "sel => document.querySelector(sel)?.closest('details')?.open === true",
            arg=selector,
            timeout=5_000,
        )
    page.locator(selector).locator(".jp-OutputArea-output").first.scroll_into_view_if_needed()
    return page.evaluate(STATE, [selector])[0]["shown"]


def visible_text(page, selector: str) -> str:
    return page.locator(selector).locator(".jp-OutputArea").first.inner_text()


class ChapterPages:
    """Each chapter page of the site at each width, opened on first use and recorded; a page that
    could not be opened fails every test that asks for it, with the same error.

    The tests ask for the pages in ``order`` (chapter by chapter, wide then narrow): while one page
    is read, the next one already loads in a page of its own (Chromium renders it in another
    process, so the two cores of a CI machine both work)."""

    def __init__(self, browser, site_url: str, artifacts: Path, books: list[Path]) -> None:
        self.browser, self.site_url, self.artifacts = browser, site_url, artifacts
        self.order = [(b, w) for b in books for w in (WIDE, NARROW)]
        self._seen: dict[tuple[str, int], dict | BaseException] = {}
        self._loading: dict[tuple[str, int], tuple] = {}

    def get(self, notebook: Path, width: int = WIDE) -> dict:
        key = (notebook.stem, width)
        if key not in self._seen:
            try:
                started = self._loading.pop(key, None) or self._open(notebook, width)
                self._open_next(key)
                self._seen[key] = self._read(notebook, width, started)
            except Exception as exc:  # kept, and raised to every test that asks
                self._seen[key] = exc
        seen = self._seen[key]
        if isinstance(seen, BaseException):
            raise seen
        return seen

    def close(self) -> None:
        """Close the pages opened ahead and not asked for."""
        for cm, _ in self._loading.values():
            cm.__exit__(None, None, None)
        self._loading.clear()

    def _open_next(self, key: tuple[str, int]) -> None:
        keys = [(b.stem, w) for b, w in self.order]
        if key not in keys or keys.index(key) + 1 == len(keys):
            return
        book, width = self.order[keys.index(key) + 1]
        nxt = (book.stem, width)
        if nxt not in self._seen and nxt not in self._loading:
            self._loading[nxt] = self._open(book, width)

    def _open(self, notebook: Path, width: int) -> tuple:
        """A watched page of its own, its navigation to the chapter begun: (its context, page)."""
        cm = watched_page(self.browser)
        w = cm.__enter__()
        try:
            w.page.set_viewport_size({"width": width, "height": 1000})
            w.page.goto(self.site_url + f"{notebook.stem}.html", wait_until="commit")
        except BaseException:
            cm.__exit__(None, None, None)
            raise
        return cm, w

    def _read(self, notebook: Path, width: int, started: tuple) -> dict:
        stem, art = notebook.stem, self.artifacts
        cm, w = started
        try:
            page = w.page
            page.wait_for_load_state("load")
            page.wait_for_selector(".js-plotly-plot .main-svg", timeout=30_000)
            page.wait_for_load_state("networkidle")
            page.wait_for_timeout(300)  # plotly's responsive relayout after the first paint
            rec = {"layout": page.evaluate(MEASURE)}
            page.screenshot(path=str(art / f"layout-{stem}-{width}.png"), full_page=True)
            if width != WIDE:
                return rec
            rec["figures"] = page.evaluate(
                "document.querySelectorAll('.js-plotly-plot .main-svg').length"
            )
            rec["plotly"] = page.evaluate("typeof window.Plotly") == "object"
            rec["data"] = page.evaluate(FIGURES)
            page.screenshot(path=str(art / f"site-{stem}.png"))
            page.locator(".js-plotly-plot").first.screenshot(
                path=str(art / f"site-{stem}-figure.png")
            )
            cells = solution_cells(notebook)
            rec["solutions"] = self._solutions(page, stem, cells) if cells else None
            rec["errors"], rec["blocked"] = list(w.errors), list(w.blocked)
            return rec
        finally:
            cm.__exit__(None, None, None)

    def _solutions(self, page, stem: str, cells) -> dict:
        """The solutions as the page opens, then the first one opened by a click on its summary."""
        sels = [f'[id="cell-id={cid}"]' for _, cid, _ in cells]
        states = page.evaluate(STATE, sels)
        tag = stem.split("-", 1)[0]
        page.locator(sels[0]).locator("xpath=ancestor::details[1]").scroll_into_view_if_needed()
        page.screenshot(path=str(self.artifacts / f"solutions-site-{tag}.png"))
        shown = open_first(page, sels[0])
        text = visible_text(page, sels[0])
        page.screenshot(path=str(self.artifacts / f"solutions-site-{tag}-open.png"))
        return {"states": states, "opened_shown": shown, "opened_text": text}
