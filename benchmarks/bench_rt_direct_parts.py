"""What the direct fit misses on the ray-traced channel, part by part.

Per epoch: the direct fit (:func:`tunnelkit.extraction.direct.fit.direct_fix`, second-order atoms on the
elements that see them, with its speed) from the true position and velocity on the noiseless
traced tensor (:meth:`tunnelkit.rt.RayTracedChannel.components`, transmit power included), then
on the same tensor with one part of :func:`tunnelkit.rt.tensor_components` removed at a time
(``--remove``, default ``diffuse``). Prints the part's share of the tensor's power and, per
tensor, the fit's residual share, its position error along and across the tunnel, the line of
sight's azimuth and elevation error seen from the site and the speed's error. With
``--diffuse D`` the full tensor is also fitted with at most ``D`` diffuse atoms, each admitted by
its test against the receiver's noise power (the tensor itself is noiseless, so every atom whose
drop clears what that noise would give stays).

    python benchmarks/bench_rt_direct_parts.py --scenario italiano2026-slalom --epochs 4 12 14 16 22 26
    python benchmarks/bench_rt_direct_parts.py --scenario italiano2026-straight --epochs 4 16 22
"""

from __future__ import annotations

import argparse
import shlex
import sys
import warnings
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.extraction.direct.fit import direct_fix
from tunnelkit.geometry import spherical
from tunnelkit.rt import COMPONENTS
from tunnelkit.simulation.drives import scenario_route


def _row(label, route, arr, H, k, diffuse=0) -> str:
    traj = route.trajectory
    ue, vel = traj.position[k], traj.velocity[k]
    f = direct_fix(route, arr, H, ue, vel, element_second_order=True, diffuse=diffuse,
                   noise_power=route.config.noise_power if diffuse else None)  # fmt: skip
    a0, e0, _ = spherical(ue - arr.origin)
    a1, e1, _ = spherical(f.position - arr.origin)
    dx, dy = f.position[:2] - ue[:2]
    return (f"   {label:18s} residual {100 * f.residual:5.2f} %  along {dx:+.3f} across {dy:+.3f} m"
            f"  azimuth {np.degrees(a1 - a0):+.3f} elevation {np.degrees(e1 - e0):+.3f} deg"
            f"  speed {f.speed - np.linalg.norm(vel[:2]):+.3f} m/s  ok {f.ok}  diffuse {f.diffuse}")  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-slalom")
    ap.add_argument("--epochs", type=int, nargs="+", default=[4, 16, 22])
    ap.add_argument("--remove", nargs="+", choices=COMPONENTS, default=["diffuse"])
    ap.add_argument(
        "--diffuse",
        type=int,
        default=0,
        help="also the full tensor fitted with at most this many diffuse atoms",
    )
    a = ap.parse_args(argv)
    print("command: python benchmarks/bench_rt_direct_parts.py " + shlex.join(argv or sys.argv[1:]))
    route = scenario_route(a.scenario, "exact", "sionna", {"diffuse_floor": True})
    amp = np.sqrt(route.config.tx_power)
    with threadpool_limits(1, "blas"), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fits' own tests flag traced epochs
        for k in a.epochs:
            arr, parts, _, _ = route.raytraced.components(k, amplitude=amp)
            full = parts["full"]
            p = float(np.sum(np.abs(full) ** 2))
            shares = ", ".join(
                f"{n} {100 * np.sum(np.abs(parts[n]) ** 2) / p:.1f} %" for n in a.remove
            )
            x, y = route.trajectory.position[k, :2]
            print(f"{a.scenario} epoch {k} (x {x:.1f}, y {y:.2f} m): power share {shares}")
            print(_row("full", route, arr, full, k), flush=True)
            if a.diffuse:
                print(
                    _row(f"full, diffuse <= {a.diffuse}", route, arr, full, k, a.diffuse),
                    flush=True,
                )
            for n in a.remove:
                print(_row(f"{n} removed", route, arr, full - parts[n], k), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
