"""The notebook tests (``make notebooks``: ``pytest --nbmake notebooks``) start their kernels over
Unix sockets in a private temporary directory, as the lecture tools do (``notebook_client`` in
tools/_lecture.py), so that two runs beside each other cannot be handed the same TCP port.

nbmake builds its ``NotebookClient`` in ``nbmake.nb_run`` with no setting for the transport; the
name it calls is replaced here by ``notebook_client``, which takes the same arguments.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

from _lecture import notebook_client


def pytest_configure(config) -> None:
    try:
        from nbmake import nb_run
    except ImportError:  # without nbmake there are no notebook tests to configure
        return
    nb_run.NotebookClient = notebook_client
