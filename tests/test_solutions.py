"""Exercise solution cells (tunnelkit.solutions): the ``%%solution`` magic runs a solution only when
asked for, or at once under TUNNELKIT_SOLUTIONS=1, always in a copy of the notebook's namespace."""

from __future__ import annotations

import sys

import pytest
from IPython.core.interactiveshell import InteractiveShell
from IPython.utils.capture import capture_output

import tunnelkit as tk
from tunnelkit import solutions

CELL = (
    "%%solution 01.1\n# Solution 1: the answer\nroute = 'solution'\nprint('the answer is', 6 * 7)\n"
)


@pytest.mark.parametrize(
    ("source", "sid"),
    [
        ("%%solution 02.2\n# Solution 2: the opposite lane\nx = 1", "02.2"),
        ("\n%%solution 04b.3\nprint(1)", "04b.3"),
        ("%%solution 03.4a\n# Exercise 4, solution (a): the wrong basin", "03.4a"),
        ("%%solution 03.12  \nx", "03.12"),
        ("# Solution 1: the comment alone is not the magic\nx = 1", None),
        ("%%solution\nx", None),
        ("%%solution 3.2\nx", None),
        ("%%solution 03.2 extra\nx", None),
        ("x = 1\n%%solution 01.1", None),
        ("%%time\nx", None),
        ("", None),
    ],
)
def test_a_solution_is_known_by_its_magic(source, sid):
    assert solutions.solution_id(source) == sid
    assert solutions.is_solution(source) is (sid is not None)


def test_exercise_of_and_title():
    assert solutions.exercise_of("04b.3") == ("04b", 3)
    assert solutions.exercise_of("03.4a") == ("03", 4)
    for bad in ("3.2", "03", "03.x", None):
        with pytest.raises(ValueError, match="sid"):
            solutions.exercise_of(bad)
    assert solutions.title("\n# Solution 2: the opposite lane\nx") == "the opposite lane"
    assert solutions.title("# Exercise 4, solution (a): the basin\nx") == "the basin"
    assert solutions.title("# Solution 1\nx") == ""
    assert solutions.title("# Solution 3: one (long\n# line)\nx = 1  # no") == "one (long line)"
    assert solutions.title("# a note: this\nx") == "a note: this"
    assert solutions.title("x = 1") == ""
    with pytest.raises(TypeError, match="source"):
        solutions.is_solution(None)


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


@pytest.mark.parametrize(("value", "expected"), [("1", True), ("yes", True), ("0", False)])
def test_the_flag(monkeypatch, value, expected):
    monkeypatch.setenv(solutions.ENV, value)
    assert solutions.at_once() is expected
    monkeypatch.delenv(solutions.ENV)
    assert solutions.at_once() is False


@pytest.fixture
def shell():
    sh = InteractiveShell.instance()
    assert solutions.install(sh) and solutions.install(sh)  # twice: registered once
    sh.user_ns["route"] = "lesson"
    yield sh
    solutions._INSTALLED.pop(id(sh))
    sh.magics_manager.magics["cell"].pop(solutions.MAGIC)
    InteractiveShell.clear_instance()


def _texts(cap) -> str:
    return cap.stdout + "".join(str(v) for o in cap.outputs for v in o.data.values())


def test_on_demand_nothing_runs_until_asked(shell, monkeypatch):
    monkeypatch.delenv(solutions.ENV, raising=False)
    with capture_output() as cap:
        res = shell.run_cell(CELL)
    assert res.success
    assert "the answer is" not in _texts(cap)  # Run All: not run ...
    assert shell.user_ns["route"] == "lesson"
    box = solutions._INSTALLED[id(shell)].bodies
    assert box == {"01.1": CELL.split("\n", 1)[1]}
    with capture_output() as cap:  # ... asked for: it runs, in a copy of the namespace
        tk.solution("01.1")
    assert "the answer is 42" in cap.stdout
    assert shell.user_ns["route"] == "lesson"
    with pytest.raises(KeyError, match=r"01\.2"):
        tk.solution("01.2")


def test_on_demand_the_button_runs_it_and_shows_the_line(shell, monkeypatch):
    monkeypatch.delenv(solutions.ENV, raising=False)
    sol = solutions._INSTALLED[id(shell)]
    with capture_output():
        box = sol._offer("01.1", CELL.split("\n", 1)[1])
    line, button, out = box.children
    assert solutions.ASK in line.value and "Solution 01.1 (the answer)" in line.value
    assert 'tk.solution("01.1")' in line.value
    assert button.description == "Run solution 01.1"
    with capture_output() as cap:
        button.click()
    assert "the answer is 42" in _texts(cap) + str(out.outputs)
    assert button.description.endswith("again") and shell.user_ns["route"] == "lesson"


def test_at_once_the_output_is_collapsed_and_the_globals_kept(shell, monkeypatch):
    monkeypatch.setenv(solutions.ENV, "1")
    with capture_output() as cap:
        res = shell.run_cell(CELL)
        shell.run_cell("print('an ordinary cell')")
    assert res.success
    assert "the answer is" not in cap.stdout  # captured, not printed
    assert "an ordinary cell" in cap.stdout
    html = [o.data["text/html"] for o in cap.outputs if "text/html" in o.data]
    assert len(html) == 1 and html[0].startswith(f'<details class="{solutions.CSS_CLASS}">')
    assert "the answer is 42" in html[0]
    assert shell.user_ns["route"] == "lesson"  # the solution's `route` stayed in its copy


def test_a_solution_sees_the_lesson_and_its_own_names(shell, monkeypatch):
    monkeypatch.setenv(solutions.ENV, "1")
    shell.user_ns["k"] = 5
    with capture_output() as cap:
        res = shell.run_cell("%%solution 01.2\ndef f():\n    return k * y\ny = 3\nprint(f())")
    assert res.success and "15" in cap.outputs[0].data["text/html"]
    assert "f" not in shell.user_ns and "y" not in shell.user_ns


def test_an_error_in_a_solution_fails_the_cell(shell, monkeypatch):
    monkeypatch.setenv(solutions.ENV, "1")
    with capture_output() as cap:
        res = shell.run_cell("%%solution 01.3\nprint('before')\nraise ValueError('boom')")
    assert isinstance(res.error_in_exec, ValueError)
    assert "before" in cap.outputs[0].data["text/html"]  # what ran is shown with the error
    monkeypatch.delenv(solutions.ENV)
    with capture_output():
        assert shell.run_cell("%%solution 01.3\nraise ValueError('boom')").success  # offered
    with pytest.raises(ValueError, match="boom"):
        tk.solution("01.3")


def test_a_malformed_id_is_refused(shell):
    with capture_output():
        res = shell.run_cell("%%solution 1\nprint('x')")
    assert isinstance(res.error_in_exec, ValueError)


def test_outside_a_notebook():
    InteractiveShell.clear_instance()
    assert solutions.install() is False
    with pytest.raises(RuntimeError, match="setup_notebook"):
        tk.solution("01.1")
    with pytest.raises(TypeError, match="shell"):
        solutions.install(object())


def test_without_ipywidgets_the_line_alone(shell, monkeypatch):
    monkeypatch.delenv(solutions.ENV, raising=False)
    monkeypatch.setitem(sys.modules, "ipywidgets", None)  # import fails
    with capture_output() as cap:
        assert solutions._INSTALLED[id(shell)]._offer("01.1", "# Solution 1: it\nx = 1") is None
    assert cap.stdout.strip() == solutions.ask_line("01.1", "# Solution 1: it", button=False)
    assert "button" not in cap.stdout and 'tk.solution("01.1")' in cap.stdout
