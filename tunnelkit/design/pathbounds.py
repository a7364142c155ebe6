"""The per-path CRLBs of a candidate array along the route (:func:`path_bounds`): delay
distance, direction and curvature of every traced path at every epoch, from
:func:`tunnelkit.extraction.crlb_paths` on the route of :func:`~tunnelkit.design.bounds.route_geometry`.
How it works: docs/internals/design.md."""

from __future__ import annotations

import numpy as np

from .._validate import instance
from ..constants import C
from .bounds import route_geometry
from .setup import DesignSetup, parse_array

__all__ = ["path_bounds"]


def path_bounds(setup: DesignSetup, spec, *, epochs=None) -> dict[str, np.ndarray]:
    """Per-path CRLBs along the route from :func:`tunnelkit.extraction.crlb_paths` (structured).

    Returns flat arrays over every (epoch, path): ``d`` [m] delay distance, ``direction`` [rad],
    ``kappa`` [m] (wavefront radius = distance to the VUE), ``kind`` (surface kind).
    """
    from ..extraction import crlb_paths  # tensorly and the extraction load only here

    instance("setup", setup, DesignSetup)
    spec = parse_array(spec)
    cfg = setup.config
    g = route_geometry(setup, spec, epochs=epochs)
    pos = spec.local(cfg.fc)
    out = {"d": [], "direction": [], "kappa": [], "kind": []}
    for t in range(len(g.ue)):
        j = np.flatnonzero(g.exists[t])
        if not j.size:
            continue
        src = (g.source[t, j] - g.origin[t]) @ g.rotation[t]
        d0 = np.linalg.norm(src, axis=1)
        res = crlb_paths(
            np.sqrt(cfg.tx_power) * g.gain[t, j],
            src,
            pos,
            -2 * np.pi * cfg.tone_spacing * d0 / C,
            2 * np.pi * cfg.symbol_period * g.doppler[t, j],
            cfg.fc,
            cfg.n_tones,
            cfg.n_symbols,
            cfg.noise_power,
            spatial="structured",
        )
        u = src / d0[:, None]
        proj = np.eye(3)[None] - u[:, :, None] * u[:, None, :]
        cov = res["source_cov"]
        out["d"].append(C / (2 * np.pi * cfg.tone_spacing) * res["mu_f"])
        var_dir = np.einsum("lij,ljk,lki->l", proj, cov, proj)
        var_kap = np.einsum("li,lij,lj->l", u, cov, u)
        # a variance that is not positive: the parameter is not identifiable (e.g. curvature
        # with 2 x 2 elements) and the inversion lost it in round-off -> an infinite bound
        with np.errstate(invalid="ignore"):
            out["direction"].append(np.where(var_dir > 0, np.sqrt(var_dir), np.inf) / d0)
            out["kappa"].append(np.where(var_kap > 0, np.sqrt(var_kap), np.inf))
        out["kind"].append(np.array(g.kinds)[j])
    return {k: np.concatenate(v) if v else np.zeros(0) for k, v in out.items()}
