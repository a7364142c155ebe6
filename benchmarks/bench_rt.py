"""Ray tracing: time per epoch of the image method and of Sionna RT for the paper's 10 x 10 array.

One epoch = all LoS + single-bounce paths from the vehicle (epoch 9 of italiano2026-straight) to
the 100 antennas of the array it faces, as ``Path`` objects. The Sionna scene is exported, loaded
and JIT-compiled during the warm-up call, so the medians are steady-state per-epoch times. Sionna
cases are left out when the ``rt`` extra is not installed.
"""

from __future__ import annotations

from run import Case

import tunnelkit as tk
from tunnelkit import propagation, rt


def cases() -> list[Case]:
    sc = tk.load_scenario("italiano2026-straight")
    tun, fc = sc.tunnel(), sc.get("radio.fc")
    traj = sc.trajectory(tun)
    ue, vel = traj.position[9], traj.velocity[9]
    arrays = [rt.lower_into_tunnel(tun, a)[0] for a in propagation.scenario_arrays(sc)]
    arr = propagation.select_array(arrays, ue)
    out = [
        Case(
            "image method, 10x10 array, one epoch",
            lambda: rt.compute_paths(tun, arr, ue, vel, fc=fc, engine="image"),
            group="rt_epoch",
            baseline=True,
            repeat=30,
        )
    ]
    if not rt.sionna_available():
        return out
    for n in (100_000, 10_000):
        out.append(
            Case(
                f"Sionna RT, 10x10 array, {n:.0e} rays, one epoch",
                lambda n=n: rt.compute_paths(
                    tun, arr, ue, vel, fc=fc, engine="sionna", samples_per_src=n
                ),
                group="rt_epoch",
                repeat=5,
            )
        )
    return out
