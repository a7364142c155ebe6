"""What the first-order model leaves in the ray-traced tensor, component by component.

The extraction's residual test flags every ray-traced epoch. This benchmark measures which rays
carry that residual. Per epoch it traces the paths afresh (:meth:`tunnelkit.rt.RayTracedChannel.trace`)
and splits the noiseless tensor (transmit power included, noise power ``N0`` of the radio) into

* the parts of :func:`tunnelkit.rt.tensor_components`: ``diffuse``, ``specular2+``, the
  spatial-wideband term of the first-order paths (``wideband``), the change of a path's gain
  across the array (``element_gain``: 1/distance, the reflection coefficient's change with the
  incidence angle, the polarisation projection) and of its Doppler shift (``element_doppler``),
  beside ``first_order_model`` (each first-order path with the reference element's gain, delay
  and Doppler);
* ``visibility``: ``first_order_model`` minus its least-squares fit by the image method's eq. 1
  atoms of the same paths (:func:`tunnelkit.channel.channel_tensor`, a free complex gain per
  path). A sign or reference mismatch between the two conventions would show here; so does a
  first-order path that only part of the array sees (the specular point leaves a finite facet
  or road marking across the aperture; no diffraction is traced, so the field is cut at the
  shadow boundary), a facet's path the image method does not list at the reference element, and
  any other difference between the traced paths and the image method's. Per first-order path
  the benchmark prints how many elements see it and the normalised correlation of its tensor
  (as traced) with the best image-method atom, and the first-order paths the reference element
  does not see (the image method does not list them).

For each: its power per sample over ``N0``, and the largest peak of its single-path periodogram
in noise units (:func:`tunnelkit.extraction.ml.residual.residual_peak`, the statistic of the
extraction's residual test; the threshold at its false-alarm rate is printed). Then the residual
the first-order model leaves at the **true** parameters (the full tensor minus its least-squares
fit by the image method's first-order atoms) and the same residual with each part of
:func:`tunnelkit.rt.tensor_components` removed from the tensor, one at a time, and all of them.

    python benchmarks/bench_rt_residual.py --epochs 0 12 24 28
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.channel import channel_tensor
from tunnelkit.extraction.ml.residual import calibrated_threshold, residual_peak
from tunnelkit.rt import COMPONENTS as RT_COMPONENTS
from tunnelkit.rt import element_tensor, first_order_groups
from tunnelkit.signal_route import SignalRoute

COMPONENTS = (*RT_COMPONENTS, "visibility")


def components(route: SignalRoute, k: int) -> dict:
    """The noiseless tensors of epoch ``k`` (module docstring), transmit power included."""
    cfg = route.config
    arr, H, ep, trace_s = route.raytraced.components(k, amplitude=np.sqrt(cfg.tx_power))
    _, paths = route.paths(k)
    atoms = np.stack([channel_tensor([p], cfg).ravel() for p in paths], axis=1)
    model = H["first_order_model"].ravel()
    H["visibility"] = (model - _project(atoms, model)).reshape(H["full"].shape)
    eng = route.raytraced.engine()
    groups = []
    for g in first_order_groups(ep):
        h = (
            np.sqrt(cfg.tx_power)
            * element_tensor(
                ep,
                cfg.tone_spacing,
                cfg.n_tones,
                cfg.symbol_period,
                cfg.n_symbols,
                select=g["select"],
            ).ravel()
        )
        cor = np.abs(atoms.conj().T @ h) / np.linalg.norm(atoms, axis=0) / np.linalg.norm(h)
        groups.append(
            {
                "surface": eng.surface_of(g["first_object"])[0] if g["order"] else "los",
                "elements": g["count"],
                "corr": float(cor.max()),
                "power_N0": float(np.mean(np.abs(h) ** 2) / cfg.noise_power),
            }
        )
    return {
        "array": arr,
        "paths": paths,
        "atoms": atoms,
        "H": H,
        "trace_s": trace_s,
        "groups": groups,
    }


def _project(atoms: np.ndarray, h: np.ndarray) -> np.ndarray:
    c, *_ = np.linalg.lstsq(atoms, h, rcond=None)
    return atoms @ c


def study(route: SignalRoute, k: int) -> dict:
    cfg = route.config
    c = components(route, k)
    n0 = cfg.noise_power
    pos = c["array"].local
    out = {"k": k, "trace_s": c["trace_s"], "L": len(c["paths"]), "groups": c["groups"]}
    H = c["H"]
    for name in COMPONENTS:
        out[name] = (
            float(np.mean(np.abs(H[name]) ** 2) / n0),
            residual_peak(H[name], pos, cfg.fc, n0)[0],
        )
    full = H["full"].ravel()

    def resid(h):
        r = (h - _project(c["atoms"], h)).reshape(H["full"].shape)
        return float(np.mean(np.abs(r) ** 2) / n0), residual_peak(r, pos, cfg.fc, n0)[0]

    out["residual"] = {"none removed": resid(full)}
    for name in RT_COMPONENTS:
        out["residual"][f"-{name}"] = resid(full - H[name].ravel())
    allr = full - sum(H[n].ravel() for n in RT_COMPONENTS)
    out["residual"]["-all five"] = resid(allr)
    out["threshold"] = calibrated_threshold(pos, cfg.fc, H["full"].shape)
    out["signal"] = float(np.mean(np.abs(full) ** 2) / n0)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="italiano2026-straight")
    ap.add_argument("--epochs", type=int, nargs="+", default=[0, 12, 24, 28])
    a = ap.parse_args(argv)
    route = SignalRoute.from_scenario(a.scenario, channel="sionna")
    for k in a.epochs:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = study(route, k)
        print(
            f"{a.scenario} epoch {k}: trace {s['trace_s']:.2f} s, L = {s['L']} first-order paths, "
            f"signal {s['signal']:.3g} N0 per sample, residual-test threshold {s['threshold']:.1f}"
        )
        for g in s["groups"]:
            print(
                f"  first-order path {g['surface']:17s} seen by {g['elements']:3d} elements, "
                f"power {g['power_N0']:9.3g} N0/sample, best image-atom correlation {g['corr']:.4f}"
            )
        for name in COMPONENTS:
            p, pk = s[name]
            print(f"  component {name:13s} power {p:10.3g} N0/sample  periodogram peak {pk:10.3g}")
        for name, (p, pk) in s["residual"].items():
            print(
                f"  residual at the true parameters, {name:15s} power {p:10.3g} N0/sample  "
                f"peak {pk:10.3g}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
