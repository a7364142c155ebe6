"""A track bound beside the traced JAVELIN RMSEs: the posterior CRLB of the drive at the traced
sigmas (:func:`traced_pcrlb`).

The traced design (:mod:`tunnelkit.studies.traced`) tells JAVELIN the ML route's RMS extraction
error on the ray-traced channel. Fed those sigmas as independent Gaussian errors of every
first-order path, the design's drive bound (:func:`tunnelkit.design.position_information`,
:func:`tunnelkit.design.drive_pcrlb`: JAVELIN's motion model on the V2X speed and heading,
Tichavsky et al. 1998) says what such measurements allow a tracker told the reflectors.
"""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, instance
from ..design import DesignSetup, drive_pcrlb, position_information
from ..design.setup import parse_array
from ..design.tracedbounds import sigma_error_model
from ..odometry import Odometry
from ..simulation.prefilter import SIGMA_SCENARIO
from .traced import traced_errors

__all__ = ["traced_pcrlb"]


def traced_pcrlb(
    scenario: str = SIGMA_SCENARIO,
    *,
    rows=None,
    array: str = "10x10",
    sigma_p0: float = 1.0,
    odometry: Odometry | None = None,
) -> np.ndarray:
    """The posterior CRLB (T,) [m] of the 2-D position along ``scenario``'s drive when every
    first-order path (LoS, walls, ceiling, road, RRMs; the image method's, known reflectors) is
    measured at every epoch with independent zero-mean Gaussian errors of the traced sigmas
    (``rows``: an :func:`~tunnelkit.simulation.analysis.extraction_errors` table, its ``"all"`` row;
    default the stored record, :func:`~tunnelkit.studies.traced.traced_errors`), ``kappa`` as a range and ``d`` with the
    clock bias removed (:func:`tunnelkit.design.position_information`), JAVELIN's motion model
    on the V2X messages and a start of ``sigma_p0`` [m] (:func:`tunnelkit.design.drive_pcrlb`).
    ``array`` is the candidate mounted as the design mounts it (the paper's 10 x 10 by default);
    ``odometry`` the messages' model with its repeating errors as states
    (:func:`tunnelkit.design.drive_pcrlb`; None: the drive's own, its scenario's ``[odometry]``,
    the paper's white sigmas where it has none).

    A bound for a tracker told the reflectors; the traced errors are neither Gaussian nor
    independent between epochs (repeating biases of the bounces), so it is what the sigmas
    alone allow, not a bound on what the channel allows."""

    if not isinstance(scenario, str) or not scenario:
        raise TypeError(f"scenario: expected a preset name, got {scenario!r}")
    if not isinstance(array, str) or not array:
        raise TypeError(f"array: expected a candidate such as '10x10', got {array!r}")
    if rows is None:
        rows = traced_errors()["rows"]
    if not isinstance(rows, list | tuple) or not all(isinstance(r, list | tuple) for r in rows):
        raise TypeError(f"rows: expected the rows of extraction_errors, got {rows!r}")
    allrow = [r for r in rows if len(r) >= 6 and r[0] == "all"]
    if not allrow:
        raise ValueError("rows: no 'all' row of extraction_errors")
    a = allrow[0]
    sig = finite_array("rows", [np.radians(a[2]), np.radians(a[3]), a[4], a[5]])
    if np.any(sig <= 0):
        raise ValueError(f"rows: the 'all' row's sigmas must be > 0, got {a[2:6]}")
    try:
        spec = parse_array(array)
    except ValueError as exc:
        raise ValueError(f"array: {exc}") from None
    setup = DesignSetup.from_scenario(scenario)
    model, g = sigma_error_model(setup, spec, dict(zip(("phi", "psi", "kappa", "d"), sig)))
    if odometry is not None:
        instance("odometry", odometry, Odometry)
    return drive_pcrlb(setup, position_information(model, g), sigma_p0=sigma_p0, odometry=odometry)
