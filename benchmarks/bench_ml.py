"""The default extraction (CPD, coherent split, joint ML) against the structured CRLB.

Timing (``cases``): the whole default extraction at M = 100, Nf = 410, Nt = 12, L = 6 on one
BLAS thread, with today's CPD + coherent route as the baseline of the group.

Accuracy (``report``, printed by ``benchmarks/run.py`` after the timings, or alone with
``python benchmarks/bench_ml.py --snapshots 200``): over seeded snapshots of random near-field
scenes (2-4 sources 2-8 m from a 10 x 10 URA, per-sample SNR -10..10 dB) and of tunnel epochs
drawn across both drives (``italiano2026-straight`` and ``-slalom``, :class:`SignalRoute`), the
RMS of error / CRLB standard deviation per parameter (d, v, direction, kappa) and per path kind,
and the share of errors beyond 6 sigma (a missed path counts as beyond). Goal: RMS <= 1.5 and
<= 2 % beyond 6 sigma.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run import Case

from tunnelkit import channel, evaluation, extraction, propagation, signal_route
from tunnelkit.constants import C
from tunnelkit.montecarlo import spawn_rngs

PARAMS = ("d", "v", "direction", "kappa")
DRIVES = ("italiano2026-straight", "italiano2026-slalom")


def _tensor():
    """bench_extraction's tensor: epoch 10 of the straight drive plus a second vehicle (L = 6)."""
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    arr, paths = route.paths(10)
    extra = propagation.trace_paths(
        route.tunnel, arr, [25.0, 2.0, 1.5], [-10.0, 0, 0], fc=route.config.fc, kinds=("los",)
    )
    paths = paths + extra
    snap = channel.synthesize(paths, route.config, np.random.default_rng(0))
    return snap.H, arr, route.config, len(paths)


def cases() -> list[Case]:
    H, arr, cfg, L = _tensor()
    args = (arr, cfg)

    def run(**kw):
        with threadpool_limits(1), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return extraction.extract_paths(H, L, *args, **kw)

    g = "ml"
    return [
        Case(
            f"extract_paths L={L}, CPD + coherent split",
            lambda: run(refine="coherent"),
            group=g,
            baseline=True,
            repeat=7,
        ),
        Case(
            f"extract_paths L={L}, default (CPD + search + ML)",
            lambda: run(),
            group=g,
            repeat=7,
            goal_s=0.25,
        ),
    ]


def _tunnel_errors(route, rng, k):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ep = route.epoch(k, rng)
    src = np.stack([ep.array.to_local(p.source) for p in ep.paths])
    d_true = np.array([p.length for p in ep.paths]) + C * ep.snapshot.clock_bias
    v_true = np.array([p.velocity for p in ep.paths])
    bound = extraction.path_crlb(ep.paths, ep.array, route.config)
    err = evaluation.normalized_errors(ep.estimates, d_true, v_true, src, bound)
    return err, [p.surface_kind for p in ep.paths], ep.estimates.fit


def _scene_errors(rng):
    sc = evaluation.random_scene(rng, int(rng.integers(2, 5)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(sc.tensor(rng), len(sc.d), sc.element_positions, sc.config)
    err = evaluation.normalized_errors(est, sc.d, sc.v, sc.sources, sc.crlb())
    return err, ["scene"] * len(sc.d), est.fit


def study(n_snapshots: int = 200, seed: int = 14) -> dict:
    """Normalised errors of ``n_snapshots`` random scenes and ``n_snapshots`` tunnel epochs
    (half per drive), grouped by path kind; also the wall-clock time per snapshot."""
    routes = [signal_route.SignalRoute.from_scenario(d) for d in DRIVES]
    rows: dict[str, list] = {}
    fits = {"scene": [], "tunnel": []}
    t0 = time.perf_counter()
    for i, rng in enumerate(spawn_rngs(seed, 2 * n_snapshots)):
        if i < n_snapshots:
            err, kinds, fit = _scene_errors(rng)
            tag = "scene"
        else:
            route = routes[i % 2]
            k = int(rng.integers(0, len(route.trajectory)))
            err, kinds, fit = _tunnel_errors(route, rng, k)
            tag = DRIVES[i % 2].split("-")[1]
        fits["scene" if tag == "scene" else "tunnel"].append(
            (fit.n_reseed, fit.rho > fit.rho_max, fit.n_iter)
        )
        for e, kind in zip(err, kinds):
            if tag != "scene":
                rows.setdefault(kind, []).append(e)
            rows.setdefault(f"all {tag}", []).append(e)
    return {
        "errors": {k: np.array(v) for k, v in rows.items()},
        "seconds": time.perf_counter() - t0,
        "fits": {k: np.array(v, float).reshape(-1, 3) for k, v in fits.items()},
    }


def table(res: dict) -> str:
    lines = [
        f"{'path kind':16s} {'n':>5s} "
        + " ".join(f"{'RMS ' + p:>14s}" for p in PARAMS)
        + " "
        + " ".join(f"{'>6sig ' + p:>14s}" for p in PARAMS)
    ]
    for kind, e in sorted(res["errors"].items()):
        fin = np.isfinite(e)
        with np.errstate(invalid="ignore"):
            rms = [
                np.sqrt(np.mean(e[fin[:, j], j] ** 2)) if fin[:, j].any() else np.nan
                for j in range(4)
            ]
        beyond = np.mean(~(np.abs(e) <= 6.0), axis=0) * 100
        lines.append(
            f"{kind:16s} {len(e):5d} "
            + " ".join(f"{r:14.2f}" for r in rms)
            + " "
            + " ".join(f"{b:13.1f}%" for b in beyond)
        )
    for tag, f in res["fits"].items():
        lines.append(
            f"{tag}: {len(f)} fits, re-seeded {np.mean(f[:, 0] > 0) * 100:.1f} %, basin test "
            f"still failed {np.mean(f[:, 1]) * 100:.1f} %, median LM iterations "
            f"{np.median(f[:, 2]):.0f}"
        )
    return "\n".join(lines)


#: the numerics' unchecked twins the fits call, per module (swapped back by :func:`checked_numerics`)
TWINS = {
    "tunnelkit.extraction.ml.fitting": ("spatial_phase",),
    "tunnelkit.extraction.ml.lm": ("damped_solve", "damped_system", "free_newton"),
    "tunnelkit.extraction.ml.model": ("solve", "spatial_phase"),
    "tunnelkit.extraction.ml.wideband": ("solve", "spatial_phase"),
    "tunnelkit.extraction.coherent": (
        "damped_solve",
        "damped_system",
        "free_newton",
        "solve",
        "spatial_phase",
    ),
    "tunnelkit.extraction.joint": ("contract",),
    "tunnelkit.extraction.direct.aperture": ("solve", "spatial_phase"),
    "tunnelkit.extraction.direct.fit": ("spatial_phase",),
}


def checked_numerics(fn):
    """``fn()`` with the fits calling the checked public numerics instead of their unchecked
    twins (the route before the twins: the same arithmetic, every call's finiteness checks)."""
    import importlib

    from tunnelkit.extraction import linalg, numerics

    saved = []
    try:
        for mod, names in TWINS.items():
            m = importlib.import_module(mod)
            for n in names:
                saved.append((m, f"{n}_unchecked", getattr(m, f"{n}_unchecked")))
                setattr(m, f"{n}_unchecked", getattr(linalg if hasattr(linalg, n) else numerics, n))
        return fn()
    finally:
        for m, n, f in saved:
            setattr(m, n, f)


def check_share(tensor, label: str) -> str:
    """The share of one default extraction of ``tensor = (H, array, config, L)`` (one BLAS
    thread, after a warm-up) spent in the numerics' argument checks, profiled, with the fits
    calling the unchecked twins and calling the checked functions (:func:`checked_numerics`); a
    load-independent measure of what the twins save (profiling inflates the Python-level share)."""
    import cProfile
    import pstats

    H, arr, cfg, L = tensor

    def run():
        return extraction.extract_paths(H, L, arr, cfg)

    lines = [f"argument checks of extraction.numerics in one extraction ({label}, profiled)"]
    with threadpool_limits(1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run()
        for name, fn in (("twins", run), ("checked", lambda: checked_numerics(run))):
            pr = cProfile.Profile()
            pr.enable()
            fn()
            pr.disable()
            st = pstats.Stats(pr)
            chk, calls = 0.0, 0
            for (f, _, fname), (_, nc, tt, ct, callers) in st.stats.items():
                if f.endswith("numerics.py") and fname in ("_finite", "_square"):
                    chk += ct
                if f.endswith("numerics.py") and fname == "_masks":
                    chk += tt
                if f.endswith("_validate.py") and any(
                    c[0].endswith("numerics.py") for c in callers
                ):
                    chk += ct
                if f.endswith("numerics.py") and fname in TWIN_NAMES:
                    calls += nc
            lines.append(
                f"  {name:8s} {st.total_tt * 1e3:6.0f} ms profiled, checks {chk * 1e3:5.1f} ms "
                f"({100 * chk / st.total_tt:.1f} %), calls of the checked numerics {calls}"
            )
    return "\n".join(lines)


TWIN_NAMES = ("solve", "free_newton", "damped_step", "spatial_phase", "contract")


def cpu_times(repeat: int = 15) -> str:
    """Median process (CPU) time of the default extraction and of the CPD + coherent route on
    bench_extraction's tensor, one BLAS thread, interleaved: on a shared machine the wall-clock
    medians of ``cases`` grow with the load, the CPU times much less."""
    H, arr, cfg, L = _tensor()
    args = (arr, cfg)
    out = {"default": [], "coherent": [], "cpd": []}
    with threadpool_limits(1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        extraction.extract_paths(H, L, *args)  # warm-up (scan grid cache)
        for _ in range(repeat):
            for key, fn in (
                ("default", lambda: extraction.extract_paths(H, L, *args)),
                ("coherent", lambda: extraction.extract_paths(H, L, *args, refine="coherent")),
                ("cpd", lambda: extraction.cpd(H, L, element_positions=arr.local)),
            ):
                t = time.process_time()
                fn()
                out[key].append(time.process_time() - t)
    med = {k: float(np.median(v)) for k, v in out.items()}
    return (
        f"CPU time per extraction (L = {L}, M = {H.shape[0]}, Nf = {H.shape[1]}, "
        f"Nt = {H.shape[2]}, median of {repeat}): default {med['default'] * 1e3:.0f} ms, "
        f"CPD + coherent {med['coherent'] * 1e3:.0f} ms (ratio "
        f"{med['default'] / med['coherent']:.2f}), CPD alone {med['cpd'] * 1e3:.0f} ms; goal 250 ms"
    )


def report(n_snapshots: int | None = None) -> str:
    n = n_snapshots or int(os.environ.get("TUNNELKIT_BENCH_SNAPSHOTS", 200))
    with threadpool_limits(1):
        res = study(n)
    return (
        cpu_times()
        + f"\nRMS(error / CRLB) and share beyond 6 sigma, {n} random scenes + {n} tunnel epochs "
        f"({res['seconds']:.0f} s, load {os.getloadavg()[0]:.1f})\n" + table(res)
    )


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--snapshots", type=int, default=200)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--save", default=None, help="write the normalised errors to this .npz")
    ap.add_argument("--cpu", action="store_true", help="also the CPU times of the extraction")
    a = ap.parse_args()
    if a.cpu:
        print(cpu_times())
    if a.snapshots > 0:
        with threadpool_limits(1):
            r = study(a.snapshots, a.seed)
        print(
            f"{a.snapshots} + {a.snapshots} snapshots, {r['seconds']:.0f} s, "
            f"load {os.getloadavg()[0]:.1f}"
        )
        print(table(r))
        if a.save:
            np.savez(a.save, **{k.replace(" ", "_"): v for k, v in r["errors"].items()})
