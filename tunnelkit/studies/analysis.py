"""Studies on simulated drives: the road-marking/design ablation, what the extraction found per
kind of path, the errors it hands the tracker, and how well a VUE motion model predicts.
"""

from __future__ import annotations

import numpy as np
from tqdm.auto import tqdm

from .._validate import boolean, instance, sequence
from ..tracking.javelin import designs
from ..tracking.javelin.motion import motion_increment
from ..tracking.javelin.roles import JavelinDesign
from ..tracking.javelin.state import JavelinState
from .drives import DriveData
from .scoring import evaluate

__all__ = ["ablation", "extraction_errors", "path_errors", "vue_prediction_errors"]


def ablation(
    drives: dict[str, list[DriveData]],
    variants: dict[str, JavelinDesign] | None = None,
    separated: dict[str, list[DriveData]] | None = None,
    ml: dict[str, list[DriveData]] | None = None,
    progress: bool = False,
) -> tuple[list[str], list[list]]:
    """Mean 2-D RMSE per variant (rows) and condition (columns) over the given drives.

    With ``separated`` (the same drives through the coherent route) two more rows: the
    last variant on those (the measurement route as one more step), then
    :func:`~tunnelkit.tracking.javelin.designs.ours_coherent` (our design on that route). With
    ``ml`` (the same drives through the ML route) three more: the paper's design on it,
    :func:`~tunnelkit.tracking.javelin.designs.paper_vue`, then
    :func:`~tunnelkit.tracking.javelin.designs.ours_ml`.
    ``progress``: a tqdm bar over the (variant, drive) evaluations; nothing here is random.
    """
    instance("drives", drives, dict, "drives per condition (a dict)")
    for name, value in (("variants", variants), ("separated", separated), ("ml", ml)):
        if value is not None:
            instance(name, value, dict, "a dict")
    boolean("progress", progress)
    variants = designs.ablation_path() if variants is None else variants
    conds = list(drives)
    steps = [(name, cfg, drives) for name, cfg in variants.items()]
    if separated is not None:
        steps.append(("+ coherent paths separated", list(variants.values())[-1], separated))
        steps.append(
            ("+ curvature centred on the VUE (= ours)", designs.ours_coherent(), separated)
        )
    if ml is not None:
        steps.append(("paper design, ML route", designs.paper(), ml))
        steps.append(("paper design + VUE curvature, ML route", designs.paper_vue(), ml))
        steps.append(("our design, ML route", designs.ours_ml(), ml))
    total = sum(len(by_cond[c]) for _, _, by_cond in steps for c in conds)
    bar = tqdm(total=total, desc="ablation: drives", leave=False, disable=not progress)
    rows = []
    for name, cfg, by_cond in steps:
        row: list = [name]
        for c in conds:
            rmse = []
            for d in by_cond[c]:
                rmse.append(evaluate(d, cfg).metrics["rmse_2d_m"])
                bar.update()
            row.append(float(np.mean(rmse)))
        rows.append(row)
    bar.close()
    return ["design", *conds], rows


def path_errors(drives: list[DriveData]) -> tuple[list[str], list[list]]:
    """How well the measurement route found each kind of path, over ``drives``.

    Rows per surface kind (``los``, ``ceiling``, ``road``, ``rrm``...): true paths, paths found
    (matched to an estimate), RMS and median angle error between the measured and the true
    arrival direction [deg]; a last row counts the estimates matched to no true path.
    """
    drives = sequence("drives", drives)
    err: dict[str, list[float]] = {}
    n_true: dict[str, int] = {}
    spurious = 0
    for drive in drives:
        for k, m in enumerate(drive.epochs):
            kinds = drive.kinds[k] if k < len(drive.kinds) else []
            for kind in kinds:
                n_true[kind] = n_true.get(kind, 0) + 1
            if m is None:
                continue
            for j, t in enumerate(drive.truth_index[k]):
                if t < 0:
                    spurious += 1
                    continue
                q = drive.sources[k][t] - drive.base_station
                u = np.array(
                    [
                        np.cos(m.psi[j]) * np.cos(m.phi[j]),
                        np.cos(m.psi[j]) * np.sin(m.phi[j]),
                        np.sin(m.psi[j]),
                    ]
                )
                cos = float(np.clip(u @ q / np.linalg.norm(q), -1.0, 1.0))
                err.setdefault(kinds[t], []).append(float(np.degrees(np.arccos(cos))))
    rows: list[list] = []
    for kind, n in n_true.items():
        e = np.asarray(err.get(kind, []))
        rms = float(np.sqrt(np.mean(e**2))) if e.size else None
        rows.append([kind, n, int(e.size), rms, float(np.median(e)) if e.size else None])
    rows.append(["no true path", None, spurious, None, None])
    return ["path", "true", "found", "rms angle error [deg]", "median [deg]"], rows


def extraction_errors(drives: list[DriveData]) -> tuple[list[str], list[list]]:
    """RMS error of what the tracker is fed, per kind of path, over ``drives``.

    For every measurement matched to a true path: azimuth and elevation against the true
    arrival direction (world frame) [deg], curvature against the distance of the true wave
    source (the UE for the LoS, the VUE for a reflection: the radius of the exact wavefront)
    [m], and the TDoA ``Delta d`` of eq. 52 against the true one [m] (each epoch's earliest
    matched path is the reference, so the clock bias cancels; the reference itself has none).
    Rows per kind and a last row ``"all"`` pooling every path; columns: kind, matched
    measurements, RMS of phi, psi, kappa, Delta d, and how many matched paths had no curvature.
    """
    drives = sequence("drives", drives)
    acc: dict[str, dict[str, list]] = {}
    for drive in drives:
        for k, m in enumerate(drive.epochs):
            if m is None or not len(m):
                continue
            tidx = np.asarray(drive.truth_index[k])
            hit = np.flatnonzero(tidx >= 0)
            if not hit.size:
                continue
            q = drive.sources[k][tidx[hit]] - drive.base_station
            rng_true = np.linalg.norm(q, axis=1)
            phi_t = np.arctan2(q[:, 1], q[:, 0])
            psi_t = np.arctan2(q[:, 2], np.hypot(q[:, 0], q[:, 1]))
            dphi = np.degrees(np.angle(np.exp(1j * (m.phi[hit] - phi_t))))
            dpsi = np.degrees(m.psi[hit] - psi_t)
            dkap = m.kappa[hit] - rng_true
            e_d = m.d[hit] - rng_true  # common clock bias per epoch
            ref = int(np.argmin(m.d[hit]))
            ddd = e_d - e_d[ref]
            for i, j in enumerate(hit):
                kind = drive.kinds[k][tidx[j]]
                a = acc.setdefault(kind, {"phi": [], "psi": [], "kappa": [], "dd": [], "far": 0})
                a["phi"].append(dphi[i])
                a["psi"].append(dpsi[i])
                if np.isfinite(dkap[i]):
                    a["kappa"].append(dkap[i])
                else:
                    a["far"] += 1
                if i != ref:
                    a["dd"].append(ddd[i])
    if not acc:
        raise ValueError("drives: no measurement matched to a true path")

    def rms(x):
        x = np.asarray(x, float)
        return float(np.sqrt(np.mean(x**2))) if x.size else None

    rows = []
    pooled = {"phi": [], "psi": [], "kappa": [], "dd": [], "far": 0}
    for kind, a in acc.items():
        rows.append(
            [kind, len(a["phi"]), *(rms(a[q]) for q in ("phi", "psi", "kappa", "dd")), a["far"]]
        )
        for q in ("phi", "psi", "kappa", "dd"):
            pooled[q] += a[q]
        pooled["far"] += a["far"]
    rows.append(
        [
            "all",
            len(pooled["phi"]),
            *(rms(pooled[q]) for q in ("phi", "psi", "kappa", "dd")),
            pooled["far"],
        ]
    )
    cols = ["path", "matched", "phi [deg]", "psi [deg]", "kappa [m]", "Delta d [m]", "no kappa"]
    return cols, rows


def vue_prediction_errors(drive: DriveData, vue_motion: str) -> np.ndarray:
    """One-epoch prediction error of the *true* VUEs [m], per VUE and epoch (flattened).

    From the true UE and VUEs of epoch ``k`` and the true velocity, predict epoch ``k + 1`` with
    ``vue_motion`` ("random_walk": stay; "mirror": mirrored UE displacement) and compare each
    prediction with the nearest true VUE of epoch ``k + 1`` in (y, z).
    """
    instance("drive", drive, DriveData)
    out = []
    for k in range(len(drive.sources) - 1):
        a, b = drive.sources[k], drive.sources[k + 1]
        if len(a) < 2 or len(b) < 1 + int(drive.los[k + 1]) or not drive.los[k]:
            continue
        n = len(a) - 1
        st = JavelinState(
            np.concatenate([a[0], a[1:, 1:].ravel()]),
            np.eye(3 + 2 * n),
            ids=list(range(1, n + 1)),
            misses=[0] * n,
            transient=[False] * n,
        )
        v = drive.velocity[k]
        inc, _ = motion_increment(
            st, float(np.linalg.norm(v[:2])), float(np.arctan2(v[1], v[0])), drive.dt, vue_motion
        )
        pred = (st.x[3:] + inc[3:]).reshape(-1, 2)
        # the LoS (first source when present) is not a VUE; epoch k + 1 may have lost it
        vues_next = b[1:] if drive.los[k + 1] else b
        d = np.linalg.norm(pred[:, None, :] - vues_next[None, :, 1:], axis=-1)
        out.extend(d.min(axis=1))
    return np.asarray(out)
