"""The chain on the ray-traced channel: trace cost, cache size, extraction error against the bound.

For the straight and slalom drives at the preset's 10 x 10 arrays, with the scenario's
``[raytracing]`` settings (defaults: 20,000 rays, max_depth 2, scattering coefficient 0.3
Lambertian on the concrete shell and the asphalt road, smooth metal RRMs):

1. per epoch: trace time, tensor synthesis time, paths per element and power per kind of path
   (LoS, first-order specular, higher-order specular, diffuse), from the cache
   (:class:`tunnelkit.rt.RayTracedChannel`, traced on a miss); the cache size per drive;
2. the extraction error (the route's own extraction, ``L`` = the image method's first-order
   paths) of the delay ``d`` and direction of each true first-order path, over the CRLB standard
   deviation (:func:`tunnelkit.extraction.path_crlb`), on both channels from the same draws.
   On the ray-traced channel the bound is also given with the noise floor raised by the power the
   model leaves out, ``N0' = N0 + P_t P_diffuse`` (diffuse only) and ``N0 + P_t (P_diffuse +
   P_specular2+)`` (every unmodelled path), with the mean power per element of those paths:
   their sum over many paths of random phase acts on each tensor entry like noise of that power
   (white across tones and elements for the diffuse part; the higher-order specular paths are
   not white, so the second bound is optimistic about what they cost). Routes (``--routes``):
   ``image``, ``sionna`` (first-order model), ``sionna_floor`` (the same, its fit tested against
   noise + diffuse power, ``RouteOptions(diffuse_floor=True)``), ``sionna_2nd`` (the model also
   carries the ``--second-order`` strongest second-order images, ``RouteOptions(second_order=N)``;
   the bound is then the whole model's CRLB) and ``sionna_2nd_floor`` (both). Also the draws each route's extraction flags (``fit_ok`` False), per epoch,
   the number of paths each route extracted and its seconds per epoch.
3. the tensor synthesis from the traced paths (:func:`tunnelkit.rt.element_tensor`): the
   direct path-by-path sum against the non-uniform FFT (``method="nufft"``, ``eps=1e-9``), on
   ``--synthesis-epochs`` epochs traced afresh per drive (not from the cache, which keeps only the
   tensor): median seconds per epoch of each, their ratio per epoch, and the relative error.

    TUNNELKIT_RT_CACHE=/tmp/rt python benchmarks/bench_rt_channel.py --epochs-every 4 --draws 3
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit import evaluation, extraction
from tunnelkit.constants import C
from tunnelkit.montecarlo import spawn_rngs
from tunnelkit.propagation import SECOND_ORDER
from tunnelkit.signal_route import SignalRoute

DRIVES = ("italiano2026-straight", "italiano2026-slalom")


def trace_costs(route) -> dict:
    """Per-epoch trace/synthesis times, path counts and powers of ``route``'s ray-traced channel."""
    rc = route.raytraced
    t0 = time.perf_counter()
    st = rc.prepare(progress=False)
    eps = [rc.epoch(k) for k in range(len(route.trajectory))]
    return {
        "epochs": len(eps),
        "newly_traced": st["traced"],
        "wall_s": time.perf_counter() - t0,
        "trace_s": [e["trace_s"] for e in eps],
        "synth_s": [e["synth_s"] for e in eps],
        "cache_bytes": st["bytes"],
        "power": [e["power"] for e in eps],
        "count": [e["count"] for e in eps],
    }


def synthesis_speed(route, n_epochs: int) -> dict:
    """Direct sum vs NUFFT on ``n_epochs`` epochs spread over the drive, traced afresh."""
    from tunnelkit.rt import element_tensor

    rc, cfg = route.raytraced, route.config
    ks = np.linspace(0, len(route.trajectory) - 1, n_epochs).round().astype(int)
    out = {"epochs": ks.tolist(), "direct_s": [], "nufft_s": [], "rel_error": [], "paths": []}
    for k in ks:
        _, ep, _ = rc.trace(int(k))
        sel = ep.valid & (ep.order > 0)
        args = (ep, cfg.tone_spacing, cfg.n_tones, cfg.symbol_period, cfg.n_symbols)
        H = {}
        for method in ("direct", "nufft"):
            t0 = time.perf_counter()
            H[method] = element_tensor(*args, select=sel, method=method)
            out[f"{method}_s"].append(time.perf_counter() - t0)
        ref = np.linalg.norm(H["direct"])
        out["rel_error"].append(float(np.linalg.norm(H["nufft"] - H["direct"]) / ref))
        out["paths"].append(float(sel.sum() / ep.M))
    return out


def _errors(ep, config, snr_offset_db=0.0) -> np.ndarray:
    """|error| / CRLB of the first-order paths of ``ep`` (the bound of the route's whole model:
    with second-order nuisance paths in it, they are in the Fisher information too)."""
    src = np.stack([ep.array.to_local(p.source) for p in ep.paths])
    d_true = np.array([p.length for p in ep.paths]) + C * ep.snapshot.clock_bias
    v_true = np.array([p.velocity for p in ep.paths])
    bound = extraction.path_crlb(ep.paths, ep.array, config, snr_offset_db=snr_offset_db)
    e = evaluation.normalized_errors(ep.estimates, d_true, v_true, src, bound)
    return e[[p.kind != SECOND_ORDER for p in ep.paths]]


ROUTES = (
    "image",
    "sionna",
    "sionna_floor",
    "sionna_2nd",
    "sionna_2nd_floor",
)


def extraction_study(
    name: str,
    every: int,
    draws: int,
    seed: int,
    second_order: int,
    which=ROUTES,
    epochs=None,
) -> dict:
    """Normalised errors of the first-order paths on both channels (same rng per draw), and on
    the ray-traced channel with ``second_order`` second-order paths in the model; the share of
    draws each route's extraction flags (``fit_ok`` False), also with the fit tested against
    noise + diffuse power (``diffuse_floor``)."""
    img = SignalRoute.from_scenario(name)
    srt = SignalRoute.from_scenario(name, channel="sionna")
    srt2 = srt.with_options(second_order=second_order)
    routes = {
        "image": img,
        "sionna": srt,
        "sionna_floor": srt.with_options(diffuse_floor=True),
        "sionna_2nd": srt2,
        "sionna_2nd_floor": srt2.with_options(diffuse_floor=True),
    }
    routes = {key: r for key, r in routes.items() if key in which}
    ks = list(range(0, len(img.trajectory), every)) if epochs is None else list(epochs)
    cfg = img.config
    out: dict[str, list] = {}
    flagged = dict.fromkeys(routes, 0)
    per_epoch = {key: dict.fromkeys(ks, 0) for key in routes}
    n_paths = {key: [] for key in routes}
    seconds = {key: [] for key in routes}
    n_second = []
    kinds: list[str] = []
    for i, rng in enumerate(spawn_rngs(seed, len(ks) * draws)):
        k = ks[i // draws]
        state = rng.bit_generator.state
        eps = {}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for key, route in routes.items():
                rng.bit_generator.state = state
                t0 = time.perf_counter()
                eps[key] = route.epoch(k, rng)
                seconds[key].append(time.perf_counter() - t0)
                bad = eps[key].estimates.fit_ok is False
                flagged[key] += bad
                per_epoch[key][k] += bad
                n_paths[key].append(len(eps[key].estimates))
        two = [e for key, e in eps.items() if "2nd" in key]
        n_second.append(sum(p.kind == SECOND_ORDER for p in two[0].paths) if two else 0)
        pw = srt.raytraced.epoch(k)["power"]
        n0 = cfg.noise_power
        floors = {
            "diffuse_floor": n0 + cfg.tx_power * pw["diffuse"],
            "all_floor": n0 + cfg.tx_power * (pw["diffuse"] + pw["specular2+"]),
        }
        for key, ep in eps.items():
            out.setdefault(key, []).append(_errors(ep, cfg))
            if key == "image":
                continue
            for fkey, n in floors.items():
                if fkey == "all_floor" and "2nd" in key:
                    continue  # the second-order power is in the model, not the floor
                out.setdefault(f"{key}+{fkey}", []).append(
                    _errors(ep, cfg, snr_offset_db=-10 * np.log10(n / n0))
                )
        kinds += [p.surface_kind for p in next(iter(eps.values())).paths if p.kind != SECOND_ORDER]
    res = {key: np.concatenate(v) for key, v in out.items()}
    return {
        "errors": res,
        "kinds": np.array(kinds),
        "epochs": ks,
        "draws": draws,
        "flagged": flagged,
        "flagged_per_epoch": per_epoch,
        "paths_extracted": n_paths,
        "seconds": seconds,
        "n": len(ks) * draws,
        "second_order_paths": n_second,
    }


def _summary(e: np.ndarray) -> dict:
    """Median and RMS of |error| / CRLB over the paths found, the fraction missed."""
    found = np.isfinite(e)
    f = e[found]
    return {
        "n": int(e.size),
        "missed": float(1 - found.mean()) if e.size else float("nan"),
        "median": float(np.median(np.abs(f))) if f.size else float("nan"),
        "rms": float(np.sqrt(np.mean(f**2))) if f.size else float("nan"),
    }


def report(costs: dict, studies: dict, synth: dict | None = None) -> str:
    lines = []
    for name, s in (synth or {}).items():
        d, n = np.array(s["direct_s"]), np.array(s["nufft_s"])
        lines.append(
            f"{name}: synthesis on {len(d)} epochs ({np.median(s['paths']):.0f} paths/element): "
            f"direct median {np.median(d):.2f} s, NUFFT median {np.median(n):.3f} s, speed-up "
            f"median {np.median(d / n):.0f}x, relative error max {max(s['rel_error']):.1e}"
        )
    for name, c in costs.items():
        p = {k: np.array([x[k] for x in c["power"]]) for k in c["power"][0]}
        tot = sum(p.values())
        lines.append(
            f"{name}: {c['epochs']} epochs, trace median {np.median(c['trace_s']):.2f} s/epoch "
            f"(IQR {np.percentile(c['trace_s'], 25):.2f}-{np.percentile(c['trace_s'], 75):.2f}), "
            f"tensor synthesis median {np.median(c['synth_s']):.2f} s/epoch, cache "
            f"{c['cache_bytes'] / 1e6:.1f} MB, paths/element median "
            f"{np.median([sum(x.values()) for x in c['count']]):.0f}"
        )
        lines.append(
            "  power share per epoch (median [min, max]): "
            + ", ".join(
                f"{k} {np.median(v / tot):.3f} [{np.min(v / tot):.3f}, {np.max(v / tot):.3f}]"
                for k, v in p.items()
            )
        )
    for name, st in studies.items():
        lines.append(
            f"{name}: epochs flagged by the extraction's own fit test (fit_ok False) of "
            f"{st['n']} draws: "
            + ", ".join(f"{k} {v}" for k, v in st["flagged"].items())
            + f"; second-order paths in the model per epoch: median "
            f"{np.median(st['second_order_paths']):.0f}"
        )
        for key in st["flagged"]:
            lines.append(
                f"  {key}: flagged share per epoch "
                + " ".join(
                    f"{k}:{v / st['draws']:.2f}" for k, v in st["flagged_per_epoch"][key].items()
                )
                + f"; paths extracted median {np.median(st['paths_extracted'][key]):.0f} "
                f"[{min(st['paths_extracted'][key])}, {max(st['paths_extracted'][key])}]; "
                f"seconds per epoch median {np.median(st['seconds'][key]):.1f}"
            )
        lines.append(f"{name}: |error| / CRLB of the first-order paths (median / RMS, missed)")
        for col, label in ((0, "d"), (2, "direction")):
            for key, e in st["errors"].items():
                for kind in ["all", *sorted(set(st["kinds"]))]:
                    sel = np.ones(len(st["kinds"]), bool) if kind == "all" else st["kinds"] == kind
                    s = _summary(e[sel, col])
                    lines.append(
                        f"  {label:9s} {key:22s} {kind:8s} n={s['n']:3d} median {s['median']:10.2f}"
                        f"  RMS {s['rms']:10.2f}  missed {s['missed']:.2f}"
                    )
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--epochs-every", type=int, default=4)
    ap.add_argument("--draws", type=int, default=3)
    ap.add_argument("--seed", type=int, default=26)
    ap.add_argument("--synthesis-epochs", type=int, default=3)
    ap.add_argument(
        "--second-order", type=int, default=8, help="second-order paths in the model (strongest)"
    )
    ap.add_argument(
        "--only",
        choices=("all", "synthesis", "extraction"),
        default="all",
        help="synthesis: item 3 alone; extraction: item 2 alone (epochs from the cache)",
    )
    ap.add_argument("--drives", nargs="+", default=list(DRIVES), choices=DRIVES)
    ap.add_argument("--routes", nargs="+", default=list(ROUTES), choices=ROUTES)
    ap.add_argument("--epochs", type=int, nargs="+", default=None, help="these epochs only")
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args(argv)
    synth = {
        n: synthesis_speed(SignalRoute.from_scenario(n, channel="sionna"), a.synthesis_epochs)
        for n in a.drives
        if a.only in ("all", "synthesis")
    }
    costs: dict = {}
    studies: dict = {}
    if a.only == "all":
        costs = {n: trace_costs(SignalRoute.from_scenario(n, channel="sionna")) for n in a.drives}
    if a.only in ("all", "extraction"):
        studies = {
            n: extraction_study(
                n,
                a.epochs_every,
                a.draws,
                a.seed,
                a.second_order,
                a.routes,
                a.epochs,
            )
            for n in a.drives
        }
    print(report(costs, studies, synth))
    if a.json:
        a.json.write_text(
            json.dumps(
                {
                    "synthesis": synth,
                    "costs": costs,
                    "studies": {
                        n: {
                            "epochs": s["epochs"],
                            "draws": s["draws"],
                            "flagged": s["flagged"],
                            "second_order_paths": s["second_order_paths"],
                            "kinds": s["kinds"].tolist(),
                            "errors": {
                                k: np.where(np.isfinite(v), v, -1).tolist()
                                for k, v in s["errors"].items()
                            },
                        }
                        for n, s in studies.items()
                    },
                },
                indent=1,
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
