"""The notebook tests (``make notebooks``: ``pytest --nbmake notebooks``) start their kernels over
Unix sockets in a private temporary directory, as the lecture tools do (``notebook_client`` in
tools/_lecture.py), so that two runs beside each other cannot be handed the same TCP port.

nbmake builds its ``NotebookClient`` in ``nbmake.nb_run`` with no setting for the transport; the
name it calls is replaced here by ``notebook_client``, which takes the same arguments.

The kernels inherit ``TUNNELKIT_SOLUTIONS=1`` unless it is set otherwise, so every exercise's
solution runs once, with the asserts on its reading (tunnelkit.solutions); a student's Run All
leaves them alone. ``TUNNELKIT_SOLUTIONS=0`` runs the notebooks as a student's Run All does.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

from _lecture import notebook_client


def pytest_configure(config) -> None:
    os.environ.setdefault("TUNNELKIT_SOLUTIONS", "1")
    try:
        from nbmake import nb_run
    except ImportError:  # without nbmake there are no notebook tests to configure
        return
    nb_run.NotebookClient = notebook_client
