"""The residual test with a stated model-error share: chosen on one drive, checked on another.

Reads the JSON of ``benchmarks/bench_rt_mcrb.py`` for a drive to choose on (the straight drive)
and a held-out drive (the slalom). The share is chosen as the smallest that lets every fit of the
choosing drive whose noise-free limit is the pseudo-true point pass: the residual at the
pseudo-true paths and the local fits about them (:func:`tunnelkit.signal_route.judging.model_error_test`;
``--margin`` multiplies it). On the held-out drive, per epoch: the share of fits the test flags
(local fits about the pseudo-true point and the route's full extraction), and, over the fits whose
first-order delays lie beyond ``--z`` MCRB standard deviations of the pseudo-true ones, how many
are flagged; over those within, how many are flagged anyway (false flags).

    python benchmarks/bench_rt_flags.py /tmp/mcrb-straight.json /tmp/mcrb-slalom.json
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np


def _needed(test: dict) -> float:
    return float(test.get("needed", test.get("share")))


def choose(drive: dict, margin: float) -> float:
    """The smallest share every model-error-only fit of ``drive`` passes with, times ``margin``."""
    need = []
    for e in drive["epochs"]:
        need.append(_needed(e["pseudo_true_test"]))
        need += [_needed(d["test"]) for d in e["local"]]
    return margin * max(need)


def _beyond(fit: dict, z: float) -> bool | None:
    """Any first-order delay beyond ``z`` MCRB sd of the pseudo-true one; None when a path's
    ``z`` is unknown (an unmatched estimate)."""
    v = np.abs(np.asarray(fit["z_mcrb"], float))
    if not np.all(np.isfinite(v)):
        return None
    return bool(np.any(v > z))


def report(drive: dict, share: float, z: float) -> dict:
    rows = []
    tot = {"beyond": 0, "beyond_flagged": 0, "within": 0, "within_flagged": 0, "unknown": 0}
    for e in drive["epochs"]:
        fits = [("local", d) for d in e["local"]] + [("full", d) for d in e["full"]]
        row = {"k": e["k"], "residual_share": e["residual_share"], "definite": e["definite"]}
        for kind in ("local", "full"):
            f = [d for k, d in fits if k == kind]
            flagged = [_needed(d["test"]) > share for d in f]
            row[kind] = (int(sum(flagged)), len(f))
        for _, d in fits:
            b, fl = _beyond(d, z), _needed(d["test"]) > share
            if b is None:
                tot["unknown"] += 1
                continue
            tot["beyond" if b else "within"] += 1
            tot[("beyond" if b else "within") + "_flagged"] += int(fl)
        rows.append(row)
    return {"rows": rows, "totals": tot}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("choose_on", type=Path)
    ap.add_argument("held_out", type=Path)
    ap.add_argument("--margin", type=float, default=1.0)
    ap.add_argument("--z", type=float, default=6.0)
    a = ap.parse_args(argv)
    first = json.loads(a.choose_on.read_text())
    second = json.loads(a.held_out.read_text())
    share = choose(first, a.margin)
    print(f"model-error share chosen on {first['scenario']}: {share:.4g} (margin {a.margin})")
    for drv in (first, second):
        r = report(drv, share, a.z)
        print(f"{drv['scenario']}:")
        for row in r["rows"]:
            print(
                f"  epoch {row['k']:2d}: residual at the pseudo-true paths "
                f"{row['residual_share']:.3g} of P_rx, A definite {row['definite']}; flagged "
                f"local fits {row['local'][0]}/{row['local'][1]}, full extraction "
                f"{row['full'][0]}/{row['full'][1]}"
            )
        t = r["totals"]
        print(
            f"  fits beyond {a.z:g} MCRB sd of the pseudo-true delays: {t['beyond']}, flagged "
            f"{t['beyond_flagged']}; within: {t['within']}, flagged (false flags) "
            f"{t['within_flagged']}; z unknown (unmatched): {t['unknown']}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
