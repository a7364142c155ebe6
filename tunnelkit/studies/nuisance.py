"""A model that absorbs what eq. 1 misses: the pseudo-true bias of the first-order paths on the
ray-traced channel under eq. 1 and under eq. 1 extended, and what each extension costs on eq.
1's own tensor (``docs/results/traced-models.md``).

The models (:data:`MODELS`):

* ``eq1``: eq. 1 with the image method's first-order paths (the extraction's model);
* ``aperture-1`` / ``aperture-2``: each path with a real amplitude profile over the array of
  that polynomial order (:class:`~tunnelkit.extraction.direct.aperture.ApertureProblem`: the visibility of a path to only
  part of the array, the term the attribution found in the LoS and ceiling paths);
* ``second-order-N``: eq. 1 with the image method's ``N`` strongest second-order specular paths
  as nuisance atoms beside the first-order ones
  (:func:`tunnelkit.propagation.second_order.second_order_paths`, as
  ``RouteOptions(second_order=N)`` models them; the second-order bounces carry about 20 % of the
  traced power);
* ``visibility``: eq. 1 with each first-order path on the elements that see it and an atom for
  each facet some element sees that the reference element does not (:mod:`tunnelkit.extraction.direct.visibility`: masks
  from the true position for the bias, from a predicted one for the noisy rows);
  ``visibility-second-order-N`` the same with ``N`` second-order atoms (seen by every element).

:func:`traced_bias` fits each model noiselessly to the traced tensor of each epoch (the pseudo-true
parameters: eq. 1's by :func:`~.misspecified.pseudo_true` from the true paths, the profile's by
:meth:`ApertureProblem.fit <tunnelkit.extraction.direct.aperture.ApertureProblem.fit>` from eq. 1's, the second-order
model's by ``pseudo_true`` from the true first- and second-order paths, the visibility models'
by :meth:`MaskedProblem.fit <tunnelkit.extraction.direct.visibility.MaskedProblem.fit>` from every true path they hold and
from eq. 1's fit, the better kept: the most favourable start, an oracle) and reports each first-order path's bias against the image method's geometry,
by kind; with noisy draws also each model's extraction errors (not started at the truth) and a
one-epoch position fix from either. :func:`eq1_cost` does the same on eq. 1's own tensor, where every model must be
unbiased, and gives the profile's Cramer-Rao bound against eq. 1's (the price of ``K`` more
parameters per path) with the Monte-Carlo RMSE of both fits.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from dataclasses import dataclass

import numpy as np

from .._validate import boolean, choice, integer, positive, sequence
from ..channel import channel_tensor
from ..constants import C
from ..evaluation import match_paths
from ..extraction import extract_paths, ml_truth
from ..extraction.direct.aperture import MAX_ORDER, ApertureProblem
from ..extraction.direct.visibility import MaskedProblem, predicted_model
from ..extraction.ml import Problem, fit_problem, start_from_estimates
from ..propagation import SECOND_ORDER
from ..signal_route import SignalRoute
from .attribution import KINDS, measured_record, one_epoch_fix, scenario_with_array
from .misspecified import pseudo_true
from .truth import angles_of_theta, path_differences, path_truth

__all__ = ["MODELS", "CostRow", "ModelRow", "eq1_cost", "traced_bias"]

#: the models compared (module docstring)
MODELS = (
    "eq1",
    "aperture-1",
    "aperture-2",
    "second-order-2",
    "second-order-4",
    "visibility",
    "visibility-second-order-4",
)


@dataclass(frozen=True)
class ModelRow:
    """One model, measure and kind of first-order path over the epochs: ``n`` paths, median and
    RMS of |x| in world azimuth and elevation [deg] and the delay distance ``d`` [m], ``x`` the
    pseudo-true bias (``measure = "bias"``) or the noisy extraction's error (``"error"``), and
    the median share of the tensor's power the model leaves at its pseudo-true parameters (over
    all epochs, the same in every kind and measure). Rows of kind ``"all"`` also give the
    horizontal error [m] of a one-epoch fix (:func:`~.attribution.one_epoch_fix`, its weights,
    the oracle association of the attribution study) from the pseudo-true parameters (``bias``)
    or from each noisy extraction (``error``): median and RMS over epochs and draws; NaN in the
    other rows. ``extract_s``: the median wall time [s] of one noisy extraction under the model
    (``error`` rows; NaN for ``bias``)."""

    model: str
    measure: str
    kind: str
    n: int
    az_med: float
    az_rms: float
    el_med: float
    el_rms: float
    d_med: float
    d_rms: float
    residual_share: float
    fix_med_m: float
    fix_rms_m: float
    extract_s: float

    def __post_init__(self) -> None:
        choice("model", self.model, MODELS)
        choice("measure", self.measure, ("bias", "error"))
        choice("kind", self.kind, (*KINDS, "all"))
        measured_record(self, ("n",))
        integer("n", self.n, minimum=1)


def _rows(
    model: str, measure: str, errs: list, shares: list, fixes: list, secs=()
) -> list[ModelRow]:
    out = []
    for kind in [k for k in KINDS if any(e[0] == k for e in errs)] + ["all"]:
        e = np.abs(np.array([x[1][:3] for x in errs if kind in ("all", x[0])]))
        med, rms = np.median(e, 0), np.sqrt(np.mean(e**2, 0))
        f = np.array(fixes if kind == "all" else [np.nan], float)
        fix = (
            (np.nanmedian(f), np.sqrt(np.nanmean(f**2)))
            if np.any(np.isfinite(f))
            else (np.nan,) * 2
        )
        out.append(ModelRow(model, measure, kind, len(e), med[0], rms[0], med[1], rms[1], med[2], rms[2],
                           float(np.median(shares)), *map(float, fix),
                           float(np.median(secs)) if len(secs) else float("nan")))  # fmt: skip
    return out


def _shape(array) -> tuple[int, int]:
    """``array`` as (rows, columns) of a URA, each 1 to 64."""
    shape = sequence("array", array)
    if len(shape) != 2:
        raise ValueError(f"array: expected (rows, columns), got {array!r}")
    return tuple(integer("array", n, minimum=1, maximum=64) for n in shape)


def _fit(model: str, H, arr, cfg, paths, extra, mask=None, fits=None) -> tuple:
    """``(theta, mu_f, cost, mu_t)`` of the first-order paths under ``model`` (module docstring):
    ``extra`` its nuisance paths, ``mask`` (visibility models) each path's elements; ``fits``
    (a dict) keeps eq. 1's fit of ``H`` once made, which the visibility models start from too."""
    fits = {} if fits is None else fits
    L = len(paths)
    if model.startswith("visibility"):  # from every true path, and from eq. 1's fit: the better
        prob, tol = MaskedProblem(H, arr.local, cfg.fc, mask), 0.01 * cfg.noise_power
        th, mf, mt = ml_truth(list(paths) + list(extra), arr, cfg)
        e1 = fits.get("eq1") or _fit("eq1", H, arr, cfg, paths, [], fits=fits)
        f = min(
            prob.fit(th, mf, mt, tol),
            prob.fit(np.vstack([e1[0], th[L:]]), np.r_[e1[1], mf[L:]], np.r_[e1[3], mt[L:]], tol),
            key=lambda r: r["cost"],
        )
        return f["theta"][:L], f["mu_f"][:L], f["cost"], f["mu_t"][:L]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fit's tests judge a noisy snapshot
        if model.startswith("second-order"):
            start = ml_truth(list(paths) + list(extra), arr, cfg)
        else:
            start = ml_truth(paths, arr, cfg)
        pt = pseudo_true(H, arr.local, cfg.fc, start, noise_power=cfg.noise_power,
                         newton_iter=30)  # fmt: skip
    out = pt["theta"][:L], pt["mu_f"][:L], pt["residual_power"] * H.size, pt["mu_t"][:L]
    if model == "eq1":
        fits["eq1"] = out
    if not model.startswith("aperture"):
        return out
    prob = ApertureProblem(H, arr.local, cfg.fc, order=int(model.rsplit("-", 1)[1]))
    f = prob.fit(pt["theta"], pt["mu_f"], pt["mu_t"], 0.01 * cfg.noise_power)
    return f["theta"], f["mu_f"], f["cost"], f["mu_t"]


def traced_bias(
    scenario: str = "italiano2026-straight",
    *,
    array=(8, 8),
    epochs=(0, 5, 10, 15, 20, 25),
    models=MODELS,
    draws: int = 0,
    rng: np.random.Generator | None = None,
    cache_dir=None,
    progress: bool = False,
    predicted_sigma: float = 0.1,
) -> list[ModelRow]:
    """The first-order pseudo-true bias by model and kind (module docstring) on ``scenario``'s
    traced channel at ``epochs``, with every base-station array ``array`` (rows, columns) mounted
    as the scenario mounts its own (:func:`~.attribution.scenario_with_array`), traces cached
    under ``cache_dir`` (:func:`tunnelkit.rt.default_cache_dir` by default); with ``draws``
    also each model's errors on that many noisy snapshots per epoch (clock bias and noise drawn
    with ``rng``, :meth:`SignalRoute.draw <tunnelkit.signal_route.SignalRoute.draw>`): the
    extraction's default route (:func:`tunnelkit.extraction.extract_paths`) with the first-order
    paths' number (``eq1``), with that number plus the image method's second-order paths
    (``second-order-N``: started as the extraction starts, not at the truth), or eq. 1's then
    refined with the profile (``aperture-K``); estimates matched to the first-order truth
    (:func:`tunnelkit.evaluation.match_paths`), ``d`` less the drawn clock bias. The visibility
    models' noisy fit starts every atom at the model of a predicted position
    (:func:`~tunnelkit.extraction.direct.visibility.predicted_model` at the true one moved by ``N(0, predicted_sigma^2)``
    [m] along x and y, drawn with ``rng`` after each snapshot: a tracker's prediction), the
    delays shifted by eq. 1's earliest delay less the prediction's shortest path (the clock
    bias, unknown to the receiver)."""
    models = [m for m in sequence("models", models)]
    for m in models:
        if m not in MODELS:
            raise ValueError(f"models: expected names of {MODELS}, got {m!r}")
    progress = boolean("progress", progress)
    draws = integer("draws", draws, minimum=0, maximum=100)
    if draws and not isinstance(rng, np.random.Generator):
        raise TypeError(f"rng: expected a numpy.random.Generator, got {type(rng).__name__}")
    if positive("predicted_sigma", predicted_sigma) > 10.0:
        raise ValueError(
            f"predicted_sigma: a tracker's prediction within 10 m, got {predicted_sigma}"
        )
    if cache_dir is not None and not isinstance(cache_dir, str | os.PathLike):
        raise TypeError(f"cache_dir: expected a directory path, got {type(cache_dir).__name__}")
    sc = scenario_with_array(scenario, _shape(array))
    route = SignalRoute.from_scenario(sc, channel="sionna", cache_dir=cache_dir)
    T = len(route.trajectory.t)
    ks = [integer("epochs", k, minimum=0, maximum=T - 1) for k in sequence("epochs", epochs)]
    route.raytraced.prepare(epochs=ks, progress=progress)
    amp = math.sqrt(route.config.tx_power)
    errs = {m: [] for m in models}
    noisy = {m: [] for m in models}
    shares = {m: [] for m in models}
    fix_bias = {m: [] for m in models}
    fix_err = {m: [] for m in models}
    secs = {m: [] for m in models}
    # each model's number of second-order atoms; the route of each second-order model, built once
    n2 = {m: int(m.rsplit("-", 1)[1]) if "second-order" in m else 0 for m in models}
    with_second = {m: route.with_options(second_order=n2[m]) for m in models if n2[m]}
    for k in ks:
        arr, paths = route.paths(k)
        H = amp * route.raytraced.tensor(k)[1]
        h2 = float(np.vdot(H, H).real)
        tru, idx = path_truth(paths, arr), np.arange(len(paths))
        ue, vel = route.trajectory.position[k], route.trajectory.velocity[k]
        extras, masks, fits = {}, {}, {}
        for m in models:
            extra = []
            if m.startswith("visibility"):  # the true position's model: missing facets, bounces
                hat, masks[m], n_first = predicted_model(route, arr, ue, vel, n2[m])
                extra = hat[n_first:]
            elif m in with_second:
                extra = [p for p in with_second[m].paths(k)[1] if p.kind == SECOND_ORDER]
            theta, mu_f, cost, _ = _fit(m, H, arr, route.config, paths, extra, masks.get(m), fits)
            est = angles_of_theta(theta, mu_f, arr, route.config)
            e = path_differences(est, tru, idx, idx)
            errs[m] += [(p.surface_kind, x) for p, x in zip(paths, e, strict=True)]
            dx = one_epoch_fix(est["phi"], est["psi"], est["d"], paths, ue, arr.origin)
            fix_bias[m].append(float(np.hypot(*dx)))
            shares[m].append(cost / h2)
            extras[m] = len(extra)
        for _ in range(draws):
            snap = route.draw(k, rng)[2]
            eq1 = {}  # eq. 1's extraction of this snapshot, shared by eq1 and the profiles
            if masks:  # a tracker's prediction of the position
                ue_hat = ue + np.r_[predicted_sigma * rng.standard_normal(2), 0.0]
            for m in models:
                x = extras[m]
                if m in masks:  # the atoms of the prediction's model
                    x = predicted_model(route, arr, ue_hat, vel, n2[m])
                (e, fix), sec = _errors(m, snap, arr, route.config, paths, tru, x, ue, eq1)
                secs[m].append(sec)
                noisy[m] += e
                fix_err[m].append(fix)
        if progress:
            print(f"  epoch {k}: " + ", ".join(f"{m} {shares[m][-1]:.4f}" for m in models))
    rows = [r for m in models for r in _rows(m, "bias", errs[m], shares[m], fix_bias[m])]
    if draws:
        rows += [
            r for m in models for r in _rows(m, "error", noisy[m], shares[m], fix_err[m], secs[m])
        ]
    return rows


def _extract(snap, n_paths: int, arr, cfg) -> tuple:
    """``(theta, mu_f, mu_t)`` of the extraction's default route with ``n_paths`` paths."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fit's own test flags every traced epoch
        return start_from_estimates(extract_paths(snap.H, n_paths, arr, cfg))


def _errors(model: str, snap, arr, cfg, paths, tru, atoms, ue, eq1: dict) -> tuple:
    """``((kind, (4,) error) list, fix error [m]), seconds``: the first-order paths one noisy
    snapshot gives under ``model``, the horizontal error of their one-epoch fix and the time of
    the model's extraction (:func:`traced_bias`). ``eq1`` holds eq. 1's extraction of the
    snapshot once made (``"fit"``, ``"s"``): the profiles refine it and the visibility models
    read its earliest delay, so they are timed with it. ``atoms``: the number of second-order
    atoms, or for a visibility model the model of a predicted position (``(paths, masks,
    n_first)``, :func:`~tunnelkit.extraction.direct.visibility.predicted_model`): its atoms start there, not at eq. 1's."""
    L = len(paths)
    t0 = time.perf_counter()
    if model.startswith("second"):
        theta, mu_f, _ = _extract(snap, L + atoms, arr, cfg)
        sec = time.perf_counter() - t0
    else:
        if "fit" not in eq1:
            eq1["fit"] = _extract(snap, L, arr, cfg)
            eq1["s"] = time.perf_counter() - t0
        theta, mu_f, mu_t = eq1["fit"]
        sec = eq1["s"]
        if model.startswith("aperture"):
            t1 = time.perf_counter()
            prob = ApertureProblem(snap.H, arr.local, cfg.fc, order=int(model.rsplit("-", 1)[1]))
            f = prob.fit(theta, mu_f, mu_t, cfg.noise_power)
            theta, mu_f = f["theta"], f["mu_f"]
            sec += time.perf_counter() - t1
        if model.startswith("visibility"):  # from the model of a predicted position
            t1 = time.perf_counter()
            hat, mask, L = atoms
            th, mf, mt = ml_truth(hat, arr, cfg)
            d_eq1 = -C * mu_f / (2 * np.pi * cfg.tone_spacing)  # eq. 1's delays, the bias in
            shift = np.min(d_eq1) - min(p.length for p in hat[:L])
            mf = mf - 2 * np.pi * cfg.tone_spacing * shift / C
            f = MaskedProblem(snap.H, arr.local, cfg.fc, mask).fit(th, mf, mt, cfg.noise_power)
            theta, mu_f = f["theta"][:L], f["mu_f"][:L]
            sec += time.perf_counter() - t1
    e = angles_of_theta(theta, mu_f, arr, cfg)
    u = np.column_stack([np.cos(e["psi"]) * np.cos(e["phi"]), np.cos(e["psi"]) * np.sin(e["phi"]),
                         np.sin(e["psi"])])  # fmt: skip
    t = match_paths(e["d"], u, paths, clock_bias=snap.clock_bias)
    rows = np.flatnonzero(t >= 0)
    diff = path_differences(e, tru, rows, t[rows], C * snap.clock_bias)
    sel = [paths[t[r]] for r in rows]
    dx = one_epoch_fix(e["phi"][rows], e["psi"][rows], e["d"][rows], sel, ue, arr.origin)
    kinds = [p.surface_kind for p in sel]
    return (list(zip(kinds, diff, strict=True)), float(np.hypot(*dx))), sec


@dataclass(frozen=True)
class CostRow:
    """One amplitude-profile order on eq. 1's own tensor, over the paths of the epochs: the
    largest noiseless bias of the direction cosines and of ``d`` [m] (zero for an unbiased model),
    the profile's Cramer-Rao bound over eq. 1's (standard deviations, median over paths) for
    ``u_x``, ``u_y`` and ``d``, and each fit's Monte-Carlo RMSE over its own bound (``u`` pooled
    over ``u_x, u_y``; eq. 1's fit started at the truth, the profile's from eq. 1's)."""

    order: int
    n_paths: int
    bias_u: float
    bias_d_m: float
    crlb_ratio_ux: float
    crlb_ratio_uy: float
    crlb_ratio_d: float
    eq1_rmse_over_crlb_u: float
    eq1_rmse_over_crlb_d: float
    rmse_over_crlb_u: float
    rmse_over_crlb_d: float

    def __post_init__(self) -> None:
        measured_record(self, ("order", "n_paths"))
        integer("order", self.order, minimum=1, maximum=MAX_ORDER)
        integer("n_paths", self.n_paths, minimum=1, maximum=100_000)


def _crlb(A, sigma2: float, n: int) -> np.ndarray:
    """(L, n) standard deviations of the per-path parameters from ``A`` = Re J^H J (the
    concentrated Fisher information is ``2 A / sigma2``)."""
    return np.sqrt(np.diag(np.linalg.inv(A)) * sigma2 / 2).reshape(-1, n)


def _over_bound(theta, mu_f, th, mf, sd) -> np.ndarray:
    """(L, 3) errors of ``u_x``, ``u_y`` and ``mu_f`` against the truth ``th``, ``mf`` over the
    standard deviations ``sd`` (L, >= 4: columns 0, 1 and 3)."""
    du = (theta[:, :2] - th[:, :2]) / sd[:, :2]
    return np.column_stack([du, np.angle(np.exp(1j * (mu_f - mf))) / sd[:, 3]])


def eq1_cost(
    scenario: str = "italiano2026-straight",
    *,
    array=(8, 8),
    epochs=(0, 10, 20),
    orders=(1, 2),
    draws: int = 20,
    rng: np.random.Generator,
) -> list[CostRow]:
    """What the amplitude profile costs where eq. 1 holds (module docstring): on eq. 1's tensor
    of the image method's paths (:func:`tunnelkit.channel.channel_tensor`) of ``scenario`` with
    ``array`` at ``epochs``, per ``orders``, ``draws`` noisy snapshots per epoch drawn with
    ``rng`` at the scenario's noise power."""
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"rng: expected a numpy.random.Generator, got {type(rng).__name__}")
    orders = [
        integer("orders", o, minimum=1, maximum=MAX_ORDER) for o in sequence("orders", orders)
    ]
    draws = integer("draws", draws, minimum=1, maximum=1000)
    route = SignalRoute.from_scenario(scenario_with_array(scenario, _shape(array)))
    cfg = route.config
    T = len(route.trajectory.t)
    ks = [integer("epochs", k, minimum=0, maximum=T - 1) for k in sequence("epochs", epochs)]
    d_per_mu = C / (2 * np.pi * cfg.tone_spacing)
    acc = {o: {"bias": [], "ratio": [], "e": []} for o in orders}
    e1 = []  # eq. 1's errors over its bound, the same beside every order
    for k in ks:
        arr, paths = route.paths(k)
        H0 = channel_tensor(paths, cfg)
        th, mf, mt = ml_truth(paths, arr, cfg)
        L, s2 = len(paths), cfg.noise_power
        sd1 = _crlb(Problem(H0, arr.local, cfg.fc).evaluate(th, mf, mt)["A"], s2, 5)
        noisy = [H0 + math.sqrt(s2 / 2) * (rng.standard_normal(H0.shape)
                 + 1j * rng.standard_normal(H0.shape)) for _ in range(draws)]  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fits1 = [fit_problem(Problem(H, arr.local, cfg.fc), (th, mf, mt), noise_power=s2,
                                 n_reseed=0, search="basic") for H in noisy]  # fmt: skip
        e1 += [_over_bound(f.theta, f.mu_f, th, mf, sd1) for f in fits1]
        for o in orders:
            prob = ApertureProblem(H0, arr.local, cfg.fc, order=o)
            n = 5 + prob.K
            f0 = prob.fit(th, mf, mt, 0.01 * s2)
            acc[o]["bias"].append(np.column_stack([np.abs(f0["theta"][:, :2] - th[:, :2]).max(1),
                                                   d_per_mu * np.abs(f0["mu_f"] - mf)]))  # fmt: skip
            sd = _crlb(prob.evaluate_profile(th, mf, mt, np.zeros((L, prob.K)))["A"], s2, n)
            acc[o]["ratio"].append(sd[:, [0, 1, 3]] / sd1[:, [0, 1, 3]])
            for H, f1 in zip(noisy, fits1, strict=True):
                fa = ApertureProblem(H, arr.local, cfg.fc, order=o).fit(f1.theta, f1.mu_f,
                                                                        f1.mu_t, s2)  # fmt: skip
                acc[o]["e"].append(_over_bound(fa["theta"], fa["mu_f"], th, mf, sd))
    e1 = np.concatenate(e1)
    rows = []
    for o in orders:
        bias = np.concatenate(acc[o]["bias"])
        ratio = np.median(np.concatenate(acc[o]["ratio"]), 0)
        e = np.concatenate(acc[o]["e"])

        def rms(x):
            return float(np.sqrt(np.mean(x**2)))

        rows.append(CostRow(o, bias.shape[0], float(bias[:, 0].max()), float(bias[:, 1].max()),
                            *map(float, ratio), rms(e1[:, :2]), rms(e1[:, 2]), rms(e[:, :2]),
                            rms(e[:, 2])))  # fmt: skip
    return rows
