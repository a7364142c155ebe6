"""Exercise solutions in the notebooks: run when the student asks for them, or at once under a flag.

A solution cell (tag ``solution``) starts with the cell magic ``%%solution NN.E``: the notebook's
number and the exercise's (``%%solution 03.2``; ``%%solution 03.4a`` for part (a) of exercise 4).
Its next line says what it answers (``# Solution 2: the opposite lane at 28 GHz``).
:func:`install`, called by ``tk.setup_notebook()``, registers the magic.

* **On demand** (the default, e.g. Run All in JupyterLab): the body does not run. The cell shows
  one line, "Solution 03.2 ... run it when you have tried", and a button (where ipywidgets is
  installed) that runs the body and shows its output below; ``tk.solution("03.2")`` in any cell
  does the same once the solution's cell has run.
* **At once**, with ``TUNNELKIT_SOLUTIONS=1`` (the notebook tests, ``notebooks/conftest.py``; the
  static site, ``tools/_lecture.py``): the body runs when its cell runs, and what it prints or
  displays is shown as one closed HTML ``<details>`` (its summary "Show the solution's output"),
  so CI executes every solution once and the site's reader opens an answer when ready. An error
  in a solution is raised: the cell, and the run, fail.

Either way the body runs in a copy of the notebook's namespace (``dict(shell.user_ns)``): a name a
solution assigns stays in the solution, so it never rebinds the lesson's globals and no later cell
can come to depend on it (``tools/check_notebooks.py`` checks that). The copy is shallow: a
solution must not change one of the lesson's objects in place (copy it first). Its last expression
is not echoed (``display()`` or ``print`` what it should show).
"""

from __future__ import annotations

import html
import linecache
import os
import re
from typing import Any

#: the cell magic's name, and the environment flag that runs every solution at once
MAGIC = "solution"
ENV = "TUNNELKIT_SOLUTIONS"
#: the first non-blank line of a solution cell: ``%%solution 03.2``, ``%%solution 04b.1``,
#: ``%%solution 03.4a``
SOLUTION_LINE = re.compile(r"^%%solution[ \t]+(\d\d[a-z]?\.(\d+)[a-z]?)[ \t]*$")
#: the collapsed output's summary line (at once) and the line shown instead of it (on demand)
SUMMARY = "Show the solution's output"
ASK = "run it when you have tried"
CSS_CLASS = "tk-solution-output"
WIDGET_MIME = "application/vnd.jupyter.widget-view+json"


def _first_line(source: str) -> str:
    if not isinstance(source, str):
        raise TypeError(f"source: expected the cell's source as a str, got {type(source).__name__}")
    return next((line.strip() for line in source.splitlines() if line.strip()), "")


def solution_id(source: str) -> str | None:
    """The solution's id (``"03.2"``) if the cell starts with the magic, else None."""
    m = SOLUTION_LINE.match(_first_line(source))
    return m.group(1) if m else None


def is_solution(source: str) -> bool:
    """Whether a cell's source is an exercise solution (its first non-blank line is the magic)."""
    return solution_id(source) is not None


def exercise_of(sid: str) -> tuple[str, int]:
    """(notebook number, exercise number) of a solution id: ``"04b.3"`` -> ``("04b", 3)``."""
    m = SOLUTION_LINE.match(f"%%{MAGIC} {sid}") if isinstance(sid, str) else None
    if m is None:
        raise ValueError(f"sid: expected a solution id such as '03.2' or '03.4a', got {sid!r}")
    return sid.split(".", 1)[0], int(m.group(2))


def title(body: str) -> str:
    """What a solution answers: the comment it starts with (its lines joined), without the
    exercise's number (``# Solution 2: the opposite lane`` -> ``the opposite lane``)."""
    lines = body.strip().splitlines() if isinstance(body, str) else []
    comment = []
    for line in lines:
        if not line.strip().startswith("#"):
            break
        comment.append(line.strip().lstrip("#").strip())
    text = " ".join(comment)
    return re.sub(r"(?i)^(?:exercise\s+\d+\s*,\s*)?solution\b[^:]*:?\s*", "", text)


def at_once() -> bool:
    """Whether solutions run when their cell runs (``TUNNELKIT_SOLUTIONS=1``)."""
    return os.environ.get(ENV, "").strip().lower() in ("1", "true", "yes")


def collapsed_html(stdout: str, stderr: str, outputs: list[dict[str, Any]]) -> str:
    """One closed ``<details>`` holding a cell's printed text, rich outputs and warnings.

    ``outputs`` are display data (MIME type -> value): their HTML when they have one, else their
    plain text.
    """
    for name, text in (("stdout", stdout), ("stderr", stderr)):
        if not isinstance(text, str):
            raise TypeError(f"{name}: expected a str, got {type(text).__name__}")
    if not isinstance(outputs, list) or not all(isinstance(o, dict) for o in outputs):
        raise TypeError("outputs: expected a list of MIME bundles (dicts)")
    parts = [f"<pre>{html.escape(stdout)}</pre>"] if stdout else []
    for data in outputs:
        if WIDGET_MIME in data:  # a progress bar: nothing to read once the cell has run
            continue
        if "text/html" in data:
            parts.append(str(data["text/html"]))
        elif "text/plain" in data:
            parts.append(f"<pre>{html.escape(str(data['text/plain']))}</pre>")
    if stderr:
        parts.append(f'<pre class="{CSS_CLASS}-stderr">{html.escape(stderr)}</pre>')
    body = "\n".join(parts) or "<p>(no output)</p>"
    return f'<details class="{CSS_CLASS}"><summary>{SUMMARY}</summary>\n{body}\n</details>'


def ask_line(sid: str, body: str, button: bool = True) -> str:
    """The line an un-run solution shows (``button``: whether a button is shown below it)."""
    what = title(body)
    how = f'{"the button or " if button else ""}tk.solution("{sid}") in a cell'
    return f"Solution {sid}{f' ({what})' if what else ''}: {ASK}, with {how}."


class Solutions:
    """The ``%%solution`` magic of one IPython shell and the bodies it has seen."""

    def __init__(self, shell) -> None:
        self.shell = shell
        self.bodies: dict[str, str] = {}

    def execute(self, sid: str, body: str) -> dict[str, Any]:
        """Run a solution's body in a copy of the user namespace; the namespace it leaves."""
        from IPython.display import display

        ns = dict(self.shell.user_ns)
        ns.setdefault("display", display)  # a builtin only while IPython runs a cell
        source = self.shell.transform_cell(body)
        filename = f"<solution {sid}>"
        linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
        exec(compile(source, filename, "exec"), ns)  # the notebook's own cell, in its copy
        return ns

    def magic(self, line: str, cell: str | None) -> None:
        """``%%solution NN.E``: remember the body; run it now under the flag, else offer it."""
        sid = line.strip()
        exercise_of(sid)  # a malformed id fails here, before anything runs
        body = cell or ""
        self.bodies[sid] = body
        if at_once():
            self._run_collapsed(sid, body)
        else:
            self._offer(sid, body)

    def _run_collapsed(self, sid: str, body: str) -> None:
        from IPython.display import HTML, display
        from IPython.utils.capture import capture_output

        error = None
        with capture_output() as captured:
            try:
                self.execute(sid, body)
            except Exception as exc:  # raised below, once what ran before it is shown
                error = exc
        outputs = [o.data for o in captured.outputs]
        display(HTML(collapsed_html(captured.stdout, captured.stderr, outputs)))
        if error is not None:
            raise error

    def _offer(self, sid: str, body: str):
        """Show the line and the button that runs the body; the widget shown (None without
        ipywidgets)."""
        from IPython.display import display

        try:
            import ipywidgets as w
        except ImportError:
            print(ask_line(sid, body, button=False))
            return None
        text = ask_line(sid, body)
        button = w.Button(
            description=f"Run solution {sid}",
            icon="play",
            button_style="info",
            layout=w.Layout(width="auto"),
        )
        out = w.Output()

        def run(_button) -> None:
            out.clear_output()
            button.description = f"Run solution {sid} again"
            with out:  # an error is shown here, as a traceback
                self.execute(sid, body)

        button.on_click(run)
        box = w.VBox([w.HTML(f"<p>{html.escape(text, quote=False)}</p>"), button, out])
        box.add_class(CSS_CLASS.replace("output", "ask"))
        display(box)
        return box

    def run(self, sid: str) -> None:
        """Run a solution whose cell has run (on demand: ``tk.solution("03.2")``)."""
        exercise_of(sid)
        if sid not in self.bodies:
            known = ", ".join(sorted(self.bodies)) or "none yet"
            raise KeyError(
                f"solution {sid!r}: its cell has not run yet (Run All runs it without running "
                f"the solution); solutions known: {known}"
            )
        self.execute(sid, self.bodies[sid])


_INSTALLED: dict[int, Solutions] = {}


def install(shell=None) -> bool:
    """Register ``%%solution`` in ``shell`` (default: the running IPython, if any); once per shell.

    Returns whether it is registered (False outside IPython, e.g. in a plain script).
    """
    if shell is None:
        try:
            from IPython import get_ipython
        except ImportError:
            return False
        shell = get_ipython()
    if shell is None:
        return False
    if not hasattr(shell, "register_magic_function"):
        raise TypeError(f"shell: expected an IPython shell, got {type(shell).__name__}")
    if id(shell) not in _INSTALLED:
        sol = Solutions(shell)
        shell.register_magic_function(sol.magic, magic_kind="cell", magic_name=MAGIC)
        _INSTALLED[id(shell)] = sol
    return True


def run(sid: str) -> None:
    """Run solution ``sid`` (``"03.2"``) of this notebook, as its button does."""
    exercise_of(sid)  # a solution id, refused by name before anything runs
    from IPython import get_ipython

    shell = get_ipython()
    if shell is None or id(shell) not in _INSTALLED:
        raise RuntimeError("solutions run in a notebook after tk.setup_notebook()")
    _INSTALLED[id(shell)].run(sid)
