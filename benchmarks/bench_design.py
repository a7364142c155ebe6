"""Notebook 08: one explorer redraw (goal < 100 ms): PEB along the route, SR-NF overlay and the
smallest-array search, bounds only. The design's Monte-Carlo sweep: 4 arrays (4x4 8x8 16x16
32x32) x 20 runs of ``example-rectangular-28ghz`` on the bound route as one task set, serially
and on a local cluster of 1 and of 2 workers (goal <= 10 min; 2 workers >= 1.6x one);
:func:`report` says whether they gave identical errors."""

from __future__ import annotations

import itertools

from run import Case

from tunnelkit.widgets.design import design_figure

SWEEP_ARRAYS = ("4x4", "8x8", "16x16", "32x32")
SWEEP_RUNS = 20
_SWEEPS: dict[str, dict] = {}


def _sweep(workers):
    from tunnelkit.design import DesignSetup
    from tunnelkit.design.montecarlo import sweep_montecarlo

    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    res = sweep_montecarlo(setup, SWEEP_ARRAYS, SWEEP_RUNS, 0, mode="bound", workers=workers)
    _SWEEPS["serial" if workers is None else f"{workers} workers"] = res
    return res


def report() -> str:
    """Settled RMSE per array of the sweep, and whether serial and 2 workers agree bit for bit."""
    if not _SWEEPS:
        return ""
    lines = ["design sweep (bound route, seed 0): settled RMSE / PEB / posterior bound [mm]"]
    first = next(iter(_SWEEPS.values()))
    for a, r in first.items():
        lines.append(
            f"  {a:6s} {r.rmse_settled * 1e3:8.3f} / {r.settled_rms(r.peb) * 1e3:7.3f} / "
            f"{r.settled_rms(r.pcrlb) * 1e3:7.3f}"
        )
    if len(_SWEEPS) > 1:
        same = all(
            all((r.errors == other[a].errors).all() for a, r in first.items())
            for other in _SWEEPS.values()
        )
        lines.append(f"  serial, 1 and 2 workers identical: {same}")
    return "\n".join(lines)


def cases() -> list[Case]:
    def paper(n):
        return lambda: design_figure(5.9, 100.0, n, 30.0, 4.8, scenario="italiano2026-straight")

    step = itertools.count(1)

    def moved_fc():
        # a new carrier on every call: nothing is reused from the previous redraw
        return design_figure(fc_ghz=28.0 + 0.01 * next(step))

    return [
        Case(
            "design sweep 4 arrays x 20 runs, bound route, serial",
            lambda: _sweep(None),
            group="design_sweep",
            baseline=True,
            goal_s=600.0,
            repeat=1,
            warmup=False,
        ),
        Case(
            "design sweep 4 arrays x 20 runs, bound route, 1 worker",
            lambda: _sweep(1),
            group="design_sweep",
            goal_s=600.0,
            repeat=1,
            warmup=False,
        ),
        Case(
            "design sweep 4 arrays x 20 runs, bound route, 2 workers",
            lambda: _sweep(2),
            group="design_sweep",
            goal_s=600.0,
            repeat=1,
            warmup=False,
        ),
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
