"""JAVELIN's iterated EKF: updates relinearised at their own estimate (Bell & Cathey 1993).

:func:`first_fix` is the first fix of a design whose initiator acquires (ours,
:class:`~.surfaces.GeometricBirth`): every path tried as the LoS by :func:`fix`, the hypothesis
the known surfaces explain best kept; :func:`iterate` relinearises an epoch's update until it
settles (``JavelinConfig.update_iterations``). The tracker (:class:`~.tracker.Javelin`) calls them
with its state, its design and ``model(x, cfg)``, its per-track predictions and Jacobians
(:meth:`~.tracker.Javelin._model`); running the paper's one-step EKF does not load this module.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..gating import ChiSquareGate
from .measurement import PathMeasurements
from .state import JavelinState
from .update import stack_measurement

__all__ = ["ACQUIRE_ITERATIONS", "UPDATE_TOLERANCE"]

#: iterations of the first fix's iterated EKF at most (:func:`first_fix`)
ACQUIRE_ITERATIONS = 20

#: an epoch's iterated update stops when an iteration moves the UE by less than this share of
#: its posterior standard deviation (the smallest axis): the linearisation point is then
#: as good as the estimate can tell
UPDATE_TOLERANCE = 0.01


def fix(state: JavelinState, design, meas: PathMeasurements, j: int, cfg, model):
    """The UE's prior updated with path ``j``'s angles as its LoS by an iterated EKF
    (relinearised at its own estimate until it settles): ``(x, P, C)``. The curvature is
    left out: an extraction near its threshold reports it metres off with a sigma that
    does not say so, and the height prior and the angles place the UE on the ray. ``cfg``:
    the epoch's (:meth:`~.tracker.Javelin._epoch_config`)."""
    st, roles = state, design
    kap = meas.kappa.copy()
    kap[j] = np.nan
    meas = replace(meas, kappa=kap)
    x0, P0, C0 = st.x.copy(), st.P.copy(), None if st.C is None else st.C.copy()
    xi = x0.copy()
    for _ in range(ACQUIRE_ITERATIONS):
        pred, J = model(xi, cfg)
        m = stack_measurement(pred, J, meas, [(0, j)], cfg, j, roles.noise, C0)
        m.h = m.h + m.H @ (x0 - xi)  # linearised at xi, the prior at x0
        out = roles.updater.update(x0, P0, m, C0)
        step = np.linalg.norm(out[0] - xi)
        xi = out[0]
        if step < 1e-6:
            break
    return out[0], out[1], (out[3] if len(out) == 4 else st.C)


def iterate(
    state: JavelinState, design, out: tuple, meas: PathMeasurements, m, los_path, C0, cfg, model
) -> tuple:
    """The epoch's update relinearised at its own estimate until it settles (an iterated
    EKF: Gauss-Newton on the prior and the epoch's rows, Bell & Cathey 1993). ``out`` is
    the update linearised at the prior (``(x, P, nis[, C])``), ``m`` its stacked
    measurement; the same rows (``m.labels``: the pairs kept) are stacked again at each
    iterate, ``h`` shifted back to the prior (``h(x_i) + H_i (x_0 - x_i)``), and the prior's
    update repeated with them, so the covariance is the Joseph form with the last
    Jacobian. A one-step EKF is exact only while the correction stays within the range
    where ``h`` is linear: at the first epoch the fix is a metre off along its ray (the
    angles alone place it), and the curvature and delay rows then leave the update
    millimetres off while its covariance says tenths of a millimetre (italiano2026-straight,
    16 x 16, the first epoch: 3.4 mm RMS against a 0.35 mm bound); the inconsistent state
    then fails the joint innovation test with true pairs for many epochs. Stops after
    ``update_iterations`` (:class:`~.config.JavelinConfig`; the array design's) or when an
    iteration moves the UE by less than :data:`UPDATE_TOLERANCE` of its posterior
    standard deviation; the NIS stays the prior's (what the tests and the report use).
    ``cfg``: the epoch's (:meth:`~.tracker.Javelin._epoch_config`)."""
    st, roles = state, design
    pairs = list(dict.fromkeys((i, j) for _, i, j in m.labels))
    x0, P0 = st.x, st.P
    for _ in range(cfg.update_iterations):
        xi = out[0]
        sd = np.sqrt(max(float(np.linalg.eigvalsh(out[1][:3, :3])[0]), 0.0))
        pred, J = model(xi, cfg)
        mi = stack_measurement(pred, J, meas, pairs, cfg, los_path, roles.noise, C0)
        mi.h = mi.h + mi.H @ (x0 - xi)
        new = roles.updater.update(x0, P0, mi, C0)
        if not (np.all(np.isfinite(new[0])) and np.all(np.isfinite(new[1]))):
            break
        step = float(np.linalg.norm(new[0][:3] - xi[:3]))
        out = (new[0], new[1], out[2], *new[3:])
        if step <= UPDATE_TOLERANCE * sd:
            break
    return out


def first_fix(
    state: JavelinState, design, meas: PathMeasurements, faults: list[str], cfg, model
) -> int | None:
    """The first fix (ours; an initiator with ``acquire``, :class:`~.surfaces.GeometricBirth`):
    before anything is associated or born, every path is tried as the LoS (:func:`fix`) and
    the hypothesis kept that the known surfaces explain best: a UE inside the tunnel, the
    smallest ``(x - x_0)^T P_0^-1 (x - x_0)`` plus, per other path, the normalised angle
    innovation of the plane whose mirror image explains it (the gate's threshold when none
    does). An open-sky fix a metre off puts the UE's prior where a reflection's wavefront is
    as likely as the LoS's, the LoS and the ceiling path differ by millimetres in delay, and
    the micro-radian angles of a large array leave a one-step EKF far from the ray. Returns
    the path used (the epoch's update leaves it out, so it counts once), or ``None``.
    ``cfg``: the epoch's (:meth:`~.tracker.Javelin._epoch_config`)."""
    st, init = state, design.initiator
    if st.n_vue or not len(meas):
        return None
    x0, P0 = st.x.copy(), st.P.copy()
    gate = ChiSquareGate(init.probability).threshold(3)
    best = None
    for j in range(len(meas)):
        try:
            x, P, C = fix(state, design, meas, j, cfg, model)
        except (ValueError, np.linalg.LinAlgError):
            continue
        if not init.inside(x[:3], cfg.bs):
            continue
        dx = x - x0
        try:
            score = float(dx @ np.linalg.solve(P0, dx))
        except np.linalg.LinAlgError:  # a told odometry term of zero: its state is known
            score = float(dx @ np.linalg.pinv(P0) @ dx)
        trial = JavelinState(x, P, n_odo=st.n_odo)
        for k in range(len(meas)):
            if k != j:
                d2 = init.match_distance(trial, meas, k, cfg, design.noise, j)[1]
                score += min(d2, gate)
        if best is None or score < best[0]:
            best = (score, j, x, P, C)
    if best is None:
        faults.append("first fix failed (no path gives a UE inside the tunnel): open-sky fix kept")
        return None
    _, j, st.x, P, st.C = best
    st.P = 0.5 * (P + P.T)
    return j
