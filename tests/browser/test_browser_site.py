"""Test 2: the static site opens from its index, every chapter renders plotly figures, no errors.

The site is built in quick mode into build/browser-site/ by tools/site.py (the same code as
``make site``) and served by ``python -m http.server`` on a free loopback port (conftest.py).
"""

from __future__ import annotations

from _lecture import list_notebooks


def test_index_links_every_chapter_and_each_renders(site_url, watched, artifacts):
    page = watched.page
    page.goto(site_url + "index.html")
    links = page.eval_on_selector_all(
        "ol.chapters a", "els => els.map(e => e.getAttribute('href'))"
    )
    expected = [f"{nb.stem}.html" for nb in list_notebooks()]
    assert links == expected
    for href in links:
        page.goto(site_url + href, wait_until="load")
        page.wait_for_selector(".js-plotly-plot .main-svg", timeout=30_000)
        page.wait_for_load_state("networkidle")
        n = page.evaluate("document.querySelectorAll('.js-plotly-plot .main-svg').length")
        assert n >= 1, f"{href}: no rendered plotly figure"
        assert page.evaluate("typeof window.Plotly") == "object", f"{href}: plotly.js not loaded"
        shot = artifacts / f"site-{href.removesuffix('.html')}"
        page.screenshot(path=f"{shot}.png")
        page.locator(".js-plotly-plot").first.screenshot(path=f"{shot}-figure.png")
    assert watched.blocked == [], f"the site asked for off-machine resources: {watched.blocked}"
    assert watched.errors == [], f"console errors: {watched.errors}"


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
    page.wait_for_timeout(500)
    after = page.evaluate(f"{plot}._fullLayout.xaxis.range.slice()")
    assert after[1] - after[0] < 0.6 * (before[1] - before[0]), (before, after)
    assert watched.errors == []
