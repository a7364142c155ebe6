"""The notebooks' own calls: :func:`setup_notebook` (the renderer, the solutions' magic, one
line on the version and the mode), :func:`solution` (an exercise's solution on demand) and
:func:`build_dir` (where a notebook writes its files). ``tk.setup_notebook()`` loads this module.
"""

from __future__ import annotations

from pathlib import Path

from ._version import __version__
from .montecarlo import quick_mode

__all__ = ["build_dir", "setup_notebook", "solution"]


def setup_notebook(*, renderer: str | None = None) -> None:
    """The one setup call every notebook makes after ``import tunnelkit as tk``.

    Sets a plotly renderer that works both in JupyterLab and when the notebook is executed
    headless (CI, static site), registers the ``%%solution`` magic of exercise solution cells
    (:mod:`tunnelkit.solutions`: run on demand, or at once with ``TUNNELKIT_SOLUTIONS=1``) and
    prints one line: the package version and whether quick mode
    is on. Returns None, so the call is not echoed as a cell result.
    """
    # the type and emptiness first: the first look at plotly's renderer registry loads it (seconds)
    if renderer is not None and not isinstance(renderer, str):
        raise TypeError(f"renderer: expected a plotly renderer name, got {type(renderer).__name__}")
    if renderer == "":
        raise ValueError("renderer: must not be empty (None keeps the default renderer)")
    import plotly.io as pio

    if renderer is not None and renderer not in pio.renderers:
        raise ValueError(
            f"renderer: expected one of plotly's renderers ({', '.join(list(pio.renderers)[:6])}, "
            f"...), got {renderer!r}"
        )
    if renderer is not None:
        pio.renderers.default = renderer
    elif pio.renderers.default in (None, "", "browser"):
        pio.renderers.default = "notebook_connected+plotly_mimetype"
    pio.templates.default = "plotly_white"
    from .solutions import install

    install()  # exercise solutions: run when asked for (tunnelkit.solutions)
    mode = "quick (TUNNELKIT_QUICK=1: Monte-Carlo counts shrunk for CI)" if quick_mode() else "full"
    print(f"tunnelkit {__version__} · mode: {mode}")


def solution(sid: str) -> None:
    """Run an exercise's solution in this notebook once you have tried: ``tk.solution("03.2")``
    (notebook 03, exercise 2), as the button under its cell does (:mod:`tunnelkit.solutions`)."""
    from .solutions import run

    run(sid)


def build_dir(*parts: str) -> Path:
    """A directory under the repository's ``build/`` (created), for files a notebook writes.

    The repository is the nearest directory at or above the working directory that holds
    ``pyproject.toml`` (a notebook runs in ``notebooks/``); elsewhere ``./build``.
    """
    here = Path.cwd().resolve()
    root = next((p for p in (here, *here.parents) if (p / "pyproject.toml").is_file()), here)
    out = root.joinpath("build", *parts)
    out.mkdir(parents=True, exist_ok=True)
    return out
