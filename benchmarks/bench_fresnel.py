"""Notebook 02: one explorer redraw (goal < 30 ms), the exact-Mmax curve and the ratio map."""

from __future__ import annotations

import numpy as np
from run import Case

from tunnelkit import fresnel
from tunnelkit.widgets.mmax import mmax_figure


def cases() -> list[Case]:
    R_curve = np.geomspace(0.5, 500.0, 61)
    R_map = np.geomspace(1.0, 200.0, 60)[None, :]
    y_map = np.linspace(-5.0, 2.95, 60)[:, None]

    def curve_loop():
        return [fresnel.mmax_exact(float(r), 3.0, 2.5, 28e9, 0.15) for r in R_curve]

    def map_loop():
        return [
            [fresnel.mmax_exact(float(r), 3.0, float(y), 5.9e9, 0.15) for r in R_map[0]]
            for y in y_map[:, 0]
        ]

    return [
        Case(
            "mmax_figure, paper example (M = 10)",
            lambda: mmax_figure(),
            group="mmax_figure",
            goal_s=0.03,
            repeat=30,
        ),
        Case(
            "mmax_figure, 28 GHz, R = 100 m, M = 256",
            lambda: mmax_figure(R=100.0, fc=28e9, M=256, z_u=-3.3),
            group="mmax_figure",
            goal_s=0.03,
            repeat=30,
        ),
        Case(
            "exact Mmax vs R (61 pts), vectorised",
            lambda: fresnel.mmax_exact_grid(R_curve, 3.0, 2.5, 28e9, 0.15),
            group="mmax_curve",
        ),
        Case(
            "exact Mmax vs R (61 pts), scalar loop", curve_loop, group="mmax_curve", baseline=True
        ),
        Case(
            "ratio map 60x60, vectorised",
            lambda: fresnel.mmax_exact_grid(R_map, 3.0, y_map, 5.9e9, 0.15),
            group="mmax_map",
        ),
        Case("ratio map 60x60, scalar loop", map_loop, group="mmax_map", baseline=True, repeat=3),
    ]
