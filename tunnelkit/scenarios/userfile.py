"""A ``user`` file's friendlier keys turned into the ones the shared builders read: each array's
``tilt_deg`` into its elevation, its spacing from ``spacing_m`` or ``spacing_wavelengths``, and
the radio's ``n_rb`` from its bandwidth when the file gives none (:func:`derive_user`, run by
:func:`tunnelkit.scenarios.files.scenario_from_dict` on a file without a ``paper`` key)."""

from __future__ import annotations

import numpy as np

from ..constants import wavelength
from ..schema import ScenarioError

#: nothing exported: a step of scenario_from_dict, on sections its schema has validated
__all__: list[str] = []


def derive_user(sec: dict, raw: dict, where: str) -> None:
    """Fill the keys the shared builders read from a ``user`` file's friendlier ones."""
    radio = sec["radio"]
    lam = float(wavelength(radio["fc"]))
    for i, (arr, given) in enumerate(
        zip(sec["base_station"]["arrays"], raw["base_station"]["arrays"])
    ):
        if "spacing_m" in given and "spacing_wavelengths" in given:
            raise ScenarioError(
                f"{where}: 'base_station.arrays[{i}].spacing_m' and '.spacing_wavelengths' both "
                "given; keep one"
            )
        arr["elevation_deg"] = -arr["tilt_deg"]
        arr["spacing"] = (
            arr["spacing_m"] if "spacing_m" in arr else arr["spacing_wavelengths"] * lam
        )
    if "n_rb" not in radio:
        n_rb = int(np.floor(0.983 * radio["bandwidth"] / (12 * radio["scs"]) + 1e-9))
        if n_rb < 1:
            raise ScenarioError(
                f"{where}: 'radio.bandwidth' {radio['bandwidth']:g} Hz holds no resource block of "
                f"12 subcarriers at radio.scs = {radio['scs']:g} Hz"
            )
        radio["n_rb"] = n_rb
