"""What modelling the spatial-wideband term removes from the first-order bias on the traced channel.

Per epoch the traced noiseless tensor (transmit power included) is split by what eq. 1 leaves out
(:meth:`tunnelkit.rt.RayTracedChannel.components`); five tensors are fitted from the true
first-order paths (no re-seeding, converged far below the noise):

* ``image`` / ``image + wideband``: eq. 1 of the image method's paths (the check) and the same with
  the spatial-wideband term (:func:`tunnelkit.channel.channel_tensor`): the term alone, no other
  model error;
* ``eq.1 part``: the first-order paths as eq. 1's atoms (the check: both models land on the truth);
* ``+ wideband``: that plus the spatial-wideband term (the term alone);
* ``full``: the whole traced tensor (second-order and diffuse paths, per-element gains too);

each by the eq. 1 model (:func:`tunnelkit.studies.misspecified.pseudo_true`: its pseudo-true
paths) and by the model with the spatial-wideband term (the ML option ``wideband=True``,
:class:`tunnelkit.extraction.ml.WidebandProblem`, fitted by
:func:`tunnelkit.extraction.ml.fit_problem` from the same start). Printed: per path the delay
bias ``d_0 - d`` [cm] of each model on each tensor, and the CRLB standard deviation of the delay.

    python benchmarks/bench_rt_wideband.py --scenario italiano2026-straight --epochs 0 12 24
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.channel import channel_tensor
from tunnelkit.constants import C
from tunnelkit.extraction import ml_truth
from tunnelkit.extraction.ml import WidebandProblem, fit_problem
from tunnelkit.signal_route import SignalRoute
from tunnelkit.studies.misspecified import pseudo_true


def wideband_pseudo_true(H, pos, cfg, start, n0):
    prob = WidebandProblem(H, pos, cfg.fc, cfg.tone_spacing)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = fit_problem(prob, start, noise_power=0.01 * n0, max_iter=400, n_reseed=0)
    return start[1] + np.angle(np.exp(1j * (f.mu_f - start[1])))


def study(route: SignalRoute, k: int) -> dict:
    cfg = route.config
    n0 = cfg.noise_power
    arr, paths = route.paths(k)
    t0 = time.perf_counter()
    _arr, parts, _, _ = route.raytraced.components(k, amplitude=float(np.sqrt(cfg.tx_power)))
    trace_s = time.perf_counter() - t0
    eq1 = parts["first_order_model"]
    tensors = {
        "image": channel_tensor(paths, cfg),
        "image + wideband": channel_tensor(paths, cfg, spatial_wideband=True),
        "eq.1 part": eq1,
        "+ wideband": eq1 + parts["wideband"],
        "full": parts["full"],
    }
    truth = ml_truth(paths, arr, cfg)
    dm = C / (2 * np.pi * cfg.tone_spacing)
    out = {"k": k, "kinds": [p.surface_kind for p in paths], "trace_s": trace_s}
    out["los"] = next((i for i, p in enumerate(paths) if p.kind == "los"), 0)
    for label, H in tensors.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pt = pseudo_true(H, arr.local, cfg.fc, truth, noise_power=n0, newton_iter=20)
        out[(label, "eq.1")] = -(pt["mu_f"] - truth[1]) * dm
        out[(label, "wideband")] = (
            -(wideband_pseudo_true(H, arr.local, cfg, truth, n0) - truth[1]) * dm
        )
    return out


def image_only(route: SignalRoute, k: int) -> dict:
    """The ``image`` / ``image + wideband`` rows of :func:`study` alone (no trace)."""
    cfg = route.config
    arr, paths = route.paths(k)
    truth = ml_truth(paths, arr, cfg)
    dm = C / (2 * np.pi * cfg.tone_spacing)
    out = {"k": k, "kinds": [p.surface_kind for p in paths], "trace_s": 0.0}
    out["los"] = next((i for i, p in enumerate(paths) if p.kind == "los"), 0)
    for label, wb in (("image", False), ("image + wideband", True)):
        H = channel_tensor(paths, cfg, spatial_wideband=wb)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pt = pseudo_true(
                H, arr.local, cfg.fc, truth, noise_power=cfg.noise_power, newton_iter=20
            )
        out[(label, "eq.1")] = -(pt["mu_f"] - truth[1]) * dm
        out[(label, "wideband")] = (
            -(wideband_pseudo_true(H, arr.local, cfg, truth, cfg.noise_power) - truth[1]) * dm
        )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--epochs", type=int, nargs="+", default=[0, 12, 24])
    ap.add_argument("--image-only", action="store_true", help="the image rows alone (no trace)")
    a = ap.parse_args(argv)
    route = SignalRoute.from_scenario(a.scenario, channel="sionna")
    labels = ("image", "image + wideband")
    if not a.image_only:
        labels += ("eq.1 part", "+ wideband", "full")
    for k in a.epochs:
        t0 = time.perf_counter()
        s = image_only(route, k) if a.image_only else study(route, k)
        print(
            f"{a.scenario} epoch {k}: {time.perf_counter() - t0:.0f} s (trace {s['trace_s']:.1f} s)"
        )
        for j, kind in enumerate(s["kinds"]):
            cells = [
                f"{lab}: eq.1 {100 * s[(lab, 'eq.1')][j]:+7.2f} / wb {100 * s[(lab, 'wideband')][j]:+7.2f}"
                for lab in labels
            ]
            print(f"  path {j} {kind:8s} bias cm  " + " | ".join(cells))
        for lab in [x for x in labels if x != "image" and x != "eq.1 part"]:
            e1, wb = np.abs(s[(lab, "eq.1")]), np.abs(s[(lab, "wideband")])
            print(
                f"  {lab}: mean |bias| eq.1 model {100 * e1.mean():.2f} cm, wideband model "
                f"{100 * wb.mean():.2f} cm; LoS {100 * e1[s['los']]:.2f} -> {100 * wb[s['los']]:.2f} cm"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
