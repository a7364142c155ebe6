"""Notebook 01: CRLB heat map (the slider callback) and a 2,000-trial TSWLS Monte-Carlo."""

from __future__ import annotations

import numpy as np
from run import Case

import tunnelkit as tk
from tunnelkit import crlb, positioning


def cases() -> list[Case]:
    sc = tk.load_scenario("jiang2023-straight")
    tunnel = sc.tunnel()
    vs = tunnel.virtual_stations(sc.base_station())
    p = sc.trajectory(tunnel).position[0]
    xs, ys = np.meshgrid(np.linspace(-20, 120, 200), np.linspace(-20, 120, 200))
    grid = np.stack([xs, ys], -1)
    sth, sd = np.radians(0.5), 0.1
    d_hat, th_hat = positioning.simulate_toa_doa(
        p, vs, sth, sd, np.random.default_rng(0), size=2000
    )

    def heatmap_loop():
        out = np.empty(grid.shape[:2])
        for i in range(grid.shape[0]):
            for j in range(grid.shape[1]):
                out[i, j] = crlb.crlb_trace(crlb.fim_toa_doa(grid[i, j], vs, sth, sd))
        return out

    return [
        Case(
            "crlb heat map 200x200, vectorised",
            lambda: crlb.crlb_rmse(grid, vs, sth, sd),
            group="crlb_map",
        ),
        Case(
            "crlb heat map 200x200, per-point loop",
            heatmap_loop,
            group="crlb_map",
            baseline=True,
            repeat=3,
        ),
        Case(
            "tswls 2000 trials, vectorised",
            lambda: positioning.tswls(vs, d_hat, th_hat, sd, sth),
            group="tswls",
            goal_s=0.05,
        ),
        Case(
            "ls 2000 trials, vectorised",
            lambda: positioning.ls_toa_doa(vs, d_hat, th_hat),
            group="tswls",
            baseline=True,
        ),
    ]
