"""Commented TOML templates of your own scenario, written from a preset
(``tunnelkit scenarios new NAME --from PRESET``)."""

from __future__ import annotations

import os

from ..schemadoc import render_template
from .files import MAX_NAME_LENGTH, NAME_RE, load_scenario

__all__ = ["template"]


def template(name: str, preset: str | os.PathLike) -> str:
    """A commented TOML template named ``name`` holding ``preset``'s values.

    Every key is documented in a comment from the schema (doc, unit, range, default). A preset of
    the JAVELIN family (``italiano2026-*``) becomes a ``user`` file (your own tunnel): kind
    ``semicircular``, arrays with ``tilt_deg``, the trajectory as ``lane`` or ``slalom``; a
    ``user`` preset is copied; Jiang and Halili presets keep their family.
    """
    if not isinstance(name, str) or not NAME_RE.fullmatch(name):
        raise ValueError(
            f"name: expected a scenario name of letters, digits, '.', '_' or '-', got {name!r}"
        )
    if len(name) > MAX_NAME_LENGTH:
        raise ValueError(
            f"name: {len(name)} characters, longer than the {MAX_NAME_LENGTH} a scenario name may "
            "have (it becomes the file name NAME.toml)"
        )
    if not isinstance(preset, str | os.PathLike) or not str(preset):
        raise TypeError(f"preset: expected a scenario name or a path, got {preset!r}")
    sc = load_scenario(preset)
    vals = {k: v for k, v in sc.raw.items()}
    family = sc.family
    if family == "italiano2026":
        family, vals = "user", _italiano_to_user(sc.raw)
    vals["name"] = name
    vals["description"] = f"My tunnel, from {sc.name}: {sc.description}".strip()
    head = (
        f"Scenario {name!r}, written by `tunnelkit scenarios new {name} --from {sc.name}`.\n"
        f"Load it with tk.load_scenario('{name}.toml'); check it with `tunnelkit scenarios {name}.toml`.\n"
        "Units: SI (m, s, Hz) and degrees; x along the tunnel, y across (+y = left), z up, road at z = 0."
    )
    return render_template(family, vals, head)


def _italiano_to_user(raw: dict) -> dict:
    out = {k: v for k, v in raw.items() if k not in ("paper", "requires")}
    tun = dict(raw["tunnel"])
    tun["kind"] = "semicircular"
    out["tunnel"] = tun
    bs = dict(raw["base_station"])
    arrs = []
    for a in bs.get("arrays", []):
        a = dict(a)
        a["tilt_deg"] = -a.pop("elevation_deg")
        arrs.append(a)
    bs["arrays"] = arrs
    out["base_station"] = bs
    tr = dict(raw["trajectory"])
    amp = tr.pop("slalom_amplitude", 0.0)
    wl = tr.pop("slalom_wavelength", 20.0)
    if amp > 0:
        tr.update(kind="slalom", amplitude=amp, wavelength=wl)
    else:
        tr["kind"] = "lane"
    out["trajectory"] = tr
    return out
