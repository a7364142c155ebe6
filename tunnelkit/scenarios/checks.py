"""What a scenario must satisfy beyond its schema, checked once on load: sizes that fit in
memory, and a base station, arrays and route inside the tunnel (one placement check per family,
registered in :data:`tunnelkit.scenarios.registry.CHECKS`; Halili's drive registers its own in
:mod:`tunnelkit.doppler_drive`)."""

from __future__ import annotations

import numpy as np

from ..schema import ScenarioError
from .model import Scenario
from .registry import CHECKS, register_check

__all__ = ["MAX_ELEMENTS", "MAX_SAMPLES", "MAX_TENSOR_BYTES", "check_placement"]

#: most trajectory samples a scenario file may ask for
MAX_SAMPLES = 1_000_000
#: most elements per array (64 x 64)
MAX_ELEMENTS = 4096
#: largest channel tensor (elements x tones x symbols, complex128) a file may ask for
MAX_TENSOR_BYTES = 2 * 2**30


def check_placement(sc: Scenario) -> None:
    """Build tunnel and trajectory once; base station, arrays and route must lie inside
    (the family's registered check; :class:`ScenarioError` naming the key otherwise)."""
    if not isinstance(sc, Scenario):
        raise TypeError(f"sc: expected a Scenario, got {type(sc).__name__}")
    CHECKS.lookup(sc.family, sc.path.name)(sc)


@register_check("jiang2023", "italiano2026", "user")
def _check_inside_tunnel(sc: Scenario) -> None:
    where, sec = sc.path.name, sc.sections
    _check_sizes(sc)
    tun = sc.tunnel()
    bs = np.asarray(sec["base_station"]["position"], dtype=float)
    if sc.family == "jiang2023":
        if not tun.contains(bs):
            raise ScenarioError(
                f"{where}: 'base_station.position' {bs.tolist()} lies outside the tunnel walls"
            )
    else:
        _check_arrays_inside(sc, tun, bs)
    sc.trajectory(tun)


def _check_sizes(sc: Scenario) -> None:
    """Refuse sizes that would exhaust memory before anything is allocated."""
    where, sec = sc.path.name, sc.sections
    tr = sec["trajectory"]
    if sc.family == "jiang2023":
        levels = np.asarray(sec.get("noise", {}).get("levels", np.zeros((0, 2))), dtype=float)
        if levels.size and np.any(levels[:, 0] > 180.0):
            raise ScenarioError(f"{where}: 'noise.levels' angle sigmas must be <= 180 deg")
        return
    radio = sec["radio"]
    if radio["bandwidth"] >= 2 * radio["fc"]:
        raise ScenarioError(
            f"{where}: 'radio.bandwidth' {radio['bandwidth']:g} Hz around radio.fc = "
            f"{radio['fc']:g} Hz reaches 0 Hz (the band must lie inside (0, inf): bandwidth < 2 fc; "
            "both are in Hz)"
        )
    n_rb = radio.get("n_rb", 273)
    if 12 * n_rb * radio["scs"] > radio["bandwidth"] * 1.0001:
        raise ScenarioError(
            f"{where}: 'radio.n_rb' {n_rb} resource blocks at radio.scs = {radio['scs']:g} Hz "
            f"occupy {12 * n_rb * radio['scs']:g} Hz, more than radio.bandwidth = "
            f"{radio['bandwidth']:g} Hz"
        )
    n_tones = -(-12 * n_rb // radio["comb"])
    for i, arr in enumerate(sec["base_station"]["arrays"]):
        m = arr["shape"][0] * arr["shape"][1]
        if m > MAX_ELEMENTS:
            raise ScenarioError(
                f"{where}: 'base_station.arrays[{i}].shape' {arr['shape']} has {m} elements, "
                f"more than {MAX_ELEMENTS}"
            )
        size = 16 * m * n_tones * radio["n_symbols"]
        if size > MAX_TENSOR_BYTES:
            raise ScenarioError(
                f"{where}: 'base_station.arrays[{i}].shape' {arr['shape']} x {n_tones} tones x "
                f"{radio['n_symbols']} symbols needs a {size / 2**30:.1f} GiB channel tensor, "
                f"more than {MAX_TENSOR_BYTES / 2**30:g} GiB (fewer elements, radio.n_symbols or "
                "a larger radio.comb)"
            )
    n = abs(tr["x_end"] - tr["x_start"]) / (tr["speed"] * tr["period"])
    if n > MAX_SAMPLES:
        raise ScenarioError(
            f"{where}: 'trajectory.period' {tr['period']:g} s gives {n:.3g} epochs "
            f"(|x_end - x_start| / (speed period)), more than {MAX_SAMPLES:g}"
        )


def _check_arrays_inside(sc: Scenario, tun, bs: np.ndarray) -> None:
    where = sc.path.name
    if not tun.contains(bs, margin=1e-6):
        raise ScenarioError(
            f"{where}: 'base_station.position' {bs.tolist()} lies outside the tunnel "
            "(in a wall, above the roof, under the road or beyond its ends)"
        )
    try:
        arrays = sc.arrays()
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ScenarioError):
            raise
        raise ScenarioError(f"{where}: base_station.arrays: {exc}") from None
    for i, box in enumerate(getattr(tun, "blockers", ())):
        if np.all(bs >= box.lo) and np.all(bs <= box.hi):
            raise ScenarioError(
                f"{where}: 'tunnel.blockers[{i}]' ({box.name}) encloses 'base_station.position' "
                f"{bs.tolist()}: every path would be blocked"
            )
    lo = np.array([tun.x_range[0], -tun.width / 2, 0.0])
    hi = np.array([tun.x_range[1], tun.width / 2, tun.height])
    for i, arr in enumerate(arrays):
        full = f"base_station.arrays[{i}]"
        if not tun.contains(arr.origin, margin=1e-6):
            raise ScenarioError(
                f"{where}: '{full}.offset' puts the reference antenna at {arr.origin.tolist()}, "
                "outside the tunnel"
            )
        # elements: inside the tunnel's bounding box (the paper's 10 x 10 URA at 4.8 m reaches a
        # few cm above the 12-facet polygon near the crown, so facets would reject the paper)
        out = ~np.all((arr.world > lo - 1e-9) & (arr.world < hi + 1e-9), axis=-1)
        if np.any(out):
            raise ScenarioError(
                f"{where}: '{full}.shape' {arr.M} elements reach {arr.world[int(np.argmax(out))].round(3).tolist()}, "
                f"outside the tunnel's cross-section (|y| <= {tun.width / 2:g}, 0 <= z <= {tun.height:g} m)"
            )
