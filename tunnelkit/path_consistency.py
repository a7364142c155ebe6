"""The geometry-consistency test on a signal route's epoch, with the bound at the estimate.

:func:`tunnelkit.consistency.geometry_consistency` asks whether one snapshot's paths agree with
one UE position through the tunnel's planes, each residual in standard deviations of a bound.
Here the bound is the CRLB at the estimate (:func:`bound_sigmas`: world azimuth, elevation and
range of each kept path, :func:`tunnelkit.signal_route.covariance.reported_covariance` computed whatever the
fit's own residual verdict) and, for the snapshot's statistic, its joint covariance over all
paths (:func:`joint_bound`, from :func:`joint_fisher`: the ML fit's paths are estimated together,
so their errors correlate within a path and between paths, up to 0.9 at the presets' epochs;
without it the test over-rejects on eq. 1's own channel). :func:`epoch_consistency` runs the
test on a :class:`tunnelkit.signal_route.Epoch`::

    ep = route.epoch(12, rng, refine="ml")
    res = epoch_consistency(ep, route)        # res["consistent"], res["keep"], res["r2"], ...
"""

from __future__ import annotations

import numpy as np

from ._physical import carrier
from ._validate import boolean, finite_array, instance, integer, positive, probability
from .arrays import ArrayGeometry
from .budget import check_elements
from .channel import SRSConfig
from .consistency import geometry_consistency, tunnel_planes
from .constants import C
from .extraction import PathEstimates, algorithm1
from .geometry import spherical_jacobian
from .signal_route import Epoch, SignalRoute
from .signal_route.covariance import reported_covariance

__all__ = ["bound_sigmas", "epoch_consistency", "joint_bound", "joint_fisher", "rate_interval"]


def rate_interval(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """The exact (Clopper-Pearson) confidence interval at ``level`` of a rate observed as ``k``
    events in ``n`` trials (e.g. a test's false alarms in ``n`` snapshots): the rates ``p`` for
    which ``P(X >= k | p)`` and ``P(X <= k | p)`` both exceed ``(1 - level) / 2``."""
    from scipy.stats import beta

    n = integer("n", n, minimum=1)
    k = integer("k", k, minimum=0, maximum=n)
    a = 1.0 - probability("level", level)
    lo = 0.0 if k == 0 else float(beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(1 - a / 2, k + 1, n - k))
    return lo, hi


def bound_sigmas(est, array: ArrayGeometry, config: SRSConfig, keep=None) -> np.ndarray:
    """(K, 3) CRLB standard deviations at the estimate ``est`` (a
    :class:`tunnelkit.extraction.PathEstimates`) of the world azimuth, elevation [rad] and range
    [m] of the paths ``keep`` (indices into ``est``, in their order; default the paths Algorithm 1
    keeps with its printed check ``d >= 0``, as ``PathMeasurements.source``): the route's
    reported covariance (:func:`tunnelkit.signal_route.covariance.reported_covariance`, ``judged=False``).
    Raises ``numpy.linalg.LinAlgError`` where the Fisher information is singular."""

    instance("est", est, PathEstimates)
    instance("array", array, ArrayGeometry)
    instance("config", config, SRSConfig)
    keep = algorithm1(est, 0.0) if keep is None else _keep(keep, len(est))
    if not keep.size:
        return np.zeros((0, 3))
    cov, sigma_d = reported_covariance(est, keep, array, config, judged=False)
    if cov is None:
        raise np.linalg.LinAlgError("the Fisher information is singular at the estimate")
    return np.stack([np.sqrt(cov[:, 0, 0]), np.sqrt(cov[:, 1, 1]), np.asarray(sigma_d)], -1)


def joint_fisher(
    alpha, sources, element_positions, mu_f, mu_t, n_tones, n_symbols, noise_power, fc
):
    """The Fisher information (7 L, 7 L) of eq. 1's ``L`` paths jointly, every cross term kept:
    per path ``Re alpha, Im alpha, mu_f, mu_t`` and the wave origin (3, local frame, exact
    spherical wavefront), as :func:`tunnelkit.extraction.bounds.crlb_paths` assembles it (``2 /
    N0 Re(J^H J)``, factorised over the three modes); that function keeps only each path's own
    block of the inverse, the geometry test needs the whole."""
    alpha = np.atleast_1d(finite_array("alpha", alpha, dtype=complex))
    if alpha.ndim != 1:
        raise ValueError(f"alpha: expected one complex gain per path (L,), got shape {alpha.shape}")
    L = alpha.size
    src = finite_array("sources", sources, ndim=2)
    if src.shape != (L, 3):
        raise ValueError(f"sources: expected shape ({L}, 3) (one per alpha), got {src.shape}")
    p = finite_array("element_positions", element_positions, ndim=2)
    if p.shape[0] < 2 or p.shape[1] != 3:
        raise ValueError(f"element_positions: expected shape (M >= 2, 3), got {p.shape}")
    mu_f, mu_t = finite_array("mu_f", mu_f), finite_array("mu_t", mu_t)
    if mu_f.shape != (L,) or mu_t.shape != (L,):
        raise ValueError(f"mu_f, mu_t: expected shape ({L},) each, got {mu_f.shape}, {mu_t.shape}")
    n_tones = integer("n_tones", n_tones, minimum=2)
    n_symbols = integer("n_symbols", n_symbols, minimum=2)
    check_elements("n_tones", 7 * L * n_tones, 16, "the Fisher information's tone factors")
    check_elements("n_symbols", 7 * L * n_symbols, 16, "the Fisher information's symbol factors")
    s, kk = np.arange(n_tones)[:, None], np.arange(n_symbols)[:, None]
    n0 = positive("noise_power", noise_power)
    fc = carrier("fc", fc)
    k0 = 2 * np.pi * fc / C
    rng_m = np.linalg.norm(src[None] - p[:, None], axis=-1)  # (M, L)
    if np.any(rng_m == 0):
        raise ValueError("sources: a wave origin coincides with an element")
    a = np.exp(1j * k0 * (rng_m - rng_m[0]))
    f, t = np.exp(1j * s * mu_f[None]), np.exp(1j * kk * mu_t[None])
    u = (src[None] - p[:, None]) / rng_m[..., None]
    da = 1j * k0 * a[..., None] * (u - u[:1])  # (M, L, 3)
    X, Y, Z = [], [], []
    for j, al in enumerate(alpha):
        terms = [(a[:, j], f[:, j], t[:, j]), (1j * a[:, j], f[:, j], t[:, j]),
                 (al * a[:, j], 1j * s[:, 0] * f[:, j], t[:, j]),
                 (al * a[:, j], f[:, j], 1j * kk[:, 0] * t[:, j])]  # fmt: skip
        terms += [(al * da[:, j, i], f[:, j], t[:, j]) for i in range(3)]
        for x, y, z in terms:
            X.append(x), Y.append(y), Z.append(z)
    X, Y, Z = (np.stack(v, axis=1) for v in (X, Y, Z))
    return 2.0 / n0 * ((X.conj().T @ X) * (Y.conj().T @ Y) * (Z.conj().T @ Z)).real


def joint_bound(est, array: ArrayGeometry, config: SRSConfig, keep=None) -> np.ndarray:
    """(3 K, 3 K) CRLB at the estimate ``est`` of the world azimuth, elevation [rad] and
    delay-distance ``d`` [m] of the paths ``keep`` (default Algorithm 1's, as
    :func:`bound_sigmas`), jointly (:func:`joint_fisher` inverted whole, then mapped through
    ``d = -c mu_f / (2 pi Df)`` and d(phi, psi)/d(origin)): row ``3 j + (0, 1, 2)`` is path
    ``j``'s ``(phi, psi, d)``. Its 3 x 3 blocks' diagonals are :func:`bound_sigmas` squared; the
    off-diagonal terms are the correlations within a path and between paths. Noise power and
    far-field placement as :func:`tunnelkit.extraction.estimate_crlb`. Raises
    ``numpy.linalg.LinAlgError`` where the Fisher information is singular."""

    instance("est", est, PathEstimates)
    instance("array", array, ArrayGeometry)
    instance("config", config, SRSConfig)
    keep = algorithm1(est, 0.0) if keep is None else _keep(keep, len(est))
    K = keep.size
    if not K:
        return np.zeros((0, 0))
    fit = getattr(est, "fit", None)
    n0 = fit.noise_power if fit is not None else config.noise_power
    p = array.local
    aperture = 2.0 * float(np.max(np.linalg.norm(p - p.mean(axis=0), axis=1)))
    far = max(2.0 * aperture**2 / (C / config.fc), 1.0)
    kap, d_est = est.kappa[keep], est.d[keep]
    src = est.direction[keep] * np.where(np.isfinite(kap), kap, np.maximum(d_est, far))[:, None]
    fim = joint_fisher(est.alpha[keep], src, p, est.mu_f[keep], est.mu_t[keep], config.n_tones,
                       config.n_symbols, n0, config.fc)  # fmt: skip
    dsc = 1.0 / np.sqrt(np.diag(fim))
    cov = dsc[:, None] * np.linalg.inv(dsc[:, None] * fim * dsc[None, :]) * dsc[None, :]
    if not np.all(np.isfinite(cov)):
        raise np.linalg.LinAlgError("joint_bound: Fisher information singular at the estimate")
    G = spherical_jacobian(array.dir_to_world(src))[:, :2] @ array.R  # (K, 2, 3) local origin
    A = np.zeros((3 * K, 7 * K))
    for j in range(K):
        A[3 * j : 3 * j + 2, 7 * j + 4 : 7 * j + 7] = G[j]
        A[3 * j + 2, 7 * j + 2] = -C / (2 * np.pi * config.tone_spacing)
    out = A @ cov @ A.T
    out = 0.5 * (out + out.T)
    if np.any(np.linalg.eigvalsh(out) <= 0):
        raise np.linalg.LinAlgError("joint_bound: covariance not positive definite at the estimate")
    return out


def _keep(keep, n: int) -> np.ndarray:
    raw = np.asarray(keep)
    if raw.ndim != 1 or (raw.size and raw.dtype.kind not in "iu"):
        raise ValueError(f"keep: expected a 1-D array of path indices, got {keep!r}")
    if raw.size and (raw.min() < 0 or raw.max() >= n or np.unique(raw).size < raw.size):
        raise ValueError(f"keep: indices must be distinct and in [0, {n}), got {raw}")
    return raw.astype(int)


def epoch_consistency(
    ep: Epoch, route: SignalRoute, *, bound: bool = True, joint: bool = True, **kw
) -> dict:
    """:func:`tunnelkit.consistency.geometry_consistency` of ``ep``'s measurements through
    ``route``'s tunnel planes (the UE hypotheses kept inside the tunnel). ``bound=True``: the
    residuals in CRLB standard deviations at the estimate (:func:`bound_sigmas`) plus any
    ``floor_angle`` / ``floor_range`` in ``kw``; ``bound=False``: the floors alone (``kw`` must
    give both). ``joint`` (with the bound): the statistic with the bound's joint covariance of
    all paths (:func:`joint_bound`: correlations within and between paths; the generalised
    least-squares chi-square), else the per-component sigmas alone. Other ``kw``: the test's options (``pfa``, ``n_los``, ...)."""
    instance("ep", ep, Epoch)
    instance("route", route, SignalRoute)
    joint = boolean("joint", joint)  # checked whether or not the bound is asked for
    m = ep.measurements
    if boolean("bound", bound):
        sig = bound_sigmas(ep.estimates, ep.array, route.config, m.source)
        if sig.shape[0] != len(m):
            raise RuntimeError("bound_sigmas: rows differ from the epoch's measurements")
        if boolean("joint", joint) and len(m) >= 2:
            kw.setdefault("cov", joint_bound(ep.estimates, ep.array, route.config, m.source))
    else:
        if not (kw.get("floor_angle") and kw.get("floor_range")):
            raise ValueError("bound: without the bound, give floor_angle and floor_range")
        sig = np.zeros((len(m), 3))
    kw.setdefault("inside", route.tunnel.contains)
    return geometry_consistency(
        m.direction, m.d, m.origin, tunnel_planes(route.tunnel), sig[:, 0], sig[:, 1], sig[:, 2],
        **kw,
    )  # fmt: skip
