"""The collapsed output of exercise solution cells (tunnelkit.solutions)."""

from __future__ import annotations

import pytest
from IPython.core.interactiveshell import InteractiveShell
from IPython.utils.capture import capture_output

from tunnelkit import solutions


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("# Solution 2: the opposite lane\nx = 1", True),
        ("\n# solution 1\nprint(1)", True),
        ("# Exercise 4, solution (a): starts in the wrong basin", True),
        ("# Solutions below\nx", False),
        ("x = 1  # Solution 1", False),
        ("# Checks\nassert True", False),
        ("print('Solution 1')", False),
        ("", False),
    ],
)
def test_a_solution_is_known_by_its_first_line(source, expected):
    assert solutions.is_solution(source) is expected


def test_collapsed_html_holds_everything_escaped_and_skips_progress_bars():
    out = solutions.collapsed_html(
        "a < b\n",
        "UserWarning: w\n",
        [
            {"text/html": "<table><tr><td>1</td></tr></table>", "text/plain": "T"},
            {"text/plain": "x & y"},
            {solutions.WIDGET_MIME: {"model_id": "m"}, "text/plain": "HBox(children=...)"},
        ],
    )
    assert out.startswith(f'<details class="{solutions.CSS_CLASS}"><summary>')
    assert out.endswith("</details>") and " open" not in out.split(">", 1)[0]
    for part in ("a &lt; b", "<table><tr><td>1</td></tr></table>", "x &amp; y", "UserWarning: w"):
        assert part in out
    assert "HBox" not in out


@pytest.mark.parametrize(
    ("args", "name"),
    [((b"x", "", []), "stdout"), (("", None, []), "stderr"), (("", "", [1]), "outputs")],
)
def test_collapsed_html_validates(args, name):
    with pytest.raises(TypeError, match=name):
        solutions.collapsed_html(*args)
    with pytest.raises(TypeError, match="source"):
        solutions.is_solution(None)


@pytest.fixture
def shell():
    sh = InteractiveShell.instance()
    assert solutions.install(sh) and solutions.install(sh)  # twice: hooks registered once
    yield sh
    hooks = solutions._INSTALLED.pop(id(sh))
    sh.events.unregister("pre_run_cell", hooks.pre_run_cell)
    sh.events.unregister("post_run_cell", hooks.post_run_cell)
    InteractiveShell.clear_instance()


def test_a_solution_cell_shows_one_closed_details_with_its_output(shell):
    with capture_output() as cap:
        shell.run_cell("# Solution 1: it\nprint('the answer is 42')\n6 * 7")
        shell.run_cell("print('an ordinary cell')\n6 * 7")
    assert "the answer is 42" not in cap.stdout  # captured, not printed
    assert "an ordinary cell" in cap.stdout
    html = [o.data["text/html"] for o in cap.outputs if "text/html" in o.data]
    assert len(html) == 1 and html[0].startswith('<details class="tk-solution-output">')
    assert "the answer is 42" in html[0] and "42</pre>" not in html[0].replace("is 42", "")
    assert shell.ast_node_interactivity == "last_expr"  # restored after the solution cell


def test_an_error_in_a_solution_is_not_swallowed(shell):
    with capture_output():
        res = shell.run_cell("# Solution 3\nraise ValueError('boom')")
    assert isinstance(res.error_in_exec, ValueError)
    assert shell.ast_node_interactivity == "last_expr"
