"""``tunnelkit reproduce javelin-table1|2 --channel sionna --diffuse-floor`` drive by drive, resumable.

A traced drive takes minutes on a loaded machine, so a 20-run table on the ray-traced channel may
not finish in one sitting. Here each drive (table ``T``, seed ``S``, run ``r``, condition ``c``:
drive ``i = n r + c`` of the table's ``n`` conditions, drawn from the ``i``-th child of the seed
exactly as :func:`tunnelkit.runner.run_trials` draws it, with one BLAS thread as there) is
simulated (:func:`tunnelkit.studies.traced.simulate_traced`: the paper's route, the ML route and
the traced column's measurements from the same tensors) and scored in every column
(:func:`tunnelkit.reproduce.javelin_tables.score_drive`), as the reproduce target's trial
(``javelin_tables._simulate_and_score``) does; the result and the drives (tensors are not kept)
go to ``DIR/<table>-seed<S>/drive<i>.pkl``. ``--conditions L`` runs only the drives of those
conditions (their rows equal the full table's: same drive indices); ``--report`` assembles the
table from the whole runs saved so far; ``--rescore OUT`` scores the saved drives again with the
current designs (e.g. after the traced record changed) into ``OUT``. Runs are interleaved over the tables and seeds given
(run 0 of each, then run 1, ...), so a cut-off leaves them with equal counts.

    nice python benchmarks/bench_rt_javelin.py --tables 1 2 --seeds 0 20261202 --conditions L \
        --runs 20 --dir /tmp/rtj
    python benchmarks/bench_rt_javelin.py --tables 1 2 --seeds 0 20261202 --conditions L --report \
        --dir /tmp/rtj
"""

from __future__ import annotations

import argparse
import functools
import json
import pickle
import sys
import time
import warnings
from pathlib import Path

from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.montecarlo import spawn_rngs
from tunnelkit.odometry import MODELS
from tunnelkit.reproduce import javelin_tables as jt
from tunnelkit.reproduce.javelin_traced import LOS_COLUMN, los_drive, los_survey
from tunnelkit.simulation.drives import FLAGGED
from tunnelkit.studies.traced import simulate_traced

TABLES = {
    "1": ("italiano2026-straight", "italiano2026_table1", ("L", "N@0.5", "N", "NoRRMs")),
    "2": ("italiano2026-slalom", "italiano2026_table2", ("L", "N@0.5", "N")),
}
EXTRACTIONS = ("paper", "ml")
NUISANCE = {"diffuse_floor": True}


@functools.cache
def _survey(scenario: str):
    """The line-of-sight column's table and summary for ``scenario`` (once per process)."""
    return los_survey(scenario)


def _score(drives: dict, cond: str, told=None, motion_step: str | None = None) -> dict:
    """One drive's routes scored in every column of the traced table (one BLAS thread), every
    JAVELIN told the odometry model ``told`` (None: the white model) and stepping on the messages
    as ``motion_step`` says (``None`` each design its own; eq. 62's ``"held"`` or ``"midpoint"``
    for every design); the line-of-sight column's
    drive made from the ML route's ``"ml-all"`` here (a drive saved before that column has none)."""
    routes = jt._traced_routes(EXTRACTIONS, "sionna")
    if LOS_COLUMN[1] not in drives:
        table = _survey(drives["ml"].scenario)[0]
        drives = {**drives, LOS_COLUMN[1]: los_drive(drives["ml-all"], table)}
    with threadpool_limits(limits=1, user_api="blas"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return jt.score_drive(
            {e: drives[e] for e in routes}, cond, jt.table_columns(routes), told, motion_step
        )


def _nuisance(second_order: int = 0) -> dict:
    """The route's model: the diffuse floor, and ``second_order`` second-order nuisance atoms."""
    return {**NUISANCE, "second_order": second_order} if second_order else NUISANCE


def drive(
    table: str,
    seed: int,
    i: int,
    n_epochs: int | None = None,
    odometry: str = "white",
    second_order: int = 0,
):
    """Drive ``i`` of ``table`` at ``seed`` on the V2X messages' model ``odometry`` (a name of
    :data:`tunnelkit.odometry.MODELS`), the route's model with ``second_order`` second-order
    nuisance atoms: ``((cond, (scores, faults)), drives)``."""
    scenario, _, conds = TABLES[table]
    rng = spawn_rngs(seed, i + 1)[i]
    cond = conds[i % len(conds)]
    routes = jt._traced_routes(EXTRACTIONS, "sionna")
    with threadpool_limits(limits=1, user_api="blas"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        drives = simulate_traced(
            scenario,
            rng,
            condition=cond,
            n_epochs=n_epochs,
            channel="sionna",
            nuisance=_nuisance(second_order),
            odometry=MODELS[odometry],
        )
    drives[LOS_COLUMN[1]] = los_drive(drives["ml-all"], _survey(scenario)[0])
    scores = _score(drives, cond)
    faults = {
        e: (len(drives[e].faults), sum(f.endswith(FLAGGED) for f in drives[e].faults),
            len(drives[e].t))
        for e in routes
    }  # fmt: skip
    return (cond, (scores, faults)), drives


def simulate(
    tables, seeds, runs, conditions, out: Path, n_epochs=None, odometry="white", second_order=0
) -> None:
    for r in range(runs):
        for t in tables:
            conds = TABLES[t][2]
            for s in seeds:
                d = out / f"table{t}-seed{s}"
                d.mkdir(parents=True, exist_ok=True)
                for c, cond in enumerate(conds):
                    if cond not in conditions:
                        continue
                    i = len(conds) * r + c
                    f = d / f"drive{i}.pkl"
                    if f.exists():
                        continue
                    t0, c0 = time.perf_counter(), time.process_time()
                    res, drives = drive(t, s, i, n_epochs, odometry, second_order)
                    tmp = f.with_suffix(".tmp")
                    tmp.write_bytes(
                        pickle.dumps({"result": res, "drives": drives, "motion_step": None})
                    )
                    tmp.rename(f)
                    print(
                        f"table {t} seed {s} drive {i} ({cond}): {time.perf_counter() - t0:.0f} s "
                        f"wall, {time.process_time() - c0:.0f} s CPU, faults {res[1][1]}",
                        flush=True,
                    )


def _faults(saved: dict) -> dict:
    """A saved drive's fault counts per route, the line-of-sight route's (absent from drives saved
    before that column) counted from the drive it is cut from (``"ml-all"``)."""
    faults = dict(saved["result"][1][1])
    if LOS_COLUMN[1] not in faults:
        d = saved["drives"]["ml-all"]
        faults[LOS_COLUMN[1]] = (
            len(d.faults),
            sum(f.endswith(FLAGGED) for f in d.faults),
            len(d.t),
        )
    return faults


def rescore(tables, seeds, conditions, src: Path, out: Path, told=None, motion_step=None) -> None:
    """Every drive saved in ``src`` scored again with the current designs (the traced design
    reads the stored record now), no drive simulated again; written to ``out`` in the same
    layout, so ``--report --dir OUT`` tables them; ``told`` and ``motion_step`` as in
    :func:`_score`."""
    for t in tables:
        conds = TABLES[t][2]
        for s in seeds:
            d_in, d_out = src / f"table{t}-seed{s}", out / f"table{t}-seed{s}"
            d_out.mkdir(parents=True, exist_ok=True)
            for f in sorted(d_in.glob("drive*.pkl")):
                i = int(f.stem.removeprefix("drive"))
                cond = conds[i % len(conds)]
                if cond not in conditions:
                    continue
                saved = pickle.loads(f.read_bytes())
                res = (cond, (_score(saved["drives"], cond, told, motion_step), _faults(saved)))
                saved = {"result": res, "drives": saved["drives"], "motion_step": motion_step}
                (d_out / f.name).write_bytes(pickle.dumps(saved))
                print(f"table {t} seed {s} drive {i} ({cond}) rescored", flush=True)


def report(
    table: str,
    seed: int,
    conditions,
    out: Path,
    fmt: str = "text",
    odometry: str = "white",
    told: bool = False,
    second_order: int = 0,
) -> str:
    scenario, ref, conds = TABLES[table]
    conds = tuple(c for c in conds if c in conditions)
    n = len(TABLES[table][2])
    d = out / f"table{table}-seed{seed}"
    done, r, steps = [], 0, set()
    while True:
        idx = [n * r + TABLES[table][2].index(c) for c in conds]
        if not all((d / f"drive{i}.pkl").exists() for i in idx):
            break
        saved = [pickle.loads((d / f"drive{i}.pkl").read_bytes()) for i in idx]
        done += [x["result"] for x in saved]
        # None: each design its own step; drives saved without the key were scored all held
        steps |= {x.get("motion_step", "held") for x in saved}
        r += 1
    if len(steps) > 1:
        names = sorted("each design's own" if x is None else x for x in steps)
        return (
            f"table {table} seed {seed}: drives scored with two motion steps {names} in {d} "
            "(drives saved before each design took its own step were scored all held): rescore "
            "the directory (--rescore OUT, with --motion-step held to keep the old scoring)"
        )
    if not done:
        return f"table {table} seed {seed}: no whole run saved yet in {d}"
    rep = jt._report(
        scenario,
        ref,
        conds,
        EXTRACTIONS,
        done,
        "sionna",
        _nuisance(second_order),
        None,
        {},
        seed,
        odometry,
        told,
        survey=_survey(scenario)[1],
        motion_step=steps.pop(),
    )
    rep.meta = {"target": f"javelin-table{table}", "runs": r, "seed": seed, **rep.meta}
    return rep.to_json() if fmt == "json" else rep.to_table() + "\n" + json.dumps(rep.meta)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tables", nargs="+", default=["1", "2"], choices=list(TABLES))
    ap.add_argument("--seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--conditions", nargs="+", default=["L", "N@0.5", "N", "NoRRMs"])
    ap.add_argument("--n-epochs", type=int, default=None)
    ap.add_argument("--dir", default="rt_javelin")
    ap.add_argument("--report", action="store_true")
    ap.add_argument("--rescore", metavar="OUT", default=None,
                    help="score the drives saved in --dir again with the current designs, into OUT")  # fmt: skip
    ap.add_argument("--format", default="text", choices=("text", "json"))
    ap.add_argument("--odometry", default="white", choices=sorted(MODELS),
                    help="the V2X messages' model (one --dir per model)")  # fmt: skip
    ap.add_argument("--motion-step", default=None, choices=["held", "midpoint"],
                    help="with --rescore: how every JAVELIN steps on the messages (default: "
                    "each design its own, the paper's eq. 62, ours the midpoint)")  # fmt: skip
    ap.add_argument("--told-odometry", action="store_true",
                    help="JAVELIN told the --odometry model (with --rescore, then --report)")  # fmt: skip
    ap.add_argument("--second-order", type=int, default=0,
                    help="second-order nuisance atoms in the route's model (one --dir per value)")  # fmt: skip
    a = ap.parse_args()
    if a.motion_step is not None and not a.rescore:
        ap.error(
            "--motion-step: with --rescore (the drives are simulated and scored with each "
            "design's own step first)"
        )
    if a.told_odometry and a.odometry == "white":
        ap.error("--told-odometry: the tracker is told the white model already")
    told = MODELS[a.odometry] if a.told_odometry else None
    out = Path(a.dir)
    if a.rescore:
        rescore(a.tables, a.seeds, a.conditions, out, Path(a.rescore), told, a.motion_step)
    elif a.report:
        for t in a.tables:
            for s in a.seeds:
                print(report(t, s, a.conditions, out, a.format, a.odometry, a.told_odometry,
                             a.second_order))  # fmt: skip
    else:
        simulate(a.tables, a.seeds, a.runs, a.conditions, out, a.n_epochs, a.odometry,
                 a.second_order)  # fmt: skip
