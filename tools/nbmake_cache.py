"""pytest plugin for ``make notebooks``: every notebook nbmake runs is run as ``execute`` in
_lecture.py runs it (the same kernel environment, widget state kept, the live FigureWidgets dumped
after the last cell) and, when it passes, stored in ``execute``'s cache (build/executed/).

``make test`` runs the notebooks first and the browser tests after: the browser tests' site build
(tools/site.py) then renders these runs instead of executing every notebook a second time. The
notebooks are checked as before (nbmake fails on any cell's error, the Checks cells included);
what nbmake reports is unchanged. The cache is written only for runs with every solution run
(``TUNNELKIT_SOLUTIONS=1``), as ``execute`` runs them; otherwise the plugin does nothing.

    python -m pytest -p tools.nbmake_cache --nbmake notebooks    (the Makefile's `notebooks`)
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _lecture import add_widget_dump, inputs_digest, kernel_env, store_executed

import tunnelkit as tk
from tunnelkit import solutions


def pytest_configure(config) -> None:
    try:
        from nbmake import nb_run
    except ImportError:  # no nbmake, no notebook runs to keep
        return
    run = nb_run.NotebookRun.execute
    if getattr(run, "keeps_executed", False):
        return

    def execute(self):
        if not solutions.at_once():
            return run(self)
        path = Path(self.filename).resolve()
        quick = tk.quick_mode()
        digest = inputs_digest(path, quick)  # of the inputs as they were when the run began
        make_client = nb_run.NotebookClient  # notebooks/conftest.py's notebook_client

        def client(nb, **kwargs):
            add_widget_dump(nb)
            return make_client(nb, store_widget_state=True, **kwargs)

        saved = dict(os.environ)
        os.environ.update(kernel_env(quick, solutions=True))  # the kernel inherits it
        nb_run.NotebookClient = client
        try:
            result = run(self)
        finally:
            nb_run.NotebookClient = make_client
            os.environ.clear()
            os.environ.update(saved)
        if result.error is None:
            store_executed(result.nb, path, quick, digest)
        return result

    execute.keeps_executed = True
    nb_run.NotebookRun.execute = execute
