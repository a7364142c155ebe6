"""Notebook 03: the paper's route of ``extract_paths`` at the paper's size (M = 100, Nf = 410,
Nt = 12, L = 6); the default (maximum-likelihood) route is timed in ``bench_ml.py``.

Run single-threaded BLAS on a shared machine for stable numbers:
``OPENBLAS_NUM_THREADS=1 python benchmarks/run.py -k extraction``. The baseline is tensorly's
plain ``parafac(H, L, init="svd")`` on the full tensor (default 100 iterations, no line search).
"""

from __future__ import annotations

import warnings

import numpy as np
import tensorly as tl
from run import Case
from tensorly.decomposition import parafac

from tunnelkit import channel, extraction, propagation, signal_route
from tunnelkit.extraction import coherent


def _tensor():
    route = signal_route.SignalRoute.from_scenario("italiano2026-straight")
    arr, paths = route.paths(10)  # LoS, ceiling, road, two RRMs
    extra = propagation.trace_paths(
        route.tunnel, arr, [25.0, 2.0, 1.5], [-10.0, 0, 0], fc=route.config.fc, kinds=("los",)
    )  # a second vehicle
    paths = paths + extra
    snap = channel.synthesize(paths, route.config, np.random.default_rng(0))
    return snap.H, arr, route.config, len(paths)


def cases() -> list[Case]:
    H, arr, cfg, L = _tensor()
    args = (arr, cfg)

    def run(**kw):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return extraction.extract_paths(H, L, *args, **kw)

    def plain():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return parafac(tl.tensor(H), L, init="svd")

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = extraction.extract_paths(H, L, *args, refine="joint")

    g = "extract_paths"
    return [
        Case(
            f"resolve_coherent L={L} (after extract_paths)",
            lambda: coherent.resolve_coherent(H, est, *args),
            group=g,
            repeat=7,
        ),
        Case(
            f"extract_paths L={L}, fast + joint roots (paper)",
            lambda: run(refine="joint"),
            group=g,
            goal_s=0.1,
        ),
        Case(
            f"extract_paths L={L}, fast + eq. 13 roots",
            lambda: run(refine="none"),
            group=g,
            goal_s=0.1,
        ),
        Case(
            f"cpd L={L}, fast only",
            lambda: extraction.cpd(H, L, element_positions=arr.local),
            group=g,
        ),
        Case(
            f"tensorly parafac(init='svd') L={L}, full tensor",
            plain,
            group=g,
            baseline=True,
            repeat=3,
        ),
    ]
