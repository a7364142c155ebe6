"""Test 1: ``tools/present.py`` serves notebook 02 with Voila, whole (``--view all``) and as the
lecturer's view (``--view explorers``); the keyboard moves the Mmax explorer's M slider; the figure
(read from the page's plotly data) and the verdict change. In the explorers view the slider is in
the first screen and the page is short.

Artefacts in build/artifacts/: voila-02-before.png, voila-02-after.png (the page),
voila-02-explorer-after.png (the explorer alone), voila-02.json (readouts, verdicts, aborted requests)
and voila-02.log (Voila's log).
"""

from __future__ import annotations

import json
import re

import pytest

from .conftest import VOILA_NOTEBOOK, presenting, watched_page

#: the explorer under test: notebook, slider label, how to read the verdict from the figure
TARGET = {
    "notebook": VOILA_NOTEBOOK,
    "slider": "M",
    "verdict": re.compile(r"SR-NF (?:not )?valid\b[^<\n]*"),
}

# Mark the slider labelled `label` and its explorer (the slider's nearest ancestor, inside its own
# output cell, that holds a rendered plotly figure) so Playwright locators can reach them. Until the
# explorer's figure has rendered this returns false and Playwright polls again.
MARK = """label => {
  const sliders = [...document.querySelectorAll('.widget-slider')];
  const s = sliders.find(e => (e.querySelector('.widget-label')?.innerText || '').trim() === label);
  if (!s) return false;
  // climb no further than the slider's own output cell: another cell's figure is not the explorer's
  const stop = s.closest('.jp-OutputArea-output, .output_area, .jp-Cell');
  let box = s.parentElement;
  while (box && box !== stop && !box.querySelector('.js-plotly-plot .main-svg')) box = box.parentElement;
  if (!box || !box.querySelector('.js-plotly-plot .main-svg')) return false;  // not rendered yet
  s.setAttribute('data-test', 'target-slider');
  box.setAttribute('data-test', 'target-explorer');
  return true;
}"""

# What the explorer shows: its figures' trace data and the text of titles, subtitles, annotations.
READ = """() => {
  const plots = [...document.querySelectorAll('[data-test=target-explorer] .js-plotly-plot')];
  const arr = a => (a && a.length !== undefined) ? Array.from(a) : a;
  const data = plots.map(p => (p.data || []).map(t => ({x: arr(t.x), y: arr(t.y), z: arr(t.z)})));
  const texts = plots.flatMap(p => {
    const L = p.layout || {};
    return [L.title?.text, L.title?.subtitle?.text, ...(L.annotations || []).map(a => a.text)];
  });
  return {data: JSON.stringify(data), text: texts.filter(Boolean).join('\\n'),
          readout: document.querySelector('[data-test=target-slider] .widget-readout')?.innerText};
}"""


def verdict_of(text: str) -> str:
    m = TARGET["verdict"].search(text)
    assert m, f"no verdict in the figure's title/annotations: {text!r}"
    return m.group(0)


@pytest.fixture(scope="module", params=["all", "explorers"])
def voila_view(request, browser):
    """The dashboard's page, opened: ``(view, Watched page)``. The whole notebook is the session's
    page (conftest.py); the explorers view gets a server and a page of its own."""
    if request.param == "all":
        _, _, w = request.getfixturevalue("voila_all")
        yield request.param, w
        return
    with presenting(request.param) as (_, url), watched_page(browser) as w:
        w.page.goto(url, timeout=300_000)
        yield request.param, w


def test_keyboard_moves_m_and_the_verdict_changes(voila_view, artifacts):
    view, watched = voila_view
    page = watched.page
    page.wait_for_function(MARK, arg=TARGET["slider"], timeout=300_000)
    tag = f"{TARGET['notebook']}-{view}"
    if view == "explorers":  # the lecturer's view: no long scroll to reach the slider
        top = page.evaluate(
            "document.querySelector('[data-test=target-slider]').getBoundingClientRect().top"
        )
        height = page.evaluate("document.documentElement.scrollHeight")
        assert top < 1000, f"the slider starts {top:.0f} px down the page"
        assert height < 2500, f"the explorers page is {height} px tall"
    before = page.evaluate(READ)
    first = verdict_of(before["text"])
    explorer = page.locator("[data-test=target-explorer]")
    explorer.scroll_into_view_if_needed()
    page.screenshot(path=str(artifacts / f"voila-{tag}-before.png"))

    handle = page.locator("[data-test=target-slider] .noUi-handle")
    handle.focus()
    after = None
    for key in ("End", "Home"):  # to the top of the range; if the verdict holds there, the bottom
        handle.press(key)
        page.wait_for_function(
            f"old => ({READ})().data !== old", arg=before["data"], timeout=120_000
        )
        after = page.evaluate(READ)
        if verdict_of(after["text"]) != first:
            break
    page.wait_for_timeout(300)
    page.screenshot(path=str(artifacts / f"voila-{tag}-after.png"))
    explorer.screenshot(path=str(artifacts / f"voila-{tag}-explorer-after.png"))
    (artifacts / f"voila-{tag}.json").write_text(
        json.dumps(
            {
                "before": {"readout": before["readout"], "verdict": first},
                "after": {"readout": after["readout"], "verdict": verdict_of(after["text"])},
                "aborted_requests": watched.blocked,
            },
            indent=1,
            ensure_ascii=False,
        )
    )

    assert after["readout"] != before["readout"], "the keyboard did not move the slider"
    assert after["data"] != before["data"], "the figure's data did not change"
    assert verdict_of(after["text"]) != first, f"the verdict stayed {first!r}"
