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


#: the order the notebooks run in. `make notebooks` runs them on two workers, and 08 takes
#: about 105 s in quick mode where the others take 6-27 s (docs/runtimes.md): 08 starts first,
#: with the shortest queued behind it (pytest-xdist hands each worker its next notebook before
#: the current one ends), and the other worker runs the rest, longest first, meanwhile: about
#: 120 s for the nine instead of 160 s with 08 started last. 09 (about 40 s with its solutions
#: since its section 4) runs after 03. A notebook not listed runs last.
ORDER = ("08", "01", "07", "03", "09", "04", "05", "04b", "06", "02")


def pytest_collection_modifyitems(config, items) -> None:
    rank = {n: i for i, n in enumerate(ORDER)}
    items.sort(key=lambda item: rank.get(item.path.name.split("-", 1)[0], len(rank)))
