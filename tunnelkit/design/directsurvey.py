"""What the direct tracker is told: the direct fix's surveyed angle errors by elevation.

The direct fit's line of sight (:mod:`tunnelkit.design.traceddirect`) goes to JAVELIN told its
azimuth and elevation sigmas by its measured elevation
(:class:`~tunnelkit.design.los.ElevationSigmas`). They come from a survey of the same route: the
RMS of the fixes fed on drives of one seed, in equal-count elevation bins
(:func:`~tunnelkit.design.los.elevation_sigmas`), told times :data:`SURVEY_SCALE` (the errors are
heavy-tailed and hold biases over several epochs, which a track told their RMS follows). Each
survey ships as a record in ``data/rt/direct/`` with the command that writes it and the table its
drives were told (``told_deg``). Two routes have surveys:

- the traced tables' (``<scenario>.json``: the scene's 10 x 10 from the truth,
  :mod:`tunnelkit.reproduce.javelin_direct`);
- the design's (``<scenario>-<array>.json``: the array's traced route from the drawn 1 m entry
  fix, ``tunnelkit design --traced-tracker direct``, :func:`design_table`).

A design route without a shipped survey is told the constant :data:`DESIGN_SIGMAS_DEG`, and its
report says so (:func:`direct_summary`). How the scale and the constant were chosen, and what
they are worth on held-out drives: ``docs/results/traced-models.md``.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np

from .._validate import instance, text
from .los import ElevationSigmas
from .setup import parse_array

__all__ = [
    "DESIGN_SIGMAS_DEG",
    "SURVEY_SCALE",
    "design_table",
    "direct_summary",
    "survey_path",
    "survey_record",
    "surveyed_table",
]

#: a survey's RMS is told times this (chosen on the traced tables' seed-0 drives, both paper
#: drives, among 1, 1.5, 2 and 3 with 4 or 8 bins: 8 bins times 2 was best on both; reported on
#: the tables' held-out seeds and on the design's held-out drives)
SURVEY_SCALE = 2.0

#: the direct fix's angle sigmas, (azimuth, elevation) [deg] at every elevation, told on a design
#: route without a survey: one constant pair, chosen on four 8 x 8 drives of the design's traced
#: route (``benchmarks/bench_rt_direct.py --seed 3``) against the array's survey table told as it
#: is and three times; loose where the fixes are better (the 28 GHz tunnel's azimuth errs 0.04
#: deg RMS)
DESIGN_SIGMAS_DEG = (2.0, 1.0)

#: the keys a survey record holds
_KEYS = ("scenario", "source", "command", "seed", "runs", "bins", "told_deg", "table_deg")


def survey_path(scenario: str, array: str | None = None) -> Path:
    """Where the survey of ``scenario``'s route ships: ``data/rt/direct/<scenario>.json`` (the
    traced tables') or, with ``array`` (a label such as ``"8x8"``),
    ``<scenario>-<array>.json`` (the design's)."""
    from ..scenarios import data_dir

    stem = text("scenario", scenario)
    if array is not None:
        stem = f"{stem}-{text('array', array)}"
    return data_dir() / "rt" / "direct" / f"{stem}.json"


def survey_record(scenario: str, array: str | None = None) -> dict | None:
    """The shipped survey of ``scenario``'s route (with ``array``: the design's route of that
    array), checked; None where none ships (a scenario file's path ships none)."""
    if "\0" in text("scenario", scenario):
        raise ValueError("scenario: a name or path holds no null character")
    if array is not None:
        try:
            array = parse_array(array).label
        except (TypeError, ValueError) as exc:  # named as this function names it
            raise type(exc)(f"array: {str(exc).removeprefix('spec: ')}") from None
    if any(c in scenario for c in "/\\") or scenario.startswith("."):
        return None
    return _load(scenario, array)


@functools.cache
def _load(scenario: str, array: str | None) -> dict | None:
    p = survey_path(scenario, array)
    if not p.is_file():
        return None
    rec = json.loads(p.read_text())
    missing = [k for k in _KEYS if k not in rec] if isinstance(rec, dict) else list(_KEYS)
    if missing:
        raise ValueError(f"scenario: {p} is no survey record (missing {missing})")
    if rec["scenario"] != scenario or rec.get("array") != array:
        raise ValueError(
            f"scenario: {p} records {rec['scenario']!r}, array {rec.get('array')!r}; expected "
            f"{scenario!r}, array {array!r}"
        )
    ElevationSigmas.from_dict(rec["table_deg"])  # a table, or the error naming what is wrong
    return rec


def surveyed_table(record: dict) -> ElevationSigmas:
    """The told table of a survey ``record`` (:func:`survey_record`): its RMS by elevation times
    :data:`SURVEY_SCALE`."""
    if not isinstance(record, dict) or "table_deg" not in record:
        raise TypeError("record: expected a survey record (survey_record)")
    return ElevationSigmas.from_dict(record["table_deg"]).scaled(SURVEY_SCALE)


def _constant() -> ElevationSigmas:
    return ElevationSigmas(np.zeros(1), *np.radians(np.array(DESIGN_SIGMAS_DEG)[:, None]))


def design_table(scenario: str, array) -> ElevationSigmas:
    """The direct fix's told sigmas on the design's traced route of ``array`` in ``scenario``
    (the design setup's name): the shipped survey of that route times :data:`SURVEY_SCALE`;
    without one, :data:`DESIGN_SIGMAS_DEG` at every elevation (one bin)."""
    rec = survey_record(scenario, array)
    return _constant() if rec is None else surveyed_table(rec)


def direct_summary(scenario: str, array, options: dict) -> dict:
    """What the design report's JSON says about the direct tracker (``error_model["direct"]``):
    its told table [deg] (:meth:`~tunnelkit.design.los.ElevationSigmas.as_dict`), the survey it
    came from (None: the constant) and the drive's ``options``."""
    instance("options", options, dict)
    rec = survey_record(scenario, array)
    survey = None
    if rec is not None:
        survey = {k: rec[k] for k in ("source", "command", "seed", "runs", "bins")}
        survey["scale"] = SURVEY_SCALE
    told = (_constant() if rec is None else surveyed_table(rec)).as_dict()
    return {"told_deg": told, "survey": survey, "options": dict(options)}
