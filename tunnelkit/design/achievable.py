"""What an array achieves, not only what it could: impairments as design inputs
(:class:`DesignImpairments`), the per-path error model of the extraction along the route
(:func:`path_error_model`) and the predicted error of the position beside the ideal PEB
(:func:`predicted_error`: a first-order prediction from the misspecified model of
:mod:`tunnelkit.design.mcrb`, not a bound).

How it works, and how well the prediction matches the Monte-Carlo of the extraction (with the
measured biases of the spatial-wideband term): docs/internals/design.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checks import bound_array
from .._validate import choice, instance, record, text
from ..constants import C
from ..geometry import spherical_jacobian
from .bounds import compress_slots, route_bounds, route_geometry
from .errormodel import PathErrorModel
from .geometry import RouteGeometry
from .impairments import DesignImpairments
from .mcrb import EtaModes, scaled_inverse
from .setup import ArraySpec, DesignSetup, parse_array
from .trackerfix import fix_identifiable, position_error_parts, position_noise_cov, tracker_weights

__all__ = [
    "WEIGHTS",
    "DesignImpairments",
    "PredictedError",
    "path_error_model",
    "predicted_error",
    "unresolved_reason",
]

LN10_20 = np.log(10.0) / 20.0
#: epochs evaluated together (bounds the memory of the mode vectors)
_CHUNK_BYTES = 64e6


def _check(setup, impairments):
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    if not isinstance(impairments, DesignImpairments):
        raise TypeError(
            f"impairments: expected a design.DesignImpairments, got {type(impairments).__name__}"
        )


@dataclass(frozen=True)
class _Frame:
    """The used paths of a route, compressed to (T, L) (padding masked), in the bounds' terms."""

    g: RouteGeometry
    idx: np.ndarray
    mask: np.ndarray
    src: np.ndarray
    s_loc: np.ndarray
    d0: np.ndarray
    alpha: np.ndarray
    mu_f: np.ndarray
    mu_t: np.ndarray
    pos: np.ndarray


def _frame(setup, spec, g) -> _Frame:
    cfg = setup.config
    idx, mask = compress_slots(g.exists)
    take = lambda a: np.take_along_axis(a, idx[..., None] if a.ndim == 3 else idx, axis=1)  # noqa: E731
    src = take(g.source)
    s_loc = np.einsum("tlj,tjk->tlk", src - g.origin[:, None, :], g.rotation)
    d0 = np.linalg.norm(s_loc, axis=-1)
    return _Frame(
        g,
        idx,
        mask,
        src,
        s_loc,
        d0,
        np.sqrt(cfg.tx_power) * take(g.gain),
        -2 * np.pi * cfg.tone_spacing * d0 / C,
        2 * np.pi * cfg.symbol_period * take(g.doppler),
        spec.local(cfg.fc),
    )


def _chunks(setup, fr: _Frame, imp: DesignImpairments, frame: str = "cartesian"):
    """Per chunk of epochs: the slice, the FIM ``A``, the diffuse excess ``E`` (or None), the
    wideband score ``s`` (or None), the calibration scores per unit phase [rad] and gain
    [dB] (or None) and the wave-origin ``basis`` of ``frame``: all in eta space (module
    :mod:`~tunnelkit.design.mcrb`; ``frame="radial"``: each wave origin in its own azimuth,
    elevation and range directions, :func:`~tunnelkit.design.mcrb.radial_basis`)."""
    cfg = setup.config
    T, L = fr.idx.shape
    M = fr.pos.shape[0]
    per = 16 * L * (cfg.n_tones * 4 + M * 8 + cfg.n_symbols * 2) + 8 * (7 * L) ** 2 * 6
    size = max(1, int(_CHUNK_BYTES // per))
    s2 = cfg.noise_power
    for lo in range(0, T, size):
        sl = slice(lo, min(lo + size, T))
        mk = fr.mask[sl]
        md = EtaModes(
            fr.s_loc[sl],
            fr.pos,
            fr.alpha[sl],
            fr.mu_f[sl],
            fr.mu_t[sl],
            mk,
            cfg.fc,
            cfg.n_tones,
            cfg.n_symbols,
            frame=frame,
        )
        out = {"slice": sl, "A": md.fim(s2), "E": None, "s_wb": None, "S_ph": None, "S_g": None}
        out["basis"] = md.basis
        if imp.dmc_share > 0:
            spec = imp.dmc
            tau0 = np.where(mk, fr.d0[sl], np.inf).min(axis=1) / C
            tau0 = np.where(np.isfinite(tau0), tau0, 0.0)
            p_d = spec.power(1.0) * np.sum(np.abs(md.alpha) ** 2, axis=1)  # (T,)
            G = md.diffuse_gram(spec, cfg.tone_spacing, tau0).real
            out["E"] = 2.0 / s2**2 * p_d[:, None, None] * G
        if imp.spatial_wideband and not imp.wideband_model:
            from .wideband import wideband_score  # loaded when the term is in, not modelled

            out["s_wb"] = 2.0 / s2 * wideband_score(md, cfg.tone_spacing).real
        if imp.phase_error_deg > 0 or imp.gain_error_db > 0:
            S = md.calibration_scores()
            out["S_ph"] = 2.0 / s2 * (1j * S).real
            out["S_g"] = 2.0 / s2 * LN10_20 * S.real
        yield out


def _z_jacobian(fr: _Frame, g: RouteGeometry, cfg) -> np.ndarray:
    """``d z / d eta`` per path (T, L, 4, 7): ``z = [phi, psi, kappa, d]``."""
    T, L = fr.idx.shape
    rel = fr.src - g.origin[:, None, :]
    # padding slots: any point off the vertical axis (their rows are masked out later)
    rel = np.where(fr.mask[..., None], rel, np.array([1.0, 1.0, 0.0]))
    Js = spherical_jacobian(rel) @ g.rotation[:, None, :, :]  # d(phi, psi, r) / d s_loc
    Jz = np.zeros((T, L, 4, 7))
    Jz[:, :, :3, 4:] = Js
    Jz[:, :, 3, 2] = -C / (2 * np.pi * cfg.tone_spacing)
    return Jz


def _block_diag(Jz: np.ndarray) -> np.ndarray:
    """(T, L, 4, 7) -> (T, 4L, 7L) block diagonal."""
    T, L = Jz.shape[:2]
    out = np.zeros((T, L, 4, L, 7))
    out[:, np.arange(L), :, np.arange(L), :] = Jz.transpose(1, 0, 2, 3)
    return out.reshape(T, 4 * L, 7 * L)


def _vertical(fr: _Frame, g: RouteGeometry) -> np.ndarray:
    """(T, L) the used paths whose wave origin lies on the vertical through the reference
    antenna: their world azimuth (``z``'s ``phi``) is undefined."""
    rel = fr.src - g.origin[:, None, :]
    rho2 = rel[..., 0] ** 2 + rel[..., 1] ** 2
    return fr.mask & (rho2 < 1e-18)


def _subframe(fr: _Frame, rows: np.ndarray, mask: np.ndarray) -> _Frame:
    """The epochs ``rows`` of ``fr`` with the used paths ``mask`` (len(rows), L)."""
    return _Frame(
        fr.g, fr.idx[rows], mask, fr.src[rows], fr.s_loc[rows], fr.d0[rows], fr.alpha[rows],
        fr.mu_f[rows], fr.mu_t[rows], fr.pos,
    )  # fmt: skip


def _weakest_path(A: np.ndarray, mask: np.ndarray, alpha: np.ndarray) -> int:
    """The path (index into ``mask``) a singular ``A`` (7L, 7L) cannot resolve: the one that
    carries most of the Jacobi-scaled eigenvector of the smallest eigenvalue (of two paths that
    share it, the weaker)."""
    d = np.diagonal(A)
    sc = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    _, V = np.linalg.eigh(sc[:, None] * A * sc[None, :])
    share = np.where(mask, np.sum(V[:, 0].reshape(-1, 7) ** 2, axis=1), 0.0)
    share[np.flatnonzero(mask)[np.any(d.reshape(-1, 7)[mask] <= 0, axis=1)]] = np.inf
    cand = np.flatnonzero(share >= 0.5 * share.max())
    return int(cand[np.argmin(np.abs(alpha[cand]))])


def _solve(setup, fr: _Frame, imp: DesignImpairments, Jz: np.ndarray, cal: bool) -> dict:
    """The compressed per-path error model of the epochs of ``fr`` (``Jz`` (T, L, 4, 7): d z /
    d eta, Cartesian wave origin), and per epoch whether the Fisher information is singular
    (``bad``) with the path it cannot resolve (``weakest``, -1 where regular)."""
    T, L = fr.idx.shape
    M = fr.pos.shape[0]
    out = {
        "crlb": np.zeros((T, 4 * L, 4 * L)),
        "cov": np.zeros((T, 4 * L, 4 * L)),
        "bias": np.zeros((T, 4 * L)),
        "kph": np.zeros((T, 4 * L, M)) if cal else None,
        "kg": np.zeros((T, 4 * L, M)) if cal else None,
        "bad": np.zeros(T, bool),
        "weakest": np.full(T, -1),
    }
    for ch in _chunks(setup, fr, imp, frame="radial"):
        sl = ch["slice"]
        mk = np.repeat(fr.mask[sl], 7, axis=1)
        A = ch["A"] + np.eye(7 * L)[None] * ~mk[:, :, None]  # padding decoupled
        Ainv, sing = scaled_inverse(A)
        sing &= fr.mask[sl].any(axis=1)
        out["bad"][sl] = sing
        for i in np.flatnonzero(sing):
            out["weakest"][sl.start + i] = _weakest_path(A[i], fr.mask[sl][i], fr.alpha[sl][i])
        Ainv = np.where(mk[:, :, None] & mk[:, None, :] & ~sing[:, None, None], Ainv, 0.0)
        Jr = Jz[sl].copy()  # the wave origin in its radial frame: d z / d s @ basis
        Jr[..., 4:] = Jr[..., 4:] @ ch["basis"]
        J = _block_diag(Jr)
        JA = J @ Ainv
        out["crlb"][sl] = JA @ J.transpose(0, 2, 1)
        out["cov"][sl] = out["crlb"][sl]
        if ch["E"] is not None:
            out["cov"][sl] += JA @ ch["E"] @ JA.transpose(0, 2, 1)
        if ch["s_wb"] is not None:
            out["bias"][sl] = (JA @ ch["s_wb"][..., None])[..., 0]
        if cal:
            out["kph"][sl] = JA @ ch["S_ph"]
            out["kg"][sl] = JA @ ch["S_g"]
    return out


def path_error_model(
    setup: DesignSetup,
    spec,
    impairments: DesignImpairments | None = None,
    *,
    epochs=None,
    geometry: RouteGeometry | None = None,
) -> PathErrorModel:
    """The joint ML extraction's per-path error along ``setup``'s route for array ``spec`` under
    ``impairments`` (docs/internals; fields in :class:`PathErrorModel`).

    Every existing path of the route geometry (``geometry``, or traced at ``epochs``: not both) enters
    the joint model. ``crlb`` is the ideal bound of all paths' ``z`` (gains and Dopplers
    eliminated), ``cov`` the sandwich covariance with diffuse multipath (``crlb`` without it),
    ``bias`` the spatial-wideband bias (zero when the estimator models the term,
    ``impairments.wideband_model``: its Fisher information is eq. 1's to within 1 %, module
    docstring), ``k_phase`` [per rad] and ``k_gain`` [per dB] the
    calibration sensitivities (None when the calibration is perfect).

    Each epoch stands alone: the Fisher information is inverted with every wave origin in its
    own azimuth, elevation and range directions (:func:`~tunnelkit.design.mcrb.radial_basis`),
    in which a far path's unresolved curvature is a large but finite variance at any range.
    Where it is still singular at an epoch (a path the array cannot tell from another, or a
    parameter it cannot resolve), the path that carries the singular direction is left out of
    that epoch's joint model, one at a time until the rest is regular; a path whose wave
    origin lies on the vertical through the reference antenna (no azimuth) is left out too.
    Those paths are absent from ``exists`` at that epoch and flagged in ``unresolved``
    (:func:`unresolved_reason` says which and where); the other epochs and paths keep their
    values, whatever the rest of the route holds.
    """
    imp = DesignImpairments() if impairments is None else impairments
    _check(setup, imp)
    spec = parse_array(spec)
    cfg = setup.config
    if geometry is not None and epochs is not None:
        raise ValueError("epochs: the geometry given was traced at its own epochs; give one")
    g = route_geometry(setup, spec, epochs=epochs) if geometry is None else geometry
    instance("geometry", g, RouteGeometry)
    fr = _frame(setup, spec, g)
    T, L = fr.idx.shape
    P = g.exists.shape[1]
    M = fr.pos.shape[0]
    cal = imp.phase_error_deg > 0 or imp.gain_error_db > 0
    vertical = _vertical(fr, g)
    mask = fr.mask & ~vertical
    fr = _subframe(fr, np.arange(T), mask)
    Jz = _z_jacobian(fr, g, cfg)  # (T, L, 4, 7)
    res = _solve(setup, fr, imp, Jz, cal)
    todo = np.flatnonzero(res["bad"])
    weak = res["weakest"][todo]
    while todo.size:  # leave out, epoch by epoch, the path the array cannot resolve
        mask[todo, weak] = False
        res_t = _solve(setup, _subframe(fr, todo, mask[todo]), imp, Jz[todo], cal)
        for key in ("crlb", "cov", "bias", "kph", "kg"):
            if res[key] is not None:
                res[key][todo] = res_t[key]
        still = res_t["bad"]
        todo, weak = todo[still], res_t["weakest"][still]
    crlb_c, cov_c, bias_c, kph_c, kg_c = (res[k] for k in ("crlb", "cov", "bias", "kph", "kg"))
    # scatter the compressed paths into the route's slots
    rows = (4 * fr.idx[:, :, None] + np.arange(4)).reshape(T, 4 * L)
    keep = np.repeat(mask, 4, axis=1)
    tt = np.arange(T)[:, None]

    def scatter_mat(Xc):
        out = np.zeros((T, 4 * P, 4 * P))
        r = np.where(keep, rows, 0)
        Xc = np.where(keep[:, :, None] & keep[:, None, :], Xc, 0.0)
        np.add.at(out, (tt[:, :, None], r[:, :, None], r[:, None, :]), Xc)
        return out

    def scatter_vec(Xc):  # (T, 4L, ...) -> (T, 4P, ...)
        out = np.zeros((T, 4 * P, *Xc.shape[2:]))
        r = np.where(keep, rows, 0)
        Xc = np.where(keep.reshape(T, 4 * L, *([1] * (Xc.ndim - 2))), Xc, 0.0)
        np.add.at(out, (tt, r), Xc)
        return out

    rel = g.source - g.origin[:, None, :]
    rng_ = np.linalg.norm(rel, axis=-1)
    truth = np.stack(
        [
            np.arctan2(rel[..., 1], rel[..., 0]),
            np.arctan2(rel[..., 2], np.hypot(rel[..., 0], rel[..., 1])),
            rng_,
            rng_,
        ],
        axis=-1,
    )
    ex = np.zeros((T, P), bool)
    np.put_along_axis(ex, fr.idx, mask, axis=1)
    ex &= g.exists
    k_ph = k_g = None
    if cal:
        k_ph = scatter_vec(kph_c).reshape(T, P, 4, M)
        k_g = scatter_vec(kg_c).reshape(T, P, 4, M)
    return PathErrorModel(
        t=_epoch_times(setup, g),
        exists=ex,
        kinds=tuple(g.kinds),
        truth=np.where(ex[..., None], truth, 0.0),
        v=np.where(ex, C * g.doppler / cfg.fc, 0.0),
        crlb=scatter_mat(crlb_c),
        cov=scatter_mat(cov_c),
        bias=scatter_vec(bias_c).reshape(T, P, 4),
        k_phase=k_ph,
        k_gain=k_g,
        phase_sigma_rad=float(np.radians(imp.phase_error_deg)),
        gain_sigma_db=float(imp.gain_error_db),
        unresolved=g.exists & ~ex,
    )


def _ranges(x: np.ndarray, hit: np.ndarray) -> str:
    """``"x = 80.3..100.2 m, 120.0 m"``: the runs of consecutive epochs where ``hit``, worded
    as the report words the stretches above a target (:func:`~tunnelkit.design.render.over_target`)."""
    from .render import over_target  # the wording loaded when an array leaves a path unresolved

    return "x = " + over_target(x, np.asarray(hit, float), 0.5)


def unresolved_reason(model: PathErrorModel, geometry: RouteGeometry, label: str) -> str:
    """Which paths ``model`` leaves out because the array cannot resolve them, and where:
    ``"the 4x4 cannot resolve the ceiling path at x = 80.3..100.2 m (12 epochs)"`` per path
    kind, joined by ``"; "`` (``""`` when it leaves out none)."""
    instance("model", model, PathErrorModel), instance("geometry", geometry, RouteGeometry)
    text("label", label)
    if model.unresolved is None or not model.unresolved.any():
        return ""
    x = geometry.ue[:, 0]
    out = []
    for kind in dict.fromkeys(model.kinds):
        cols = np.array(model.kinds) == kind
        hit = model.unresolved[:, cols].any(axis=1)
        if hit.any():
            name = "direct" if kind == "los" else kind
            out.append(
                f"the {label} cannot resolve the {name} path at {_ranges(x, hit)} "
                f"({int(hit.sum())} epochs)"
            )
    return "; ".join(out)


def _epoch_times(setup, g: RouteGeometry) -> np.ndarray:
    """The trajectory times of the geometry's epochs (matched by the UE position)."""
    traj = setup.trajectory
    d = np.linalg.norm(g.ue[:, None, :] - np.asarray(traj.position)[None, :, :], axis=-1)
    return np.asarray(traj.t, float)[np.argmin(d, axis=1)]


@dataclass(frozen=True)
class PredictedError:
    """Per-epoch results of :func:`predicted_error` [m]: ``x`` position along the tunnel,
    ``peb`` the ideal PEB (as :func:`~tunnelkit.design.bounds.route_bounds`), ``predicted``
    ``sqrt(peb^2 + calibration^2 + wideband^2 + diffuse^2)`` and its parts: ``calibration`` the
    RMS position bias over the calibration draw, ``wideband`` the spatial-wideband position
    bias (zero when the estimator models the term), ``diffuse`` the excess standard deviation
    the diffuse multipath adds (root of the trace); ``weights`` the estimator they belong to
    (:data:`WEIGHTS`). ``inf`` where the position is not identifiable. ``noise`` (T,) [m] the
    noise part of ``predicted`` (the impairments' parts left out): the PEB for the ideal
    weights, the noise of the fix weighted block by block as the tracker is told for the
    tracker's (``None``: the PEB). ``valid`` (T,) bool: the epochs where ``predicted`` is
    defined (finite); elsewhere it is ``inf``, a gap at that epoch only, and ``reason`` says
    why and where (no path, a position the paths do not determine, paths the array cannot
    resolve: :func:`unresolved_reason`); ``""`` when nothing is missing. A path the array
    cannot resolve at an epoch is left out of that epoch only (its information is absent),
    which is named in ``reason`` even where the other paths still fix the position."""

    spec: object
    impairments: DesignImpairments
    x: np.ndarray
    peb: np.ndarray
    predicted: np.ndarray
    calibration: np.ndarray
    wideband: np.ndarray
    diffuse: np.ndarray
    weights: str = "tracker"
    noise: np.ndarray | None = None
    valid: np.ndarray | None = None
    reason: str = ""

    def __post_init__(self) -> None:
        instance("spec", self.spec, ArraySpec)
        if self.valid is None:
            object.__setattr__(self, "valid", np.isfinite(np.asarray(self.predicted, float)))
        bounds = ("peb", "predicted", "calibration", "wideband", "diffuse")
        record(self, shapes={**dict.fromkeys(("x", *bounds, "valid"), ("T",))},
               nonnegative=bounds, allow_inf=(*bounds, "noise"),
               may_be_empty=("reason",))  # fmt: skip
        if np.asarray(self.valid).dtype != bool:
            raise TypeError(f"valid: expected a bool array, got {np.asarray(self.valid).dtype}")
        choice("weights", self.weights, WEIGHTS)
        if self.noise is not None:
            object.__setattr__(self, "noise", bound_array("noise", self.noise, ndim=1))


#: whose error :func:`predicted_error` maps to the position: ``"tracker"`` the design's tracker
#: (each path weighted by the error budget it is told, block by block, a curvature it is not
#: handed left out: :func:`tunnelkit.design.trackerfix.tracker_weights`), ``"ideal"`` the
#: direct-position ML estimator that assumes eq. 1 (the misspecified bound of the whole
#: channel, which weighs every path by the ideal Fisher information)
WEIGHTS = ("tracker", "ideal")


def predicted_error(
    setup: DesignSetup,
    spec,
    impairments: DesignImpairments | None = None,
    *,
    geometry: RouteGeometry | None = None,
    epochs=None,
    weights: str = "tracker",
) -> PredictedError:
    """The ideal PEB and the predicted error (a first-order prediction, not a bound) of ``spec`` along
    ``setup``'s route under ``impairments`` (docs/internals); ``geometry`` reuses a traced
    route, ``epochs`` (indices) subsamples it.

    ``weights`` (:data:`WEIGHTS`): ``"tracker"`` (default) maps the per-path error model
    (:func:`path_error_model`) to the position as the design's tracker weighs its paths
    (:func:`tunnelkit.design.trackerfix.position_error_parts`); ``"ideal"`` maps the channel's
    misspecified score through the ideal Fisher information of the position. The ideal
    weighting trusts a large array's micrometre curvatures, whose calibration and wideband
    biases are centimetres: on the 28 GHz example with the wideband term and 0.2 dB of gain
    error it puts 32 x 32 at several times the error its tracker has. The tracker weighting
    needs the per-path model: a path the array cannot resolve at an epoch is left out of that
    epoch (:func:`path_error_model`), and an epoch whose resolved paths do not fix the position
    is a gap (``inf`` there, ``valid`` False, ``reason`` naming the cause and where); every
    epoch is evaluated on its own, whatever the rest of the route holds. With the tracker's weights the noise
    part is the covariance of the fix weighted block by block as the tracker is told
    (:func:`tunnelkit.design.trackerfix.position_noise_cov`), not the PEB: never below it, and
    above it where the joint CRLB correlates paths (small arrays, paths close in angle and
    delay)."""
    imp = DesignImpairments() if impairments is None else impairments
    _check(setup, imp)
    weights = choice("weights", weights, WEIGHTS)
    spec = parse_array(spec)
    cfg = setup.config
    g = route_geometry(setup, spec, epochs=epochs) if geometry is None else geometry
    instance("geometry", g, RouteGeometry)
    peb = route_bounds(setup, spec, geometry=g).peb
    if weights == "tracker":
        return _tracker_bound(setup, spec, imp, g, peb)
    from .idealweights import ideal_parts  # loaded when the ideal weighting is asked for

    fr = _frame(setup, spec, g)
    cal2, wb, dif2 = ideal_parts(cfg, fr, g, imp, peb, _chunks(setup, fr, imp))
    fin = np.isfinite(peb)
    cal = np.where(fin, np.sqrt(np.clip(cal2, 0, None)), np.inf)
    wb = np.where(fin, wb, np.inf)
    dif = np.where(fin, np.sqrt(np.clip(dif2, 0, None)), np.inf)
    with np.errstate(invalid="ignore"):
        ach = np.where(fin, np.sqrt(peb**2 + cal**2 + wb**2 + dif**2), np.inf)
    reason = _gap_reason(spec, g, peb, None, None)
    return PredictedError(
        spec, imp, g.ue[:, 0].copy(), peb, ach, cal, wb, dif, "ideal", peb, fin, reason
    )


def _tracker_bound(setup, spec, imp, g, peb) -> PredictedError:
    """:func:`predicted_error` with the tracker's weights."""

    T = peb.shape[0]
    m = path_error_model(setup, spec, imp, geometry=g)
    w = tracker_weights(m)
    ok = fix_identifiable(m, g, w)
    # the noise of the fix weighted as the tracker weighs: one block per path, so the
    # correlation of the joint CRLB between paths is not used (never below the PEB)
    cov = position_noise_cov(m, g, w)
    noise = np.maximum(np.sqrt(np.clip(np.trace(cov, axis1=1, axis2=2), 0, None)), peb)
    parts = np.zeros((T, 3)) if imp.ideal else position_error_parts(m, g, w)
    fin = np.isfinite(peb) & ok
    cal, wb, dif = (np.where(fin, parts[:, i], np.inf) for i in range(3))
    with np.errstate(invalid="ignore"):
        ach = np.where(fin, np.sqrt(noise**2 + cal**2 + wb**2 + dif**2), np.inf)
    noise = np.where(fin, noise, np.inf)
    reason = _gap_reason(spec, g, peb, m, ok)
    return PredictedError(
        spec, imp, g.ue[:, 0].copy(), peb, ach, cal, wb, dif, "tracker", noise, fin, reason
    )


def _gap_reason(spec, g: RouteGeometry, peb, model: PathErrorModel | None, ok) -> str:
    """Why and where the bound has gaps: epochs without a path, without an identifiable
    position (PEB), whose resolved paths do not fix the position, and the paths the array
    cannot resolve (:func:`unresolved_reason`); ``""`` without a gap."""
    x = g.ue[:, 0]
    out = []
    none = ~g.exists.any(axis=1)
    if none.any():
        out.append(f"no path reaches the {spec.label} at {_ranges(x, none)}")
    unid = ~none & ~np.isfinite(peb)
    if unid.any():
        out.append(f"the paths do not determine the position at {_ranges(x, unid)}")
    if model is not None:
        lost = ~none & np.isfinite(peb) & ~ok
        if lost.any():
            out.append(
                f"the paths the {spec.label} resolves do not fix the position at {_ranges(x, lost)}"
            )
        un = unresolved_reason(model, g, spec.label)
        if un:
            out.append(un)
    return "; ".join(out)
