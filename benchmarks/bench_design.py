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
so the ratio should be near 1 where the extraction is above its threshold).

One command for the parallel speed (``python benchmarks/bench_design.py``, :func:`main`): the
bound-route sweep serially, on 1 and on 2 workers, repetitions interleaved (the machine is
shared: each repetition runs the three in a rotated order and the load is printed per run), each
run timed as cluster start / sweep / stop, then the same sweep again on the cluster still
running (workers started and imported: the start-up excluded); then the channel route, 1 vs 2
workers, on a sweep whose tasks take seconds (4x4 and 8x8 x 4 runs x the first 8 epochs). A
table of medians, the ratios 1 worker / 2 workers from the same run, and whether every run gave
byte-identical JSON of errors and bounds.
"""

from __future__ import annotations

import itertools

from run import Case

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
            "design sweep (bound route, seed 0): settled RMSE / PEB / posterior CRLB / predicted "
            "over the drive [mm]"
        )
        first = next(iter(_SWEEPS.values()))
        for a, r in first.items():
            lines.append(
                f"  {a:6s} {r.rmse_settled * 1e3:8.3f} / {r.settled_rms(r.peb) * 1e3:7.3f} / "
                f"{r.settled_rms(r.pcrlb) * 1e3:7.3f} / {r.settled_rms(r.predicted) * 1e3:7.3f}"
            )
        if len(_SWEEPS) > 1:
            lines.append(f"  serial, 1 and 2 workers identical: {_identical(_SWEEPS)}")
    chan = {k: v for k, v in _CHANNEL.items() if k.startswith("channel")}
    if len(chan) > 1:
        lines.append(f"channel sweep: 1 and 2 workers identical: {_identical(chan)}")
    lines += _validation()
    return "\n".join(lines)


def cases() -> list[Case]:
    # imported here, not at the top: a worker process of a local cluster re-runs the top of the
    # script that started it (multiprocessing's spawn), and need not load the widgets
    from tunnelkit.widgets.design import design_figure

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


# --------------------------------------------------------------------------------------------
# one command: python benchmarks/bench_design.py


def _as_json(res: dict) -> str:
    """The sweep's numbers as JSON (errors, bounds, the tracker's sigmas), to compare bytes."""
    import json

    def arr(x):
        return None if x is None else [float(v) for v in x.ravel()]

    return json.dumps(
        {
            a: {
                "errors": arr(r.errors),
                "rmse_runs": arr(r.rmse_runs),
                "peb": arr(r.peb),
                "pcrlb": arr(r.pcrlb),
                "predicted": arr(r.predicted),
                "sigmas": r.sigmas,
            }
            for a, r in res.items()
        }
    )


def _profile_start(pool) -> dict:
    import time

    if not pool.parallel:
        return {}
    from distributed import get_task_stream

    ts = get_task_stream(pool.client)
    ts.__enter__()
    return {"ts": ts, "cpu": pool.client.run(time.process_time)}


def _profile_end(pool, prof: dict) -> str:
    """Worker CPU [s] spent in the sweep and the tasks' compute / transfer time by kind."""
    import time

    if not prof:
        return ""
    cpu = pool.client.run(time.process_time)
    prof["ts"].__exit__(None, None, None)
    by: dict[str, list[float]] = {}
    for t in prof["ts"].data:
        kind = str(t["key"]).split("-")[0].split(" ")[0]
        for ss in t["startstops"]:
            by.setdefault(f"{kind} {ss['action']}", []).append(ss["stop"] - ss["start"])
    used = [cpu[w] - prof["cpu"].get(w, 0.0) for w in cpu]
    parts = ", ".join(f"{k} {len(v)}x {sum(v):.2f}s" for k, v in sorted(by.items()))
    return f"worker CPU {'+'.join(f'{u:.2f}' for u in used)} s; tasks: {parts}"


def _timed(workers, mode, arrays, runs, n_epochs, warm: bool, schedulers=None) -> dict:
    """One run: start (a pool of ``workers``; serial without; with ``schedulers`` {workers:
    address} a connection to that running cluster instead), sweep, sweep again on the same
    cluster (``warm``), stop; wall times [s], main-process CPU, load, the numbers as JSON."""
    import os
    import time

    from tunnelkit.design import DesignSetup
    from tunnelkit.design.montecarlo import sweep_montecarlo
    from tunnelkit.runner import trial_pool

    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    kw = dict(mode=mode, n_epochs=n_epochs)
    out = {"load": os.getloadavg()[0]}
    cpu0, t0 = time.process_time(), time.perf_counter()
    where = {"workers": workers}
    if schedulers and workers in schedulers:
        where = {"scheduler": schedulers[workers]}
    with trial_pool(**where) as pool:
        t1 = time.perf_counter()
        prof = _profile_start(pool)
        res = sweep_montecarlo(setup, arrays, runs, 0, pool=pool, **kw)
        t2 = time.perf_counter()
        out["profile"] = _profile_end(pool, prof)
        out["json"] = [_as_json(res)]
        if warm:
            t3 = time.perf_counter()
            out["json"].append(_as_json(sweep_montecarlo(setup, arrays, runs, 0, pool=pool, **kw)))
            out["warm"] = time.perf_counter() - t3
        t4 = time.perf_counter()
    t5 = time.perf_counter()
    out.update(start=t1 - t0, sweep=t2 - t1, stop=t5 - t4, cpu_main=time.process_time() - cpu0)
    out["total"] = out["start"] + out["sweep"] + out["stop"]
    return out


def _label(w) -> str:
    return "serial" if w is None else f"{w} worker{'s' if w > 1 else ''}"


def _table(title: str, rows: dict, warm: bool) -> list[str]:
    import statistics as st

    med = {
        w: {k: st.median(r[k] for r in rs) for k in rs[0] if k in _COLS} for w, rs in rows.items()
    }
    lines = [
        title,
        f"  {'':10s} {'start':>7s} {'sweep':>7s} {'stop':>6s} {'total':>7s}"
        + (f" {'warm':>7s}" if warm else "")
        + f" {'load':>5s}   (medians [s] of {len(next(iter(rows.values())))})",
    ]
    for w, m in med.items():
        lines.append(
            f"  {_label(w):10s} {m['start']:7.2f} {m['sweep']:7.2f} {m['stop']:6.2f} {m['total']:7.2f}"
            + (f" {m['warm']:7.2f}" if warm else "")
            + f" {m['load']:5.1f}"
        )
    if 1 in med and 2 in med:
        r = med[1]["total"] / med[2]["total"]
        lines.append(f"  1 worker / 2 workers: {r:.2f}x start-up included (total)")
        lines.append(
            f"  1 worker / 2 workers: {med[1]['sweep'] / med[2]['sweep']:.2f}x sweep "
            "on a cluster just started (worker imports included)"
        )
        if warm:
            lines.append(
                f"  1 worker / 2 workers: {med[1]['warm'] / med[2]['warm']:.2f}x "
                "start-up excluded (the cluster running, workers warm)"
            )
    if None in med and 2 in med:
        lines.append(
            f"  serial / 2 workers: {med[None]['total'] / med[2]['total']:.2f}x (total), "
            + (
                f"{med[None]['warm'] / med[2]['warm']:.2f}x (a second serial sweep / warm)"
                if warm
                else ""
            )
        )
    same = {j for rs in rows.values() for r in rs for j in r["json"]}
    lines.append(f"  byte-identical JSON of errors and bounds in every run: {len(same) == 1}")
    return lines


_COLS = ("start", "sweep", "stop", "total", "warm", "load")


def _series(title, order, reps, warm, **kw) -> list[str]:
    rows: dict = {w: [] for w in order}
    for rep in range(reps):
        k = rep % len(order)
        for w in order[k:] + order[:k]:  # rotated: a load drift does not favour one case
            r = _timed(w, warm=warm, **kw)
            rows[w].append(r)
            print(
                f"  rep {rep + 1} {_label(w):10s} load {r['load']:5.1f}  start {r['start']:6.2f}  "
                f"sweep {r['sweep']:6.2f}  stop {r['stop']:5.2f}  total {r['total']:6.2f}"
                + (f"  warm {r['warm']:6.2f}" if warm else "")
                + f"  main CPU {r['cpu_main']:5.2f}  {r['profile']}",
                flush=True,
            )
    return _table(title, rows, warm)


def main(argv=None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description="the design sweep's parallel speed (module docstring)")
    ap.add_argument("--reps", type=int, default=3, help="repetitions of the bound-route sweep")
    ap.add_argument("--runs", type=int, default=SWEEP_RUNS)
    ap.add_argument("--channel-reps", type=int, default=3, help="0: no channel-route sweep")
    ap.add_argument("--channel-runs", type=int, default=4)
    ap.add_argument("--channel-epochs", type=int, default=8)
    ap.add_argument("--channel-warm", action="store_true", help="time a warm channel sweep too")
    ap.add_argument(
        "--schedulers",
        default=None,
        help="ADDR1,ADDR2: running clusters of 1 and of 2 workers used instead of local ones "
        "(start = connecting)",
    )
    args = ap.parse_args(argv)
    sched = None
    if args.schedulers:
        a1, a2 = args.schedulers.split(",")
        sched = {1: a1, 2: a2}
    import os

    from tunnelkit.design import DesignSetup
    from tunnelkit.design.montecarlo import sweep_montecarlo

    print(f"cores {os.cpu_count()}, load {os.getloadavg()}", flush=True)
    # this process's imports out of the way (the serial case would pay them once otherwise)
    setup = DesignSetup.from_scenario("example-rectangular-28ghz")
    sweep_montecarlo(setup, ["4x4"], 1, 0, mode="bound", n_epochs=3)
    lines = [f"bound route: {' '.join(SWEEP_ARRAYS)} x {args.runs} runs, 28 GHz example, seed 0"]
    print(lines[0], flush=True)
    kw = dict(mode="bound", arrays=SWEEP_ARRAYS, runs=args.runs, n_epochs=None, schedulers=sched)
    lines = _series(lines[0], [None, 1, 2], args.reps, True, **kw)
    if args.channel_reps:
        t = (
            f"channel route: 4x4 8x8 x {args.channel_runs} runs x the first "
            f"{args.channel_epochs} epochs, seed 0"
        )
        print(t, flush=True)
        kw = dict(
            mode="channel",
            arrays=("4x4", "8x8"),
            runs=args.channel_runs,
            n_epochs=args.channel_epochs,
            schedulers=sched,
        )
        lines += _series(t, [1, 2], args.channel_reps, args.channel_warm, **kw)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
