"""One epoch's extraction on the ray-traced channel: eq. 1's ML route against the direct fit.

The cost per epoch of what each tracker of ``benchmarks/bench_rt_direct.py`` reads
(:mod:`tunnelkit.design.traceddirect`): the traced tables' line-of-sight column (eq. 1's ML
route with the number of first-order paths and the route's diffuse floor, the baseline) and the
direct fit (:func:`tunnelkit.extraction.direct.fit.direct_fix`, with its speed) with the second-order
atoms on every element or each on the elements that see it (and then with at most one diffuse
atom, the dense multipath's), from a prediction 5 cm off. One
snapshot of epochs 4 and 20 of ``italiano2026-straight`` (the paper's 10 x 10, 410 tones, 12
symbols) on one BLAS thread; the traces come from the ray tracer's cache (traced on the first
run, a few seconds per epoch). Left out when the ``rt`` extra is not installed.

The design's traced tracker ``direct`` (``tunnelkit design --traced-tracker direct``) per epoch
on the design's traced route (its 4 x 4 and 8 x 8): the first two epochs of its drive as a
design sweep runs it (:func:`~tunnelkit.design.traceddirect.direct_drive` with ``DESIGN_OPTIONS``
from an entry fix drawn as the design draws it, 1 m and 5 cm in height: the prediction's fit,
the second start's from eq. 1's line of sight where the prediction is off, a diffuse atom where
the tied fit misfits; the snapshots' draws and the tracker's updates included) against eq. 1's
line of sight of two epochs (what the ``los`` tracker reads, its draws included), the baseline.
"""

from __future__ import annotations

import sys
import warnings
from functools import partial
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_rt_direct import _setup
from run import Case

from tunnelkit import rt
from tunnelkit.design import START_HEIGHT_SIGMA_M, START_SIGMA_M
from tunnelkit.design.directsurvey import design_table
from tunnelkit.design.traceddirect import DESIGN_OPTIONS, direct_drive, eq1_los
from tunnelkit.extraction.direct.fit import direct_fix
from tunnelkit.simulation.drives import scenario_route
from tunnelkit.tracking.javelin import draw_start
from tunnelkit.tracking.javelin.motion import ue_velocity

EPOCHS = (4, 20)
#: the design's traced route's arrays timed
DESIGN_ARRAYS = ("4x4", "8x8")


def _eq1(route, k, arr, n_paths, snap):
    with threadpool_limits(1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return eq1_los(route, k, arr, n_paths, snap)


def _direct(route, arr, snap, prediction, velocity, by_element, diffuse=0):
    with threadpool_limits(1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return direct_fix(route, arr, snap.H, prediction, velocity, element_second_order=by_element,
                          diffuse=diffuse, noise_power=snap.noise_power if diffuse else None)  # fmt: skip


def cases() -> list[Case]:
    if not rt.sionna_available():
        return []
    route = scenario_route("italiano2026-straight", "exact", "sionna", {"diffuse_floor": True})
    traj, rng = route.trajectory, np.random.default_rng(20261206)
    out = []
    for k in EPOCHS:
        arr, paths, snap = route.draw(k, rng)
        vel = traj.velocity[k]
        v = ue_velocity(float(np.hypot(*vel[:2])), float(np.arctan2(vel[1], vel[0])))
        p0 = traj.position[k] + np.array([0.05, 0.0, 0.0])
        r = float(np.linalg.norm(traj.position[k] - arr.origin))
        g = f"traced_epoch_{k}"
        eq1 = partial(_eq1, route, k, arr, len(paths), snap)
        direct = partial(_direct, route, arr, snap, p0, v)
        out += [
            Case(
                f"eq. 1 ML route, line of sight, epoch {k} ({r:.0f} m)",
                eq1,
                group=g,
                baseline=True,
                repeat=5,
            ),
            Case(f"direct fit + speed, epoch {k}", partial(direct, False), group=g, repeat=5),
            Case(
                f"direct fit + speed, second order per element, epoch {k}",
                partial(direct, True),
                group=g,
                repeat=5,
            ),
            Case(
                f"direct fit + speed, second order per element, one diffuse atom, epoch {k}",
                partial(direct, True, 1),
                group=g,
                repeat=5,
            ),
        ]
    return out + design_cases()


class _DesignDrive:
    """The first two epochs of the design's direct drive on ``array``'s traced route (its
    tracker ``bench_rt_direct._setup``'s, the design's), and eq. 1's line of sight of two
    snapshots of those epochs; each call draws from the same generators."""

    def __init__(self, array):
        self.route, _, self.design = _setup("italiano2026-straight", array)
        self.table = design_table("italiano2026-straight", array)  # the design's told table

    def direct(self):
        rng, g = np.random.default_rng(20261207).spawn(2)  # as the design's sweep
        p0 = draw_start(self.route.trajectory.position[0], START_SIGMA_M, g, START_HEIGHT_SIGMA_M)
        with threadpool_limits(1), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return direct_drive(self.route, rng, self.design, None, self.table, n_epochs=2,
                                start_sigma=START_SIGMA_M, start_height_sigma=START_HEIGHT_SIGMA_M,
                                start=p0, **DESIGN_OPTIONS)  # fmt: skip

    def eq1(self):
        rng = np.random.default_rng(20261207).spawn(2)[0]
        out = []
        for k in range(2):
            arr, paths, snap = self.route.draw(k, rng)
            out.append(_eq1(self.route, k, arr, len(paths), snap))
        return out


def design_cases() -> list[Case]:
    out = []
    for array in DESIGN_ARRAYS:
        d, g = _DesignDrive(array), f"design_direct_{array}"
        out += [
            Case(
                f"eq. 1 line of sight, 2 epochs, design route {array}",
                d.eq1,
                group=g,
                baseline=True,
                repeat=3,
            ),
            Case(f"design's direct drive, 2 epochs, {array}", d.direct, group=g, repeat=3),
        ]
    return out
