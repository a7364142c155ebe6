"""Notebook 08: one explorer redraw (goal < 100 ms): PEB along the route, SR-NF overlay and the
smallest-array search, bounds only."""

from __future__ import annotations

import itertools

from run import Case

from tunnelkit.widgets.design import design_figure


def cases() -> list[Case]:
    def paper(n):
        return lambda: design_figure(5.9, 100.0, n, 30.0, 4.8, scenario="italiano2026-straight")

    step = itertools.count(1)

    def moved_fc():
        # a new carrier on every call: nothing is reused from the previous redraw
        return design_figure(fc_ghz=28.0 + 0.01 * next(step))

    return [
        Case(
            "explorer, 28 GHz 8x8, fc slider moved",
            moved_fc,
            group="design_explorer",
            goal_s=0.1,
            repeat=15,
        ),
        Case(
            "explorer, 28 GHz 400 MHz, 8x8 (default)",
            lambda: design_figure(),
            group="design_explorer",
            goal_s=0.1,
            repeat=15,
        ),
        Case(
            "explorer, 28 GHz 400 MHz, 16x16",
            lambda: design_figure(n=16),
            group="design_explorer",
            goal_s=0.1,
            repeat=15,
        ),
        Case(
            "explorer, 28 GHz 400 MHz, 32x32",
            lambda: design_figure(n=32),
            group="design_explorer",
            goal_s=0.1,
            repeat=9,
        ),
        Case(
            "explorer, paper's tunnel 5.9 GHz, 10x10",
            paper(10),
            group="design_explorer",
            goal_s=0.1,
            repeat=15,
        ),
    ]
