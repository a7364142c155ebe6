"""The pair test of the maximum-likelihood stage (:func:`tunnelkit.extraction.ml.pair_test`)
checked by Monte-Carlo: its null distribution (one path fitted as a close pair, the statistic
``(cost_merged - cost) / sigma^2`` of the test as the fit computes it) and its rate of declaring
a resolvable pair unresolved (two paths ``z`` standard deviations of their difference apart).

One path at the paper's 10 x 10 URA (28 GHz), the presets' tensor (410 tones, 12 symbols, or
fewer with ``--small``), a random direction (``|u| < 0.8``), range (5-100 m), delay and Doppler;
its post-integration SNR ``snr`` (its log-likelihood ratio against noise) given; unit noise.
The two-path fit starts from the path split in two along each of the five parameters (``u_x``,
``u_y`` an eighth and a third of a beamwidth, ``mu_f``, ``mu_t`` a quarter of a bin), every
start fitted to convergence, the most likely kept (the supremum over close pairs, which is what
the search does when it counts one path twice); then :func:`ml.pair_test` on it.

``python benchmarks/bench_stress_pairs.py --draws 300 --seed S`` prints the null quantiles and
the false-alarm rate at ``PAIR_LLR``, and, with ``--resolvable``, the share of pairs declared
unresolved at separations 4-12 sd.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

from tunnelkit.arrays import ura
from tunnelkit.constants import wavelength
from tunnelkit.extraction import ml
from tunnelkit.extraction.ml.lm import lm_fit

FC = 28e9


def _path(rng, nf, nt):
    rad = 0.8 * np.sqrt(rng.uniform())
    a = rng.uniform(0, 2 * np.pi)
    th = np.array([[rad * np.cos(a), rad * np.sin(a), 1.0 / rng.uniform(5.0, 100.0)]])
    mf = rng.uniform(-np.pi, np.pi, 1)
    mt = rng.uniform(-np.pi, np.pi, 1)
    return th, mf, mt


def _tensor(rng, th, mf, mt, gains, pos, shape):
    prob0 = ml.Problem(np.ones(shape, complex), pos, FC)
    x = prob0.model(th, mf, mt, np.asarray(gains, complex))
    n = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) / np.sqrt(2)
    return ml.Problem(x + n, pos, FC)


def null_draw(rng, snr, pos, shape):
    """One draw of the null: (llr of ml.pair_test at the best close-pair fit, the same as
    cost_one - cost_two with the one-path fit started at the truth, the pair's separation)."""
    nf, nt = shape[1], shape[2]
    th, mf, mt = _path(rng, nf, nt)
    c = np.sqrt(snr / np.prod(shape)) * np.exp(2j * np.pi * rng.uniform())
    prob = _tensor(rng, th, mf, mt, [c], pos, shape)
    one = lm_fit(prob, th, mf, mt, 1.0, 100)
    t1, f1, m1 = one[:3]
    best = None
    steps = [(0.012, 0, 0, 0), (0, 0.012, 0, 0), (0.03, 0, 0, 0), (0, 0.03, 0, 0)]
    steps += [(0, 0, 0.5 * np.pi / nf, 0), (0, 0, 0, 0.5 * np.pi / nt)]
    for s in steps:
        d = np.array(s)
        th2 = np.vstack([t1, t1])
        th2[0, :2] += d[:2]
        th2[1, :2] -= d[:2]
        f2 = np.array([f1[0] + d[2], f1[0] - d[2]])
        m2 = np.array([m1[0] + d[3], m1[0] - d[3]])
        two = lm_fit(prob, ml.project_feasible(th2), f2, m2, 1.0, 100)
        if best is None or two[3]["cost"] < best[3]["cost"]:
            best = two
    rows = ml.pair_test(prob, best[0], best[1], best[2], 1.0, z_max=np.inf)
    z = ml.separations(prob, best[0], best[1], best[2], 1.0)[0]
    llr = rows[0, 3] if len(rows) else np.inf
    return llr, (one[3]["cost"] - best[3]["cost"]), z


def resolvable_draw(rng, snr, z_target, pos, shape):
    """Two paths of equal SNR ``snr`` about ``z_target`` standard deviations apart (the second
    offset from the first along a random direction of ``(u_x, u_y, mu_f, mu_t)``, scaled by
    bisection to the first separation ``z_target`` along it, Fisher information of the
    noise-free tensor at the truth); the fit started at the truth; (llr, z at the fit)."""
    th, mf, mt = _path(rng, shape[1], shape[2])
    N = np.prod(shape)
    c = np.sqrt(snr / N) * np.exp(2j * np.pi * rng.uniform(0, 1, 2))
    prob0 = ml.Problem(np.ones(shape, complex), pos, FC)
    d = rng.standard_normal(5)
    d[2] = 0.0  # same curvature
    scale = np.array([0.01, 0.01, 0.0, 2 * np.pi / shape[1], 2 * np.pi / shape[2]])
    d = 0.05 * d * scale

    def pair(t):
        th2 = np.vstack([th, th + t * d[:3]])
        return th2, np.append(mf, mf + t * d[3]), np.append(mt, mt + t * d[4])

    def z_at(t):  # noise-free Fisher information at the truth
        th2, f2, m2 = pair(t)
        clean = ml.Problem(prob0.model(th2, f2, m2, c), pos, FC)
        return ml.separations(clean, th2, f2, m2, 1.0)[0]

    lo, hi = 0.0, 1.0
    while z_at(hi) < z_target and hi < 2**20:  # first crossing (z is not monotone further out)
        lo, hi = hi, 2 * hi
    for _ in range(12):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if z_at(mid) < z_target else (lo, mid)
    th2, f2, m2 = pair(hi)
    prob = _tensor(rng, th2, f2, m2, c, pos, shape)
    fit = lm_fit(prob, ml.project_feasible(th2), f2, m2, 1.0, 100)
    rows = ml.pair_test(prob, fit[0], fit[1], fit[2], 1.0)
    zf = ml.separations(prob, fit[0], fit[1], fit[2], 1.0)[0]
    return (rows[0, 3] if len(rows) else np.inf), zf


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=200)
    ap.add_argument("--seed", type=int, default=23)
    ap.add_argument("--snr", type=float, nargs="+", default=[100.0, 1e4])
    ap.add_argument("--small", action="store_true", help="64 tones, 12 symbols")
    ap.add_argument("--resolvable", action="store_true")
    ap.add_argument("--out", default=None, help="save the draws (.npz)")
    a = ap.parse_args()
    pos = ura(10, 10, wavelength(FC) / 2)
    shape = (100, 64 if a.small else 410, 12)
    rng = np.random.default_rng(a.seed)
    t0 = time.perf_counter()
    with threadpool_limits(1):
        for snr in a.snr:
            if not a.resolvable:
                out = np.array([null_draw(rng, snr, pos, shape) for _ in range(a.draws)])
                if a.out:
                    np.save(f"{a.out}-null-snr{snr:g}.npy", out)
                llr = out[:, 0]
                q = np.quantile(llr[np.isfinite(llr)], [0.5, 0.9, 0.95, 0.99])
                fa = np.mean(llr >= ml.PAIR_LLR)
                k = int(np.sum(llr >= ml.PAIR_LLR))
                print(
                    f"null, snr {snr:g}, shape {shape}, {a.draws} draws, seed {a.seed}: llr "
                    f"quantiles 50/90/95/99 % "
                    + " ".join(f"{x:.2f}" for x in q)
                    + f"; mean {np.mean(llr):.2f}; at PAIR_LLR = {ml.PAIR_LLR:g}: {k} "
                    f"declared resolved ({100 * fa:.1f} %); pair z median "
                    f"{np.median(out[:, 2]):.2f}; llr vs one-path-at-truth max |diff| "
                    f"{np.max(np.abs(out[:, 0] - out[:, 1])):.3g} ({time.perf_counter() - t0:.0f} s)",
                    flush=True,
                )
            else:
                for zt in (4.0, 5.0, 6.0, 8.0, 12.0):
                    out = np.array(
                        [resolvable_draw(rng, snr, zt, pos, shape) for _ in range(a.draws)]
                    )
                    if a.out:
                        np.save(f"{a.out}-two-snr{snr:g}-z{zt:g}.npy", out)
                    un = np.mean(out[:, 0] < ml.PAIR_LLR)
                    print(
                        f"two paths, snr {snr:g} each, z at the truth {zt:g}: declared "
                        f"unresolved {100 * un:.1f} % of {a.draws}; llr median "
                        f"{np.median(out[:, 0]):.1f}; z at the fit median {np.median(out[:, 1]):.1f}"
                        f" ({time.perf_counter() - t0:.0f} s)",
                        flush=True,
                    )


if __name__ == "__main__":
    sys.exit(main())
