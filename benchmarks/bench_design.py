"""Notebook 08: one explorer redraw (goal < 100 ms): PEB along the route, SR-NF overlay and the
smallest-array search, bounds only. The design's Monte-Carlo sweep: 4 arrays (4x4 8x8 16x16
32x32) x 20 runs of ``example-rectangular-28ghz`` on the bound route as one task set, serially
and on a local cluster of 1 and of 2 workers (goal <= 10 min; 2 workers >= 1.6x one; the group's
baseline is the 1-worker case, so its ratio column is the speed-up over one worker); the same
on the channel route (full synthesis and extraction every epoch) on a smaller sweep where the
work dominates: 4x4, 6x6 and 8x8 x 4 runs of the first 20 epochs. :func:`report` says whether
serial and parallel gave identical errors and validates the bound route against the channel
route on those three arrays (same seed, same epochs): settled RMSE and median error of each
route and their ratio (the bound route stands for an efficient extraction of the ideal channel,
so the ratio should be near 1 where the extraction is above its threshold)."""

from __future__ import annotations

import itertools

from run import Case

from tunnelkit.widgets.design import design_figure

SWEEP_ARRAYS = ("4x4", "8x8", "16x16", "32x32")
SWEEP_RUNS = 20
CHANNEL_ARRAYS = ("4x4", "6x6", "8x8")
CHANNEL_RUNS = 4
CHANNEL_EPOCHS = 20
_SWEEPS: dict[str, dict] = {}
_CHANNEL: dict[str, dict] = {}


def _sweep(workers):
    from tunnelkit.design import DesignSetup
    from tunnelkit.design.montecarlo import sweep_montecarlo

    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    res = sweep_montecarlo(setup, SWEEP_ARRAYS, SWEEP_RUNS, 0, mode="bound", workers=workers)
    _SWEEPS["serial" if workers is None else f"{workers} workers"] = res
    return res


def _channel(workers, mode="channel"):
    from tunnelkit.design import DesignSetup
    from tunnelkit.design.montecarlo import sweep_montecarlo

    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    res = sweep_montecarlo(
        setup,
        CHANNEL_ARRAYS,
        CHANNEL_RUNS,
        0,
        mode=mode,
        workers=workers,
        n_epochs=CHANNEL_EPOCHS,
    )
    _CHANNEL[f"{mode} {workers} workers"] = res
    return res


def _identical(runs: dict) -> bool:
    first = next(iter(runs.values()))
    return all(
        all((r.errors == other[a].errors).all() for a, r in first.items())
        for other in runs.values()
    )


def _validation() -> list[str]:
    """The bound route against the channel route on the channel sweep's arrays."""
    chan = next((r for k, r in _CHANNEL.items() if k.startswith("channel")), None)
    if chan is None:
        return []
    bound = _channel(None, mode="bound")
    lines = [
        f"bound route vs channel route (28 GHz example, {CHANNEL_RUNS} runs, first "
        f"{CHANNEL_EPOCHS} epochs, seed 0): settled RMSE / median error [mm], ratio channel/bound"
    ]
    for a, c in chan.items():
        b = bound[a]
        lines.append(
            f"  {a:6s} channel {c.rmse_settled * 1e3:8.3f} / {c.median_settled * 1e3:7.3f}   "
            f"bound {b.rmse_settled * 1e3:8.3f} / {b.median_settled * 1e3:7.3f}   "
            f"ratio {c.rmse_settled / b.rmse_settled:5.2f} / "
            f"{c.median_settled / b.median_settled:5.2f}   PEB {c.settled_rms(c.peb) * 1e3:7.3f}"
        )
    return lines


def report() -> str:
    """Settled RMSE per array of the sweep, whether serial and parallel agree bit for bit, and
    the bound route against the channel route."""
    lines = []
    if _SWEEPS:
        lines.append(
            "design sweep (bound route, seed 0): settled RMSE / PEB / posterior bound / bound "
            "over the drive [mm]"
        )
        first = next(iter(_SWEEPS.values()))
        for a, r in first.items():
            lines.append(
                f"  {a:6s} {r.rmse_settled * 1e3:8.3f} / {r.settled_rms(r.peb) * 1e3:7.3f} / "
                f"{r.settled_rms(r.pcrlb) * 1e3:7.3f} / {r.settled_rms(r.drive) * 1e3:7.3f}"
            )
        if len(_SWEEPS) > 1:
            lines.append(f"  serial, 1 and 2 workers identical: {_identical(_SWEEPS)}")
    chan = {k: v for k, v in _CHANNEL.items() if k.startswith("channel")}
    if len(chan) > 1:
        lines.append(f"channel sweep: 1 and 2 workers identical: {_identical(chan)}")
    lines += _validation()
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
            goal_s=600.0,
            repeat=3,
            warmup=False,
        ),
        Case(
            "design sweep 4 arrays x 20 runs, bound route, 1 worker",
            lambda: _sweep(1),
            group="design_sweep",
            baseline=True,
            goal_s=600.0,
            repeat=3,
            warmup=False,
        ),
        Case(
            "design sweep 4 arrays x 20 runs, bound route, 2 workers",
            lambda: _sweep(2),
            group="design_sweep",
            goal_s=600.0,
            repeat=3,
            warmup=False,
        ),
        Case(
            "design sweep 4x4 6x6 8x8 x 4 runs x 20 epochs, channel route, 1 worker",
            lambda: _channel(1),
            group="design_sweep_channel",
            baseline=True,
            repeat=1,
            warmup=False,
        ),
        Case(
            "design sweep 4x4 6x6 8x8 x 4 runs x 20 epochs, channel route, 2 workers",
            lambda: _channel(2),
            group="design_sweep_channel",
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
