"""Studies on simulated drives: the road-marking/design ablation, what the extraction found per
kind of path, the errors it hands the tracker, and how well a VUE motion model predicts.
"""

from __future__ import annotations

import numpy as np
from tqdm.auto import tqdm

from .._validate import boolean, instance, sequence
from ..tracking.javelin import designs
from ..tracking.javelin.measured import CORRELATED
from ..tracking.javelin.motion import motion_increment
from ..tracking.javelin.roles import JavelinDesign
from ..tracking.javelin.state import JavelinState
from .drives import DriveData
from .scoring import evaluate

__all__ = [
    "ERROR_QUANTITIES",
    "ablation",
    "ablation_path",
    "error_correlations",
    "error_samples",
    "extraction_errors",
    "path_errors",
    "vue_prediction_errors",
]


def ablation_path() -> dict[str, JavelinDesign]:
    """The path from the paper's design to :func:`~tunnelkit.tracking.javelin.designs.ours`, one
    change at a time (each row keeps the changes of the rows above it)."""
    target = designs.ours()
    cfg = target.config
    d = designs.paper()
    out = {"paper (section 4.2)": d}
    d = d.with_prefilter(target.prefilters[1])
    out["+ Doppler clutter rejection"] = d
    d = d.with_(sigma_phi=cfg.sigma_phi, sigma_psi=cfg.sigma_psi, sigma_kappa=cfg.sigma_kappa)
    out["+ noise calibrated on the extraction"] = d
    d = d.with_(associator=target.associator)
    out["+ global nearest neighbour"] = d
    d = d.with_(vue_motion=target.vue_motion)
    out["+ mirrored VUE motion"] = d
    d = d.with_(initiator=target.initiator)
    out["+ no update at birth"] = d
    d = d.with_(motion_step=cfg.motion_step)
    out["+ step on the midpoint of two messages (= ours)"] = d
    return out


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
    variants = ablation_path() if variants is None else variants
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


def _matched_errors(drive: DriveData, k: int):
    """Epoch ``k``'s measurements matched to a true path: ``(kind, key, dphi [deg], dpsi [deg],
    dkappa [m], Delta d error [m] or None for the epoch's reference)`` per measurement (the
    quantities of :func:`extraction_errors`); ``key`` names the true path across epochs (the LoS,
    or the plane a reflection's wave source mirrors the UE in: its normal and offset, rounded)."""
    m = drive.epochs[k]
    if m is None or not len(m):
        return []
    tidx = np.asarray(drive.truth_index[k])
    hit = np.flatnonzero(tidx >= 0)
    if not hit.size:
        return []
    src = drive.sources[k][tidx[hit]]
    q = src - drive.base_station
    rng_true = np.linalg.norm(q, axis=1)
    phi_t = np.arctan2(q[:, 1], q[:, 0])
    psi_t = np.arctan2(q[:, 2], np.hypot(q[:, 0], q[:, 1]))
    dphi = np.degrees(np.angle(np.exp(1j * (m.phi[hit] - phi_t))))
    dpsi = np.degrees(m.psi[hit] - psi_t)
    dkap = m.kappa[hit] - rng_true
    e_d = m.d[hit] - rng_true  # common clock bias per epoch
    ref = int(np.argmin(m.d[hit]))
    ddd = e_d - e_d[ref]
    out = []
    for i, j in enumerate(hit):
        kind = drive.kinds[k][tidx[j]]
        w = src[i] - drive.truth[k]
        nw = float(np.linalg.norm(w))
        if nw < 1e-6:
            key = (kind,)
        else:  # the mirror plane: normal along w, through the midpoint
            n = w / nw
            key = (
                kind,
                *np.round(n, 2).tolist(),
                round(float(n @ (src[i] + drive.truth[k])) / 2, 1),
            )
        out.append((kind, key, dphi[i], dpsi[i], dkap[i], None if i == ref else ddd[i]))
    return out


def error_samples(drives: list[DriveData]) -> dict[str, dict[str, np.ndarray | int]]:
    """Every error of what the tracker is fed, per kind of path, over ``drives``: the samples
    :func:`extraction_errors` summarises. For every measurement matched to a true path: azimuth
    and elevation against the true arrival direction (world frame) [deg], curvature against the
    distance of the true wave source (the UE for the LoS, the VUE for a reflection: the radius of
    the exact wavefront) [m], and the TDoA ``Delta d`` of eq. 52 against the true one [m] (each
    epoch's earliest matched path is the reference, so the clock bias cancels; the reference
    itself has none). Returns ``{kind: {"phi", "psi", "kappa", "delta_d": 1-D arrays, "far":
    matched paths without curvature}}``, kinds in the order first met."""
    drives = sequence("drives", drives)
    acc: dict[str, dict[str, list]] = {}
    for drive in drives:
        instance("drives[i]", drive, DriveData)
        for k in range(len(drive.epochs)):
            for kind, _, dphi, dpsi, dkap, ddd in _matched_errors(drive, k):
                a = acc.setdefault(kind, {"phi": [], "psi": [], "kappa": [], "dd": [], "far": 0})
                a["phi"].append(dphi)
                a["psi"].append(dpsi)
                if np.isfinite(dkap):
                    a["kappa"].append(dkap)
                else:
                    a["far"] += 1
                if ddd is not None:
                    a["dd"].append(ddd)
    if not acc:
        raise ValueError("drives: no measurement matched to a true path")
    return {
        kind: {
            "phi": np.asarray(a["phi"], float),
            "psi": np.asarray(a["psi"], float),
            "kappa": np.asarray(a["kappa"], float),
            "delta_d": np.asarray(a["dd"], float),
            "far": a["far"],
        }
        for kind, a in acc.items()
    }


def extraction_errors(drives: list[DriveData]) -> tuple[list[str], list[list]]:
    """RMS error of what the tracker is fed, per kind of path, over ``drives`` (the samples of
    :func:`error_samples`). Rows per kind and a last row ``"all"`` pooling every path; columns:
    kind, matched measurements, RMS of phi, psi, kappa, Delta d, and how many matched paths had
    no curvature.
    """
    samples = error_samples(drives)

    def rms(x):
        return float(np.sqrt(np.mean(x**2))) if x.size else None

    quantities = ERROR_QUANTITIES
    rows = []
    for kind, a in samples.items():
        rows.append([kind, len(a["phi"]), *(rms(a[q]) for q in quantities), a["far"]])
    pooled = {q: np.concatenate([a[q] for a in samples.values()]) for q in quantities}
    far = sum(a["far"] for a in samples.values())
    rows.append(["all", len(pooled["phi"]), *(rms(pooled[q]) for q in quantities), far])
    cols = ["path", "matched", "phi [deg]", "psi [deg]", "kappa [m]", "Delta d [m]", "no kappa"]
    return cols, rows


#: the quantities of :func:`error_correlations` (the columns of :func:`extraction_errors`; the
#: names ``design_from_errors(correlation=)`` reads)
ERROR_QUANTITIES = CORRELATED


def error_correlations(drives: list[DriveData]) -> dict[str, dict[str, float]]:
    """How much of what the tracker is fed repeats from one epoch to the next: for each quantity
    of :func:`extraction_errors` (``phi``, ``psi``, ``kappa``, ``delta_d``), the lag-1
    correlation ``r = sum e_k e_{k+1} / sqrt(sum e_k^2 sum e_{k+1}^2)`` of the errors of the same
    true path (the LoS, or the reflection off one plane) at consecutive epochs, pooled over
    ``drives``. Uncentred, so an error that persists along the drive (a bias) counts as repeating.
    Returns ``{quantity: {"r": r, "pairs": n}}`` (``r`` NaN without pairs). An AR(1) error with
    this ``r`` averages over epochs as white noise of ``(1 + r) / (1 - r)`` times its variance
    (the long-run variance), which is what a tracker that takes the errors as white should be
    told (:func:`~tunnelkit.tracking.javelin.measured.design_from_errors` ``correlation=``)."""
    drives = sequence("drives", drives)
    sums = {q: np.zeros(4) for q in ERROR_QUANTITIES}  # sum xy, sum xx, sum yy, pairs
    for drive in drives:
        instance("drives[i]", drive, DriveData)
        prev = None
        for k in range(len(drive.epochs)):
            cur = {e[1]: e[2:] for e in _matched_errors(drive, k)}
            if prev:
                for key in cur.keys() & prev.keys():
                    for q, a, b in zip(ERROR_QUANTITIES, prev[key], cur[key], strict=True):
                        if a is not None and b is not None and np.isfinite(a) and np.isfinite(b):
                            sums[q] += (a * b, a * a, b * b, 1.0)
            prev = cur
    out = {}
    for q, (xy, xx, yy, n) in sums.items():
        r = float(xy / np.sqrt(xx * yy)) if xx > 0 and yy > 0 else float("nan")
        out[q] = {"r": r, "pairs": int(n)}
    return out


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
