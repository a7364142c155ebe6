"""Jiang et al. 2023, section 3.3: Monte-Carlo RMSE of LS and TSWLS against sqrt(CRLB)."""

from __future__ import annotations

import functools

import numpy as np

from .. import crlb, positioning
from ..runner import run_trials
from ..scenarios import load_scenario
from . import Report, register


@register(
    "jiang-crlb",
    help="RMSE of LS and TSWLS beside sqrt(CRLB) at the straight trajectory's start, three noise levels",
    default_runs=2000,
    bytes_per_run=4 * 1024,
)
def jiang_crlb(runs: int, seed: int, progress: bool, **parallel) -> Report:
    """One row per noise level of Tables 2-3; all trials at the straight trajectory's start point."""
    sc = load_scenario("jiang2023-straight")
    tunnel = sc.tunnel()
    stations = tunnel.virtual_stations(sc.base_station())
    p = sc.trajectory(tunnel).position[0]
    levels = sc.noise_levels()
    trial = functools.partial(_level_row, p, stations, runs)
    rows = run_trials(
        trial,
        len(levels),
        seed,
        inputs=list(levels),
        progress=progress,
        desc="noise levels",
        **parallel,
    )
    return Report(
        title="Jiang 2023 - NLOS joint TOA/DOA from two virtual stations: RMSE vs sqrt(CRLB)",
        columns=[
            "sigma_theta_deg",
            "sigma_d_m",
            "rmse_ls_m",
            "rmse_tswls_m",
            "sqrt_crlb_m",
            "ls_over_crlb",
            "tswls_over_crlb",
        ],
        rows=rows,
        meta={"position_m": [float(v) for v in p], "stations_m": stations.round(4).tolist()},
        notes=[
            "CRLB uses the corrected F_xy (minus sign on the angle term; the paper prints plus).",
            "The paper reports no per-point RMSE table for this experiment; the bound is the reference.",
        ],
    )


def _level_row(p, stations, runs: int, level: tuple[float, float], rng) -> list[float]:
    """One noise level: ``runs`` vectorised draws at ``p``, RMSE of LS and TSWLS beside the bound."""
    sth, sd = level
    bound = float(crlb.crlb_rmse(p, stations, sth, sd))
    d_hat, th_hat = positioning.simulate_toa_doa(p, stations, sth, sd, rng, size=runs)
    ls = float(
        np.sqrt(np.mean(np.sum((positioning.ls_toa_doa(stations, d_hat, th_hat) - p) ** 2, -1)))
    )
    tw = float(
        np.sqrt(np.mean(np.sum((positioning.tswls(stations, d_hat, th_hat, sd, sth) - p) ** 2, -1)))
    )
    return [float(np.degrees(sth)), sd, ls, tw, bound, ls / bound, tw / bound]
