"""What a diffuse atom costs the direct fit's position where it is not needed: the Cramer-Rao
bound of ``(x, y, b)`` with one diffuse atom at a given delay past the line of sight over the bound
without it, on the direct model's own noiseless tensor (the paper's 10 x 10, 410 tones, 12
symbols, ``italiano2026-straight``). The concentrated cost's Hessian at the truth (central
differences) is the Fisher information up to the noise's factor, the gains (and the diffuse
atom's per-element gains) eliminated; the ratio of the square roots of its inverse's diagonals
is the bound's growth.

    python benchmarks/bench_direct_diffuse_info.py --epochs 9 20 --delays 0 0.6 1.5 3 20
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tunnelkit.constants import C
from tunnelkit.extraction.direct.fit import DirectProblem, image_maps
from tunnelkit.extraction.direct.visibility import predicted_model
from tunnelkit.extraction.numerics import spatial_phase
from tunnelkit.signal_route import SignalRoute


def _hessian(f, x, h=2e-3) -> np.ndarray:
    n = len(x)
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(i, n):
            ei, ej = np.eye(n)[i] * h, np.eye(n)[j] * h
            out[i, j] = out[j, i] = (
                f(x + ei + ej) - f(x + ei - ej) - f(x - ei + ej) + f(x - ei - ej)
            ) / (4 * h * h)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--epochs", type=int, nargs="+", default=[9, 20])
    ap.add_argument("--delays", type=float, nargs="+", default=[0.0, 0.6, 1.5, 3.0, 20.0])
    ap.add_argument("--seed", type=int, default=5)
    a = ap.parse_args(argv)
    print(
        "command: python benchmarks/bench_direct_diffuse_info.py "
        + shlex.join(argv or sys.argv[1:])
    )
    route = SignalRoute.from_scenario("italiano2026-straight")
    cfg, rng = route.config, np.random.default_rng(a.seed)
    print("| epoch | diffuse atom past the line of sight [m] | bound growth x / y / b |")
    print("| --- | --- | --- |")
    for k in a.epochs:
        arr = route.paths(k)[0]
        ue, vel = route.trajectory.position[k], route.trajectory.velocity[k]
        paths, masks, _ = predicted_model(route, arr, ue, vel, 4)
        maps = image_maps(route.tunnel, paths)
        gains = np.array([abs(p.gain) for p in paths]) * np.exp(2j * np.pi * rng.random(len(paths)))
        shell = DirectProblem(np.ones((arr.M, 410, 12), complex), arr, cfg, masks, maps, ue[2], vel)
        x = np.r_[ue[:2], 0.4]
        theta, mu_f, mu_t = shell.atoms(x)
        a_ = np.exp(1j * spatial_phase(theta, shell.pos, shell.k0)[0]) * shell.mask * gains
        H = np.einsum(
            "ml,sl,kl->msk", a_, np.exp(1j * shell.s * mu_f), np.exp(1j * shell.kk * mu_t)
        )
        prob = DirectProblem(H, arr, cfg, masks, maps, ue[2], vel)
        base = np.diag(np.linalg.inv(_hessian(prob.cost, x)))
        one = prob.with_diffuse(1)
        for dm in a.delays:
            nu = (mu_f[0] - 2 * np.pi * cfg.tone_spacing * dm / C, mu_t[0] + 0.01)
            d = np.diag(np.linalg.inv(_hessian(lambda z, nu=nu, p=one: p.cost(np.r_[z, nu]), x)))
            r = np.sqrt(d / base)
            print(f"| {k} | {dm:g} | {r[0]:.2f} / {r[1]:.2f} / {r[2]:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
