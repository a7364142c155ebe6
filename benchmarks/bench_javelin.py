"""Notebook 04: one JAVELIN step (association, management, Joseph update; extraction excluded)
and one whole epoch of the signal route (channel synthesis + CPD extraction + the step), with
the paper's extraction, with coherent paths separated (``tunnelkit.extraction.coherent``) and on
the maximum-likelihood route (``extract_paths(refine="ml")``)."""

from __future__ import annotations

import itertools
import sys
import warnings
from pathlib import Path

import numpy as np
from run import Case

from tunnelkit import simulation as ex
from tunnelkit.tracking.javelin import Javelin, JavelinWarning, PathMeasurements, designs

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from javelin_geometric import geometric_stream, toy_drive, toy_reflectors


def cases() -> list[Case]:
    bs = (0.0, 0.0, 4.8)
    n = 2000
    P, V = toy_drive(n, 0.1, amplitude=1.0, speed=2.0)
    rng = np.random.default_rng(0)
    eps = geometric_stream(
        P,
        V,
        toy_reflectors(),
        rng,
        bs=bs,
        sigma_phi=0.02,
        sigma_psi=0.02,
        sigma_kappa=1.0,
        sigma_d=0.3,
        sigma_v=0.05,
    )
    spd, hdg = np.linalg.norm(V[:, :2], axis=1), np.arctan2(V[:, 1], V[:, 0])
    trackers = {}
    for name, cfg in (("paper", designs.paper()), ("ours", designs.ours())):
        trk = Javelin(P[0], cfg.with_(base_station=bs, sigma_p0_ue=1.0))
        trackers[name] = (trk, itertools.cycle(range(1, n)))

    def step(name):
        trk, it = trackers[name]
        k = next(it)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", JavelinWarning)
            trk.step(eps[k], spd[k - 1], hdg[k - 1], 0.1)

    route = ex.scenario_route("italiano2026-straight", "exact")
    sig_rng = np.random.default_rng(1)
    trk_sig = Javelin(
        route.trajectory.position[0],
        designs.ours().with_(base_station=(0.0, 0.0, 4.8), sigma_p0_ue=1.0),
    )
    ks = itertools.cycle(range(1, 20))

    def signal_epoch(separated: bool = False, refine: str = "joint"):
        k = next(ks)
        ep = route.epoch(k, sig_rng, refine=refine)
        if separated:
            ep = ex.separate_epoch(ep, route.config)
        m = ep.measurements
        paths = PathMeasurements.from_arrays(m.phi, m.psi, m.kappa, m.d, m.v, warn=False)
        v = route.trajectory.velocity[k]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", JavelinWarning)
            trk_sig.step(paths, float(np.linalg.norm(v[:2])), float(np.arctan2(v[1], v[0])), 0.1)

    return [
        Case(
            "javelin step, paper design (5 paths)",
            lambda: step("paper"),
            group="javelin",
            baseline=True,
            repeat=15,
            number=50,
            goal_s=5e-3,
        ),
        Case(
            "javelin step, our design (5 paths)",
            lambda: step("ours"),
            group="javelin",
            repeat=15,
            number=50,
        ),
        Case(
            "signal-route epoch: synth + CPD + step",
            signal_epoch,
            group="javelin",
            repeat=7,
            number=1,
            goal_s=0.5,
        ),
        Case(
            "signal-route epoch: synth + CPD + separation + step",
            lambda: signal_epoch(separated=True),
            group="javelin",
            repeat=7,
            number=1,
            goal_s=0.5,
        ),
        Case(
            "signal-route epoch: synth + ML extraction + step",
            lambda: signal_epoch(refine="ml"),
            group="javelin",
            repeat=7,
            number=1,
        ),
    ]
