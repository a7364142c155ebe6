"""Test 4: an exercise's solution shows nothing until the student asks for it.

On the static site (tools/site.py) every solution ran when the site was built
(``TUNNELKIT_SOLUTIONS=1``, tunnelkit.solutions), but its output must not be on screen when the
page opens: the cell sits in a closed ``<details>``, one click on its summary shows its code and
the summary of its collapsed output ("Show the solution's output"), which holds what it printed.
In Voila (tools/present.py), a live kernel, a solution does not run at all until asked for: its
closed ``<details>`` holds the line "run it when you have tried" and a button, and only the
button's click runs it and shows its output. Solution cells are found from the notebook itself
(their cell ids on the site, their position in Voila, which numbers its cells from 1), so a
template that forgets to collapse them, or a solution that runs unasked, fails here.

Artefacts in build/artifacts/: solutions-site-NN.png (each chapter with solutions, as it opens),
solutions-site-NN-open.png (its first solution opened), solutions-voila-02.png,
solutions-voila-02-open.png and solutions-voila-02-run.png (after the button's click).
"""

from __future__ import annotations

from _lecture import list_notebooks

from tunnelkit.solutions import ASK, SUMMARY

from .pages import STATE, open_first, solution_cells, visible_text

#: words solution 02.1 prints (not in its title, which the line before its button shows)
PRINTED_02_1 = "for every R >="


def _assert_hidden(states: list[dict], where: str) -> None:
    for s in states:
        assert s["cells"] == 1, f"{where}: {s['sel']} matches {s['cells']} cells"
        assert s["closed"] == 1, f"{where}: {s['sel']} is not inside a closed <details>"
        assert s["shown"] == 0, f"{where}: {s['sel']} shows {s['shown']} output(s) unasked"
    assert sum(s["outputs"] for s in states) > 0, f"{where}: the solutions have no output at all"


def test_site_solutions_are_collapsed(chapter_pages):
    books = [(b, solution_cells(b)) for b in list_notebooks()]
    books = [(b, cells) for b, cells in books if cells]
    assert len(books) >= 7, "fewer notebooks with solution cells than expected"
    for book, cells in books:
        seen = chapter_pages.get(book)["solutions"]  # as the page opened, then one click
        states = seen["states"]
        assert len(states) == len(cells), f"{book.stem}: {len(states)} of {len(cells)} read"
        _assert_hidden(states, book.stem)
        for s in states:  # built with the flag: every solution ran, its output collapsed
            assert s["ran"] == 1, f"{book.stem}: {s['sel']} did not run for the site"
            assert ASK not in s["text"], f"{book.stem}: {s['sel']} offers instead of showing"
        assert seen["opened_shown"] > 0, f"{book.stem}: the opened solution shows nothing"
        assert SUMMARY in seen["opened_text"], f"{book.stem}: no collapsed output shown"


def test_voila_solutions_are_collapsed(voila_all, artifacts):
    nb, _, watched = voila_all
    cells = solution_cells(nb)
    assert cells, f"{nb.name} has no solution cell"
    page = watched.page
    # Voila numbers its cells from 1 and shows the page once the last cell has run
    sels = [f'[cell-index="{i + 1}"] .jp-CodeCell' for i, _, _ in cells]
    page.wait_for_selector("#rendered_cells", state="visible", timeout=300_000)
    page.wait_for_function(
        "sels => sels.every(s => document.querySelector(s + ' .jp-OutputArea-output'))",
        arg=sels,
        timeout=300_000,
    )
    # the widgets (a solution's line and button) render once the page's kernel is connected
    page.wait_for_function(
        "([sels, ask]) => sels.every(s => (document.querySelector(s)?.textContent || '')"
        ".includes(ask))",
        arg=[sels, ASK],
        timeout=120_000,
    )
    states = page.evaluate(STATE, sels)
    _assert_hidden(states, f"Voila {nb.stem}")
    for s in states:  # a live kernel: no solution ran, each offers itself
        assert s["ran"] == 0 and ASK in s["text"], f"Voila: {s['sel']} ran unasked: {s['text']}"
        assert PRINTED_02_1 not in s["text"], f"Voila: {s['sel']} shows an answer unasked"
    page.locator(sels[0]).locator("xpath=ancestor::details[1]").scroll_into_view_if_needed()
    page.screenshot(path=str(artifacts / "solutions-voila-02.png"))
    assert open_first(page, sels[0]) > 0, "the opened solution shows nothing"
    assert PRINTED_02_1 not in visible_text(page, sels[0]), "opened, it ran without the click"
    page.screenshot(path=str(artifacts / "solutions-voila-02-open.png"))
    page.locator(sels[0]).get_by_role("button", name=f"Run solution {cells[0][2]}").click()
    page.wait_for_function(
        "([sel, text]) => (document.querySelector(sel)?.innerText || '').includes(text)",
        arg=[sels[0], PRINTED_02_1],
        timeout=120_000,
    )
    page.screenshot(path=str(artifacts / "solutions-voila-02-run.png"))
