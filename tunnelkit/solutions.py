"""Exercise solutions in the notebooks: run with the notebook, shown only when asked for.

A solution cell (tag ``solution``; its first line names the exercise, ``# Solution 2: ...`` or
``# Exercise 4, solution (a): ...``) runs with Run All and in CI like any cell. JupyterLab hides
its source and outputs when the notebook opens (``jupyter.source_hidden``/``outputs_hidden``) but
shows the outputs again as soon as the cell runs. So :func:`install` (called by
``tk.setup_notebook()``) registers IPython hooks that capture what a solution cell prints or
displays and show it as one collapsed HTML ``<details>`` instead: the student sees a one-line
"show" summary under the exercise and opens it once they have tried. An error in a solution is not
captured (IPython reports it as usual, and the run fails).

A solution cell's last expression is not echoed (``display()`` or ``print`` what it should show).
"""

from __future__ import annotations

import html
import re
from typing import Any

#: the first non-blank line of a solution cell
SOLUTION_LINE = re.compile(r"^\s*#\s*(?:solution\b|exercise\s+\d+\s*,\s*solution\b)", re.IGNORECASE)
#: the collapsed output's summary line
SUMMARY = "Show the solution's output"
CSS_CLASS = "tk-solution-output"
WIDGET_MIME = "application/vnd.jupyter.widget-view+json"


def is_solution(source: str) -> bool:
    """Whether a cell's source is an exercise solution (by its first non-blank line)."""
    if not isinstance(source, str):
        raise TypeError(f"source: expected the cell's source as a str, got {type(source).__name__}")
    first = next((line for line in source.splitlines() if line.strip()), "")
    return bool(SOLUTION_LINE.match(first))


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


class SolutionOutputs:
    """The IPython hooks: capture a solution cell's output, then display it collapsed."""

    def __init__(self, shell) -> None:
        self.shell = shell
        self._capture = None
        self._captured = None
        self._interactivity = None

    def pre_run_cell(self, info) -> None:
        if not is_solution(getattr(info, "raw_cell", None) or ""):
            return
        from IPython.utils.capture import capture_output

        self._interactivity = self.shell.ast_node_interactivity
        self.shell.ast_node_interactivity = "none"  # the last expression would escape the capture
        self._capture = capture_output()
        self._captured = self._capture.__enter__()

    def post_run_cell(self, result) -> None:
        if self._capture is None:
            return
        capture, captured = self._capture, self._captured
        self._capture = self._captured = None
        capture.__exit__(None, None, None)
        self.shell.ast_node_interactivity = self._interactivity
        from IPython.display import HTML, display

        display(
            HTML(
                collapsed_html(captured.stdout, captured.stderr, [o.data for o in captured.outputs])
            )
        )


_INSTALLED: dict[int, SolutionOutputs] = {}


def install(shell=None) -> bool:
    """Register the hooks in ``shell`` (default: the running IPython, if any); once per shell.

    Returns whether they are installed (False outside IPython, e.g. in a plain script).
    """
    if shell is None:
        try:
            from IPython import get_ipython
        except ImportError:
            return False
        shell = get_ipython()
    if shell is None:
        return False
    if not hasattr(shell, "events"):
        raise TypeError(f"shell: expected an IPython shell, got {type(shell).__name__}")
    if id(shell) not in _INSTALLED:
        hooks = SolutionOutputs(shell)
        shell.events.register("pre_run_cell", hooks.pre_run_cell)
        shell.events.register("post_run_cell", hooks.post_run_cell)
        _INSTALLED[id(shell)] = hooks
    return True
