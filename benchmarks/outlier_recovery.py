"""Outlier recovery of every tracker: one gross outlier mid-drive, against the same drive without it.

``python benchmarks/outlier_recovery.py [--seeds N] [--particles N]`` prints one row per tracker and
outlier: the peak deviation of the position estimate from the estimate on the clean drive (same
noise, same GNSS fix or prior, same filter seed) after the outlier epoch, and the number of epochs
after the outlier until the deviation stays below ``TOL`` for the rest of the drive ("never" if it
is still above at the end). Medians over ``--seeds`` seeds (a different noise draw per seed).
"dropped" is the peak deviation when that epoch is dropped instead (NaN): what a perfect outlier
detector costs (a gated filter cannot do better than losing the epoch).

Outliers: +2 kHz on one Doppler sample, +100 m on one ToA or one range, +90 deg on one bearing.
The Halili drive is the default synthetic drive (1,688 epochs of 32 ms; outlier at epoch 844,
before the pass at epoch 1,156); the Jiang run is the straight NLOS preset at 2 deg / 2 m (100
epochs of 0.1 s; outlier at epoch 50). "calibration" puts the ToA outlier on the first ToA, the
one the KF on ToA calibrates its clock offset with; its last column is the median error against
the truth over the whole drive (without / with the outlier).

Only public interfaces are used, so the script measures any version of the package on the path.
"""

from __future__ import annotations

import argparse
import dataclasses
import warnings

import numpy as np

from tunnelkit import doppler_drive as dv
from tunnelkit.constants import C
from tunnelkit.tracking import registry
from tunnelkit.tracking import virtual_station as vs

#: deviation [m] below which a track counts as recovered: Halili drive (errors of metres), Jiang
#: run (errors of decimetres)
TOL = {"halili2022": 0.5, "jiang2023": 0.05}


def recovery(dev: np.ndarray, k0: int, tol: float) -> tuple[float, int | None]:
    """Peak deviation from epoch ``k0`` on, and epochs after ``k0`` until it stays below ``tol``."""
    d = dev[k0:]
    above = np.flatnonzero(d >= tol)
    if above.size == 0:
        return float(d.max()), 0
    last = int(above[-1])
    return float(d.max()), (None if last == len(d) - 1 else last + 1)


def _quiet(fn, *a, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*a, **kw)


def halili_rows(seeds) -> list[dict]:
    drive = dv.make_drive(dv.load_drive_config())
    fam = registry.family("halili2022")
    setup_cls = __import__("tunnelkit.tracking.doppler", fromlist=["DopplerSetup"]).DopplerSetup
    setup = setup_cls.from_drive(drive)
    k0 = len(drive.t) // 2
    cases = [
        ("EKF DS", "Doppler +2 kHz", k0, 2000.0, 0.0),
        ("KF DS and ToA", "Doppler +2 kHz", k0, 2000.0, 0.0),
        ("KF DS and ToA", "ToA +100 m", k0, 0.0, 100.0),
        ("KF DS and ToA", "ToA +100 m, calibration", 1, 0.0, 100.0),
        ("EKF DS and KF ToA", "Doppler +2 kHz", k0, 2000.0, 0.0),
        ("EKF DS and KF ToA", "ToA +100 m", k0, 0.0, 100.0),
        ("EKF DS and KF ToA", "ToA +100 m, calibration", 1, 0.0, 100.0),
    ]
    rows = []
    for name, what, k, d_hz, d_m in cases:
        res = []
        for seed in seeds:
            rng = np.random.default_rng(seed)
            meas = dv.measure(drive, rng)
            fix = dv.gnss_fix(drive, rng)
            dop, toa = meas.doppler.copy(), meas.toa.copy()
            dop[k] += d_hz
            toa[k] += d_m / C
            bad = dataclasses.replace(meas, doppler=dop, toa=toa)
            dop, toa = meas.doppler.copy(), meas.toa.copy()
            (dop if d_hz else toa)[k] = np.nan
            drop = dataclasses.replace(meas, doppler=dop, toa=toa)
            clean, hit, dropped = (
                _quiet(fam[name](setup, fix).run, m).position for m in (meas, bad, drop)
            )
            dev = np.linalg.norm(hit - clean, axis=1)
            peak, n = recovery(dev, k, TOL["halili2022"])
            ref = float(np.linalg.norm(dropped - clean, axis=1)[k:].max())
            med = (
                float(np.median(np.linalg.norm(clean - drive.position, axis=1))),
                float(np.median(np.linalg.norm(hit - drive.position, axis=1))),
            )
            res.append((peak, n, float(dev[-1]), med, ref))
        rows.append(_summary("halili2022", name, what, k, res))
    return rows


def jiang_rows(seeds, particles: int) -> list[dict]:
    exp = vs.experiment("jiang2023-straight", level=2)
    n = exp.model.n_stations
    k0 = exp.truth.shape[0] // 2
    rows = []
    for name in registry.family("jiang2023"):
        for what, col, delta in (("range +100 m", 0, 100.0), ("bearing +90 deg", n, np.pi / 2)):
            res = []
            for seed in seeds:
                Z, x0 = exp.simulate(1, np.random.default_rng(seed))
                bad = Z.copy()
                bad[0, k0, col] += delta
                drop = Z.copy()
                drop[0, k0] = np.nan
                opts = {"n_particles": particles} if name == "UPF" else {}
                est = [
                    _quiet(
                        vs.run_estimator,
                        name,
                        exp.model,
                        z,
                        x0,
                        exp.P0,
                        rng=np.random.default_rng(1000 + seed),
                        **opts,
                    )[0, :, :2]
                    for z in (Z, bad, drop)
                ]
                dev = np.linalg.norm(est[1] - est[0], axis=1)
                peak, nrec = recovery(dev, k0, TOL["jiang2023"])
                ref = float(np.linalg.norm(est[2] - est[0], axis=1)[k0:].max())
                res.append((peak, nrec, float(dev[-1]), None, ref))
            rows.append(_summary("jiang2023", name, what, k0, res))
    return rows


def _summary(family, name, what, k, res) -> dict:
    peaks = [r[0] for r in res]
    recs = [np.inf if r[1] is None else r[1] for r in res]
    rec = float(np.median(recs))
    row = {
        "family": family,
        "tracker": name,
        "outlier": what,
        "epoch": k,
        "peak_dev_m": float(np.median(peaks)),
        "epochs_to_recover": "never" if np.isinf(rec) else round(rec),
        "final_dev_m": float(np.median([r[2] for r in res])),
        "dropped_peak_dev_m": float(np.median([r[4] for r in res])),
    }
    if res[0][3] is not None:
        row["median_err_m"] = (
            float(np.median([r[3][0] for r in res])),
            float(np.median([r[3][1] for r in res])),
        )
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=5, help="noise draws (median over them)")
    ap.add_argument("--particles", type=int, default=200, help="UPF particles")
    args = ap.parse_args(argv)
    seeds = range(args.seeds)
    rows = halili_rows(seeds) + jiang_rows(seeds, args.particles)
    print(
        f"recovered = deviation from the clean run below {TOL['halili2022']} m (Halili) / "
        f"{TOL['jiang2023']} m (Jiang) for the rest of the drive"
    )
    print(f"medians over {args.seeds} seeds; UPF with {args.particles} particles\n")
    head = f"{'tracker':20s} {'outlier':26s} {'epoch':>5s} {'peak dev':>10s} {'recover':>8s} {'final dev':>10s} {'dropped':>10s}  median err (clean / hit)"
    print(head)
    for r in rows:
        med = r.get("median_err_m")
        extra = f"  {med[0]:.2f} / {med[1]:.2f} m" if med and "calibration" in r["outlier"] else ""
        print(
            f"{r['tracker']:20s} {r['outlier']:26s} {r['epoch']:5d} {r['peak_dev_m']:8.3f} m "
            f"{r['epochs_to_recover']!s:>8s} {r['final_dev_m']:8.3f} m {r['dropped_peak_dev_m']:8.3f} m{extra}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
