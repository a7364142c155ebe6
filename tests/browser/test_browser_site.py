"""Test 2: the static site opens from its index, every chapter renders plotly figures, no errors.

The site is built in quick mode into build/browser-site/ by tools/site.py (the same code as
``make site``) and served by ``python -m http.server`` on a free loopback port (conftest.py).
Each chapter is read as it opened (pages.py: one visit per chapter serves every site test).
"""

from __future__ import annotations

import contextlib

from _lecture import list_notebooks
from playwright.sync_api import TimeoutError as PlaywrightTimeout


def test_index_links_every_chapter_and_each_renders(site_url, watched, chapter_pages):
    page = watched.page
    page.goto(site_url + "index.html")
    links = page.eval_on_selector_all(
        "ol.chapters a", "els => els.map(e => e.getAttribute('href'))"
    )
    books = list_notebooks()
    assert links == [f"{nb.stem}.html" for nb in books]
    blocked, errors = list(watched.blocked), list(watched.errors)
    for href, book in zip(links, books, strict=True):  # each chapter as it opened (pages.py)
        seen = chapter_pages.get(book)
        assert seen["figures"] >= 1, f"{href}: no rendered plotly figure"
        assert seen["plotly"], f"{href}: plotly.js not loaded"
        blocked += seen["blocked"]
        errors += [f"{href}: {e}" for e in seen["errors"]]
    assert blocked == [], f"the site asked for off-machine resources: {blocked}"
    assert errors == [], f"console errors: {errors}"


# Page coordinates of the middle point of the first visible scatter trace of the first figure.
POINT = """() => {
  const p = document.querySelector('.js-plotly-plot');
  const t = p._fullData.find(t => t.type === 'scatter' && t.visible === true && t.x && t.x.length
    && !['skip', 'none'].includes(t.hoverinfo));
  const k = Math.floor(t.x.length / 2), xa = p._fullLayout[t.xaxis === 'x' ? 'xaxis' : 'xaxis' + t.xaxis.slice(1)];
  const ya = p._fullLayout[t.yaxis === 'y' ? 'yaxis' : 'yaxis' + t.yaxis.slice(1)];
  const r = p.getBoundingClientRect();
  return {x: r.left + xa._offset + xa.c2p(t.x[k]), y: r.top + ya._offset + ya.c2p(t.y[k]), name: t.name};
}"""


def test_figures_hover_and_zoom_without_a_kernel(site_url, watched):
    """Hover a data point (a label appears), then drag a box (the x range shrinks): plotly.js alone."""
    page = watched.page
    page.goto(site_url + f"{list_notebooks()[0].stem}.html")
    page.wait_for_selector(".js-plotly-plot .nsewdrag", timeout=30_000)
    page.locator(".js-plotly-plot").first.scroll_into_view_if_needed()
    pt = page.evaluate(POINT)
    page.mouse.move(pt["x"] - 5, pt["y"] - 5)
    page.mouse.move(pt["x"], pt["y"], steps=3)
    page.wait_for_selector(".js-plotly-plot .hoverlayer .hovertext", timeout=5_000)

    drag = page.locator(".js-plotly-plot .nsewdrag").first
    plot = "document.querySelector('.js-plotly-plot')"
    before = page.evaluate(f"{plot}._fullLayout.xaxis.range.slice()")
    box = drag.bounding_box()
    x0, y0 = box["x"] + 0.3 * box["width"], box["y"] + 0.3 * box["height"]
    page.mouse.move(x0, y0)
    page.mouse.down()
    page.mouse.move(x0 + 0.3 * box["width"], y0 + 0.3 * box["height"], steps=8)
    page.mouse.up()
    with contextlib.suppress(PlaywrightTimeout):  # the assert below says what did not happen
        page.wait_for_function(
            f"w => {plot}._fullLayout.xaxis.range[1] - {plot}._fullLayout.xaxis.range[0] < w",
            arg=0.6 * (before[1] - before[0]),
            timeout=5_000,
        )
    after = page.evaluate(f"{plot}._fullLayout.xaxis.range.slice()")
    assert after[1] - after[0] < 0.6 * (before[1] - before[0]), (before, after)
    assert watched.errors == []
