"""JAVELIN-L (Italiano 2026 Tables 1-2, condition L) on both channel sources, seed 0 and held out.

For each drive (straight = Table 1, slalom = Table 2), channel (``image``: eq. 1 from the image
method; ``sionna``: the cached ray-traced tensor, diffuse scattering on, the ML fit tested against
noise + diffuse power) and seed (0 and :data:`tunnelkit.simulation.HELD_OUT_SEED`), ``--runs``
drives through the ML route (:func:`tunnelkit.reproduce.javelin_tables.javelin_table`,
condition L): the table's JAVELIN-L and TeNFiLoc-L rows, the epochs the extraction flagged, the
wall time.

On the ray-traced channel every epoch fails the extraction's residual test
(``benchmarks/bench_rt_residual.py`` says why), and a flagged epoch carries no measurement
(:func:`tunnelkit.simulation.drives.path_measurements`): the table then scores the tracker's
prediction from its start alone. ``--keep-flagged`` is the experiment beside it: in this process
only, the adapter passes the flagged epochs' measurements on (the same estimates; only the
``fit_ok`` verdict is ignored), so the tracker sees what the extraction measured. ``--model-error-share S`` keeps only the
flagged epochs whose residual passes the test with a stated model-error share ``S`` of the
received power (:func:`tunnelkit.signal_route.judging.model_error_test`; the share chosen on
the straight drive by ``benchmarks/bench_rt_flags.py``).

    python benchmarks/bench_rt_tables.py --runs 2 --drives straight --channels image sionna
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.reproduce.javelin_tables import javelin_table
from tunnelkit.simulation import HELD_OUT_SEED, drives

TABLES = {
    "straight": ("italiano2026-straight", "italiano2026_table1"),
    "slalom": ("italiano2026-slalom", "italiano2026_table2"),
}


def keep_flagged() -> None:
    """Let flagged epochs' measurements through :func:`drives.path_measurements` (this process)."""
    original = drives.path_measurements

    def adapter(ep, route):
        pm, reason = original(ep, route)
        if reason == drives.FLAGGED:
            m = ep.measurements
            pm = drives.PathMeasurements.from_arrays(
                m.phi, m.psi, m.kappa, m.d, m.v, warn=False, min_d=route.min_d
            )
            return pm, None
        return pm, reason

    drives.path_measurements = adapter


def model_error_share(share: float, tally: dict) -> None:
    """Judge the flagged epochs again with a stated model-error share (this process): an epoch
    the extraction flagged carries its measurements when its fit's residual passes
    :func:`tunnelkit.signal_route.judging.model_error_test` at ``share`` (against the
    snapshot's noise power and received energy); ``tally`` counts the epochs passed and kept
    flagged."""
    from tunnelkit.signal_route.judging import model_error_test

    original = drives.path_measurements

    def adapter(ep, route):
        pm, reason = original(ep, route)
        if reason != drives.FLAGGED:
            return pm, reason
        est, snap = ep.estimates, ep.snapshot
        r = snap.H - np.einsum("ml,sl,kl,l->msk", *est.factors, est.alpha)
        y2 = float(np.vdot(snap.H, snap.H).real)
        t = model_error_test(
            r, len(est), y2, ep.array.local, route.config.fc, snap.noise_power, share
        )
        tally["passed" if t["passed"] else "flagged"] += 1
        tally.setdefault("needed", []).append(t["needed"])
        if not t["passed"]:
            return pm, reason
        m = ep.measurements
        pm = drives.PathMeasurements.from_arrays(
            m.phi, m.psi, m.kappa, m.d, m.v, warn=False, min_d=route.min_d
        )
        return pm, None

    drives.path_measurements = adapter


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--drives", nargs="+", default=list(TABLES), choices=list(TABLES))
    ap.add_argument("--channels", nargs="+", default=["image", "sionna"])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, HELD_OUT_SEED])
    ap.add_argument("--keep-flagged", action="store_true")
    ap.add_argument("--model-error-share", type=float, default=None)
    a = ap.parse_args(argv)
    if a.keep_flagged:
        keep_flagged()
    tally = {"passed": 0, "flagged": 0}
    if a.model_error_share is not None:
        model_error_share(a.model_error_share, tally)
    for name in a.drives:
        scenario, ref = TABLES[name]
        for chan in a.channels:
            for seed in a.seeds:
                t0 = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    rep = javelin_table(
                        scenario,
                        ref,
                        ("L",),
                        a.runs,
                        seed,
                        False,
                        extractions=("ml",),
                        channel=chan,
                        nuisance={"diffuse_floor": True} if chan == "sionna" else None,
                    )
                wall = time.perf_counter() - t0
                fl, ep = rep.meta["flagged_epochs"]["ml"], rep.meta["epochs"]["ml"]
                print(
                    f"{name} channel={chan} seed={seed} runs={a.runs} keep_flagged={a.keep_flagged}: "
                    f"wall {wall:.0f} s ({wall / a.runs:.0f} s/run), flagged {fl} of {ep} epochs"
                )
                if a.model_error_share is not None:
                    nd = np.array(tally.pop("needed", []))
                    print(
                        f"  model-error share {a.model_error_share:.4g}: of the flagged epochs "
                        f"{tally['passed']} pass, {tally['flagged']} stay flagged; share needed "
                        f"median {np.median(nd) if nd.size else float('nan'):.3g}, "
                        f"max {np.max(nd) if nd.size else float('nan'):.3g}"
                    )
                    tally.update(passed=0, flagged=0)
                for row in rep.rows:
                    vals = ", ".join(
                        f"{c}: {v:.3f}" for c, v in zip(rep.columns[2:], row[2:]) if v is not None
                    )
                    print(f"  {row[0]:11s} {row[1]:10s} {vals}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
