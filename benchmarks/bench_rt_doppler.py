"""The paths' Doppler on the ray-traced channel: what a radial-speed measurement would carry.

JAVELIN reads each path's radial speed ``v = c f_D / fc`` only in its clutter test; the V2X speed
message it steps on has 0.2 m/s of white noise (the paper's model). Here the ML route's radial
speed of every matched first-order path is compared with the static reflector's prediction at
the true position and velocity (:func:`tunnelkit.tracking.javelin.manage.static_doppler`), by
kind: on the drives ``benchmarks/bench_rt_javelin.py`` saved (the traced channel, route "ml-all")
and on two drives of eq. 1's channel simulated here. Per epoch of the traced drives, the median
error over the runs and its spread (MAD) tell a repeating bias (the misspecified model's) from
noise. Last, an along-track figure of what the line of sight's Doppler could add to dead
reckoning at most: each epoch's speed message fused with the line of sight's radial speed turned
into a speed along the *true* geometry (inverse-variance weights: the messages' 0.2 m/s and
``--doppler-sigma``), integrated with eq. 62's step; the RMS over the epochs of the along-track
error, beside the messages alone. The true geometry and the true line of sight make it an upper
figure, not a tracker.

    python benchmarks/bench_rt_doppler.py --dir build/rtj-los
"""

from __future__ import annotations

import argparse
import pickle
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.simulation import simulate_drive
from tunnelkit.tracking.javelin.manage import static_doppler

SIGMA_SPEED = 0.2  # the paper's white speed message [m/s]


def errors(drive) -> list[tuple[int, str, float]]:
    """``(epoch, kind, v - predicted)`` of every matched path of ``drive`` (a DriveData)."""
    out = []
    for k, e in enumerate(drive.epochs):
        if e is None:
            continue
        for j, s in enumerate(drive.truth_index[k][: len(e.v)]):
            if s >= 0:
                pred = static_doppler(
                    drive.truth[k], drive.sources[k][s], drive.velocity[k], drive.base_station
                )
                out.append((k, drive.kinds[k][s], float(e.v[j] - pred)))
    return out


def by_kind(rows) -> list[str]:
    kinds = sorted({r[1] for r in rows})
    lines = [
        "| kind | n | mean [m/s] | median abs | RMS | p90 abs |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for kd in kinds:
        x = np.array([r[2] for r in rows if r[1] == kd])
        lines.append(
            f"| {kd} | {x.size} | {x.mean():+.4f} | {np.median(abs(x)):.4f} | "
            f"{np.sqrt(np.mean(x**2)):.4f} | {np.percentile(abs(x), 90):.4f} |"
        )
    return lines


def along_track(drive, sigma_doppler: float) -> tuple[float, float]:
    """RMS along-track error [m] of the messages alone and fused with the LoS Doppler."""
    T = len(drive.t)
    v_true = np.linalg.norm(drive.velocity[:, :2], axis=1)
    speed = np.empty(T)
    for k in range(T):
        speed[k] = np.nan
        e = drive.epochs[k]
        if e is None:
            continue
        for j, s in enumerate(drive.truth_index[k][: len(e.v)]):
            if s >= 0 and drive.kinds[k][s] == "los":
                u = drive.truth[k] - drive.base_station
                cos_b = -np.dot(u / np.linalg.norm(u), drive.velocity[k]) / np.linalg.norm(
                    drive.velocity[k]
                )
                speed[k] = e.v[j] / cos_b
    w_m, w_d = 1 / SIGMA_SPEED**2, 1 / sigma_doppler**2
    fused = np.where(
        np.isfinite(speed),
        (w_m * drive.speed + w_d * np.nan_to_num(speed)) / (w_m + w_d),
        drive.speed,
    )

    def rms(s):
        err = np.concatenate([[0.0], np.cumsum((s[:-1] - v_true[:-1]) * drive.dt)])
        return float(np.sqrt(np.mean(err**2)))

    return rms(drive.speed), rms(fused)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", default="build/rtj-los", help="bench_rt_javelin.py's --dir")
    ap.add_argument("--tables", nargs="+", default=["1", "2"])
    ap.add_argument("--seeds", nargs="+", default=["0", "20261202"])
    ap.add_argument("--doppler-sigma", type=float, default=0.1)
    a = ap.parse_args()
    names = {"1": "italiano2026-straight", "2": "italiano2026-slalom"}
    for t in a.tables:
        image = simulate_drive(names[t], np.random.default_rng(5), condition="L", extraction="ml")
        print(f"\n## {names[t]}, eq. 1's channel (one drive, seed 5)\n")
        print("\n".join(by_kind(errors(image))))
        for s in a.seeds:
            files = sorted(Path(a.dir, f"table{t}-seed{s}").glob("drive*.pkl"))
            drives = [pickle.loads(f.read_bytes())["drives"]["ml-all"] for f in files]
            drives = [d for d in drives if d.condition.name == "L"]
            rows = [r for d in drives for r in errors(d)]
            print(f"\n## {names[t]}, ray-traced channel, seed {s}, {len(drives)} drives\n")
            print("\n".join(by_kind(rows)))
            los = {}
            for k, kd, x in rows:
                if kd == "los":
                    los.setdefault(k, []).append(x)
            med = np.array([np.median(v) for v in los.values()])
            mad = np.array([np.median(abs(np.array(v) - np.median(v))) for v in los.values()])
            print(
                f"\nline of sight per epoch ({len(los)} epochs): the runs' median error "
                f"RMS {np.sqrt(np.mean(med**2)):.4f} m/s (range {med.min():+.3f} to "
                f"{med.max():+.3f}), its spread over the runs (MAD) median {np.median(mad):.4f} "
                "m/s: the error repeats from run to run"
            )
            fig = np.array([along_track(d, a.doppler_sigma) for d in drives])
            print(
                f"along-track RMS, mean over drives: messages alone {fig[:, 0].mean():.4f} m, "
                f"fused with the LoS Doppler (told {a.doppler_sigma} m/s) {fig[:, 1].mean():.4f} m"
            )


if __name__ == "__main__":
    main()
