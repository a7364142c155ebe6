"""The explorer's quick look (:func:`smallest_meeting`): the first candidate array whose
predicted error meets the target, a prediction, not an answer (that is
:func:`~tunnelkit.design.design_sweep` with units).
"""

from __future__ import annotations

import numpy as np

from .._validate import choice, finite_array, positive, probability, sequence
from .achievable import predicted_error
from .bounds import route_bounds, route_geometry
from .impairments import design_impairments
from .setup import ArraySpec, DesignSetup, parse_array
from .verdict import CRITERIA, gate

__all__ = ["smallest_meeting"]


def smallest_meeting(
    setup: DesignSetup,
    arrays,
    *,
    target: float = 0.2,
    share: float = 0.9,
    criterion: str = "achievable",
    impairments="calibrated",
    eps_phi: float = 0.15,
    epochs=None,
) -> tuple[ArraySpec | None, float]:
    """The first array of ``arrays`` (in the order given) whose **predicted error** meets
    ``target`` on ``share`` of the route, and its met share; ``(None, best share)`` if none.

    A prediction for the explorer, not an answer (the answer is
    :func:`~tunnelkit.design.design_sweep` with units): with ``criterion="achievable"``
    (default) the predicted error under ``impairments`` (as the sweep's; ``"ideal"``: the PEB),
    SR-NF only information; with ``"srnf"`` (an eq. 51 estimator) an epoch where SR-NF fails
    counts as missed. Arrays that do not fit are skipped; ``epochs``
    subsamples the route."""
    sequence("arrays", arrays), epochs is None or finite_array("epochs", epochs, ndim=1)
    target = positive("target", target)
    share = probability("share", share, open_interval=False)
    if share == 0:
        raise ValueError("share: expected a share in (0, 1], got 0")
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    criterion = choice("criterion", criterion, CRITERIA)
    specs = [parse_array(a) for a in arrays]
    imp = design_impairments(impairments, setup, specs) if specs else None
    best = 0.0
    for spec in specs:
        try:
            g = route_geometry(setup, spec, epochs=epochs)
        except ValueError:
            continue
        b = route_bounds(setup, spec, eps_phi=eps_phi, geometry=g, peb=False)
        if criterion == "srnf" and b.srnf_valid.mean() < share:
            continue
        a = predicted_error(setup, spec, imp, geometry=g)
        met = float(np.mean(gate(a.predicted, b.srnf_valid, criterion) <= target))
        if met >= share:
            return spec, met
        best = max(best, met)
    return None, best
