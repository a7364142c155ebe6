"""Cramér-Rao bounds of the eq. 1 channel model (Italiano et al. 2026), per path and jointly."""

from __future__ import annotations

import numpy as np

from .._physical import carrier
from .._validate import finite_array, instance, integer, positive, sequence
from ..arrays import ArrayGeometry
from ..budget import check_elements
from ..channel import SRSConfig
from ..constants import C, db2lin
from .estimates import PathEstimates
from .ml.merged import circular_mean
from .radio import check_array, check_srs

__all__ = [
    "crlb_paths",
    "estimate_crlb",
    "in_path_units",
    "merged_crlb",
    "merged_path",
    "ml_truth",
    "path_crlb",
    "source_crlb",
]


def crlb_paths(
    alpha,
    sources,
    element_positions,
    mu_f,
    mu_t,
    fc: float,
    n_tones: int,
    n_symbols: int,
    noise_power: float,
    *,
    spatial: str = "structured",
) -> dict[str, np.ndarray]:
    """CRLB of the eq. 1 model, all paths jointly.

    Per path the unknowns are ``Re alpha, Im alpha, mu_f, mu_t`` (the Vandermonde frequencies)
    and the spatial factor: with ``spatial="structured"`` the wave origin (3, local frame, exact
    spherical wavefront); with ``spatial="free"`` every entry ``a_m, m >= 1`` (real and imaginary
    part, ``a_0 = 1``): the model a CPD actually fits. ``alpha`` includes ``sqrt(P_t)``. The FIM
    ``2/N0 Re(J^H J)`` is assembled from the rank-1 structure (inner products factorise over the
    three modes). Returns the bound's standard deviations for ``mu_f``, ``mu_t`` (rad) and, when
    structured, the (L, 3, 3) covariance of each wave origin; all infinite where the Fisher
    information is singular (a path of zero gain, a wave origin the array cannot resolve).
    """
    if spatial not in ("structured", "free"):
        raise ValueError(f"spatial: expected 'structured' or 'free', got {spatial!r}")
    alpha = np.atleast_1d(finite_array("alpha", alpha, dtype=complex))
    if alpha.ndim != 1 or alpha.size == 0:
        raise ValueError(f"alpha: expected one complex gain per path (L,), got shape {alpha.shape}")
    L = alpha.size
    src = finite_array("sources", np.atleast_2d(sources) if np.ndim(sources) == 1 else sources)
    if src.shape != (L, 3):
        raise ValueError(f"sources: expected shape ({L}, 3) (one per alpha), got {src.shape}")
    p = finite_array("element_positions", element_positions, ndim=2)
    if p.shape[0] < 2 or p.shape[1] != 3:
        raise ValueError(f"element_positions: expected shape (M >= 2, 3), got {p.shape}")
    if np.any(np.linalg.norm(src[None, :, :] - p[:, None, :], axis=-1) == 0):
        raise ValueError("sources: a wave origin coincides with an element")
    mu_f = np.atleast_1d(finite_array("mu_f", mu_f))
    mu_t = np.atleast_1d(finite_array("mu_t", mu_t))
    for name, v in (("mu_f", mu_f), ("mu_t", mu_t)):
        if v.shape != (L,):
            raise ValueError(f"{name}: expected shape ({L},) (one per alpha), got {v.shape}")
    fc = carrier("fc", fc)
    n_tones = integer("n_tones", n_tones, minimum=2)
    n_symbols = integer("n_symbols", n_symbols, minimum=2)
    noise_power = positive("noise_power", noise_power)
    n_per = 4 + (3 if spatial == "structured" else 2 * (p.shape[0] - 1))
    check_elements(
        "n_tones, n_symbols",
        (p.shape[0] + n_tones + n_symbols) * n_per * L,
        16,
        f"the mode vectors of {L} paths",
    )
    k0 = 2 * np.pi * fc / C
    s = np.arange(n_tones)[:, None]
    kk = np.arange(n_symbols)[:, None]
    rng_m = np.linalg.norm(src[None, :, :] - p[:, None, :], axis=-1)  # (M, L)
    a = np.exp(1j * k0 * (rng_m - rng_m[0]))
    f = np.exp(1j * s * np.asarray(mu_f)[None, :])
    t = np.exp(1j * kk * np.asarray(mu_t)[None, :])
    # gradient of a_m w.r.t. the source: j k0 a_m (u_m - u_0), u_m = (src - p_m)/||src - p_m||
    u = (src[None, :, :] - p[:, None, :]) / rng_m[..., None]
    da = 1j * k0 * a[..., None] * (u - u[:1])  # (M, L, 3)
    X, Y, Z = [], [], []  # mode vectors of the 7 L rank-1 derivative terms
    for j_ in range(L):
        al = alpha[j_]
        terms = [
            (a[:, j_], f[:, j_], t[:, j_]),
            (1j * a[:, j_], f[:, j_], t[:, j_]),
            (al * a[:, j_], 1j * s[:, 0] * f[:, j_], t[:, j_]),
            (al * a[:, j_], f[:, j_], 1j * kk[:, 0] * t[:, j_]),
        ]
        if spatial == "structured":
            terms += [(al * da[:, j_, i], f[:, j_], t[:, j_]) for i in range(3)]
        else:
            eye = np.eye(a.shape[0])[:, 1:]
            terms += [(al * e, f[:, j_], t[:, j_]) for e in eye.T]
            terms += [(1j * al * e, f[:, j_], t[:, j_]) for e in eye.T]
        for x, y, z in terms:
            X.append(x)
            Y.append(y)
            Z.append(z)
    X, Y, Z = (np.stack(v, axis=1) for v in (X, Y, Z))
    gram = (X.conj().T @ X) * (Y.conj().T @ Y) * (Z.conj().T @ Z)
    fim = 2.0 / noise_power * gram.real
    # Jacobi scaling before the inverse: the parameters differ by many orders of magnitude.
    # A singular information (a zero gain, an origin the array cannot resolve) bounds nothing:
    # every variance is infinite rather than NaN or an error from the inverse.
    # The scaled matrix is symmetrised before the inverse: an exactly singular information
    # (a line array's 3-D origin) then fails the factorisation on every BLAS build, where its
    # round-off asymmetry let some builds return 1e12-sized garbage instead.
    cov = np.full_like(fim, np.inf)
    if np.all(np.diag(fim) > 0):
        dsc = 1.0 / np.sqrt(np.diag(fim))
        S = dsc[:, None] * fim * dsc[None, :]
        try:
            inv = np.linalg.inv(0.5 * (S + S.T))
        except np.linalg.LinAlgError:
            inv = None
        if inv is not None and np.all(np.isfinite(inv)) and np.all(np.diag(inv) > 0):
            cov = dsc[:, None] * inv * dsc[None, :]
    n_per = fim.shape[0] // L
    idx = np.arange(L) * n_per
    out = {"mu_f": np.sqrt(cov[idx + 2, idx + 2]), "mu_t": np.sqrt(cov[idx + 3, idx + 3])}
    if spatial == "structured":
        out["source_cov"] = np.stack([cov[i + 4 : i + 7, i + 4 : i + 7] for i in idx])
    return out


def path_crlb(
    paths,
    array,
    srs,
    *,
    n_tones: int | None = None,
    spatial: str = "structured",
    snr_offset_db: float = 0.0,
) -> dict:
    """Cramér-Rao bounds for every path of one epoch at the SNR the tensor was synthesised with:
    the configured one raised (positive) or lowered by ``snr_offset_db``, as
    :func:`tunnelkit.channel.synthesize` and :class:`tunnelkit.signal_route.SignalRoute` apply it
    (the noise power ``srs.noise_power / 10^(snr_offset_db / 10)``).

    ``spatial="structured"`` (default): every parameter from the exact spherical model of eq. 1
    (wave origin = VUE, 3 numbers per path): the bound the maximum-likelihood route
    (``extract_paths(refine="ml")``) is judged against. ``spatial="free"``: ``d``/``v`` from the
    free-spatial-factor model (what a CPD fits, plus Vandermonde structure), the bound of the
    paper's route; ``direction`` [rad] and ``kappa`` [m] are always the structured ones (a free
    spatial factor has no direction). Returns standard deviations ``d`` [m], ``v`` [m/s],
    ``direction`` [rad] (angle between unit vectors: ``sqrt(trace)`` of the direction's
    covariance), ``kappa`` [m] (range of the wave origin).

    ``paths`` are the traced paths (:class:`tunnelkit.propagation.Path`) of ``array`` (an
    :class:`~tunnelkit.arrays.ArrayGeometry`: the wave origins are taken to its local frame),
    ``srs`` the :class:`~tunnelkit.channel.SRSConfig` (``n_tones`` overrides its tone count).
    """
    if spatial not in ("structured", "free"):
        raise ValueError(f"spatial: expected 'structured' or 'free', got {spatial!r}")
    if not isinstance(array, ArrayGeometry):
        raise TypeError(f"array: expected an ArrayGeometry, got {type(array).__name__}")
    config = check_srs(srs)
    nf = config.n_tones if n_tones is None else integer("n_tones", n_tones, minimum=2)
    off = float(finite_array("snr_offset_db", snr_offset_db, ndim=0))
    noise_power = config.noise_power / float(db2lin(off))
    _, mu_f, mu_t = ml_truth(paths, array, config)  # checks paths too
    alpha = np.sqrt(config.tx_power) * np.array([p.gain for p in paths])
    src = np.stack([array.to_local(p.source) for p in paths])
    out = source_crlb(
        alpha,
        src,
        array.local,
        mu_f,
        mu_t,
        config.fc,
        nf,
        config.n_symbols,
        noise_power,
        spatial=spatial,
    )
    return in_path_units(out, config)


def ml_truth(paths, array, srs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The true values of the maximum-likelihood model's parameters for traced paths: what
    :mod:`tunnelkit.extraction.ml` (``Problem``, ``WidebandProblem``, ``ml_paths``) estimates.

    Returns ``(theta, mu_f, mu_t)``:

    - ``theta`` (L, 3): per path ``(u_x, u_y, w)``: the direction cosines [-] of the unit vector
      from the array's reference element towards the wave origin (the VUE; the vehicle itself for
      LoS) in the array's local frame, and ``w = 1 / r`` [1/m], the wavefront's curvature, ``r``
      [m] the distance to the wave origin (the wave origin is ``(u_x, u_y, u_z) / w``);
    - ``mu_f`` (L,): the delay as the phase step between adjacent tones,
      ``-2 pi Delta_f d / c`` [rad], ``d`` the path length [m], ``Delta_f`` the tone spacing of
      ``srs`` [Hz];
    - ``mu_t`` (L,): the Doppler as the phase step between symbols, ``2 pi T_s f_D`` [rad],
      ``T_s`` the symbol period [s], ``f_D`` the path's Doppler shift [Hz].

    ``paths`` are the :class:`tunnelkit.propagation.Path` traced to ``array`` (an
    :class:`~tunnelkit.arrays.ArrayGeometry`), ``srs`` the :class:`~tunnelkit.channel.SRSConfig`.
    """
    from ..propagation import as_path_list

    if not isinstance(array, ArrayGeometry):
        raise TypeError(f"array: expected an ArrayGeometry, got {type(array).__name__}")
    config = check_srs(srs)
    paths = as_path_list(paths)
    src = np.stack([array.to_local(p.source) for p in paths])
    r = np.linalg.norm(src, axis=1)
    theta = np.column_stack([src[:, :2] / r[:, None], 1 / r])
    mu_f = -2 * np.pi * config.tone_spacing * np.array([p.length for p in paths]) / C
    mu_t = 2 * np.pi * config.symbol_period * np.array([p.doppler for p in paths])
    return theta, mu_f, mu_t


def in_path_units(bound: dict, config) -> dict[str, np.ndarray]:
    """:func:`source_crlb`'s standard deviations as ``d`` [m], ``v`` [m/s], ``direction`` [rad]
    and ``kappa`` [m], with the tone spacing, carrier and symbol period of ``config``."""
    instance("config", config, SRSConfig)
    instance("bound", bound, dict)
    missing = [k for k in ("mu_f", "mu_t", "direction", "kappa") if k not in bound]
    if missing:
        raise ValueError(f"bound: missing {missing} (a source_crlb result)")
    return {
        "d": C / (2 * np.pi * config.tone_spacing) * bound["mu_f"],
        "v": C / (2 * np.pi * config.fc * config.symbol_period) * bound["mu_t"],
        "direction": bound["direction"],
        "kappa": bound["kappa"],
    }


def source_crlb(
    alpha,
    sources,
    element_positions,
    mu_f,
    mu_t,
    fc,
    n_tones,
    n_symbols,
    noise_power,
    *,
    spatial: str = "structured",
) -> dict[str, np.ndarray]:
    """:func:`crlb_paths` read out per path: ``mu_f``, ``mu_t`` (rad; from the ``spatial`` model),
    ``direction`` [rad] and ``kappa`` [m] of the wave origin (structured model), for sources
    given in the array's local frame (any scene, not only traced paths)."""
    if spatial not in ("structured", "free"):
        raise ValueError(f"spatial: expected 'structured' or 'free', got {spatial!r}")
    args = (alpha, sources, element_positions, mu_f, mu_t, fc, n_tones, n_symbols, noise_power)
    st = crlb_paths(*args, spatial="structured")
    roots = st if spatial == "structured" else crlb_paths(*args, spatial="free")
    src = np.atleast_2d(np.asarray(sources, float))
    u = src / np.linalg.norm(src, axis=1, keepdims=True)
    rng_ = np.linalg.norm(src, axis=1)
    proj = np.eye(3)[None] - u[:, :, None] * u[:, None, :]
    ang = np.sqrt(np.einsum("lij,ljk,lki->l", proj, st["source_cov"], proj)) / rng_
    kap = np.sqrt(np.einsum("li,lij,lj->l", u, st["source_cov"], u))
    return {"mu_f": roots["mu_f"], "mu_t": roots["mu_t"], "direction": ang, "kappa": kap}


def estimate_crlb(est, array, srs, *, noise_power: float | None = None, paths=None) -> dict:
    """The structured CRLB evaluated at the estimates: the covariance an efficient estimator
    reports for its own output (the ML route sits on this bound, notebook 03; a CPD route does
    not, so for it this understates the error).

    ``est`` is a :class:`~tunnelkit.extraction.PathEstimates`; the paths ``paths`` (indices,
    default all) enter the joint Fisher information, so each one's bound accounts for the others;
    leave out what the extraction rejected as noise. A far-field estimate (no curvature)
    is placed on its direction at the range ``d``, at least the Fraunhofer distance of the array;
    its curvature bound is then meaningless and not used downstream. ``noise_power`` defaults to
    the ML fit's estimate (``est.fit.noise_power``), else ``srs.noise_power``. ``array`` and
    ``srs`` as in :func:`~tunnelkit.extraction.extract_paths`.

    Returns, per path of ``paths``: ``source`` (L, 3) the wave origins used (local frame),
    ``source_cov`` (L, 3, 3) [m^2] their covariance, and ``d`` (L,) [m], the delay-distance
    standard deviation. Raises
    ``numpy.linalg.LinAlgError`` when the Fisher information is singular at the estimate.
    """
    if not isinstance(est, PathEstimates):
        raise TypeError(f"est: expected PathEstimates, got {type(est).__name__}")
    p = check_array(array, m=est.delta.shape[1] if est.delta.ndim == 2 else None)
    config = check_srs(srs)
    noise_power = positive("noise_power", noise_power, none=True)
    if paths is not None and not isinstance(paths, list | tuple | np.ndarray):
        raise TypeError(f"paths: expected indices of paths, got {type(paths).__name__}")
    sel = np.arange(len(est)) if paths is None else np.asarray(paths, int).reshape(-1)
    if sel.size == 0:
        return {"source": np.zeros((0, 3)), "source_cov": np.zeros((0, 3, 3)), "d": np.zeros(0)}
    if noise_power is None:
        fit = getattr(est, "fit", None)
        noise_power = fit.noise_power if fit is not None else config.noise_power
    lam = C / config.fc
    aperture = float(np.max(np.linalg.norm(p - p.mean(axis=0), axis=1))) * 2.0
    far = max(2.0 * aperture**2 / lam, 1.0)
    kap, d_est = est.kappa[sel], est.d[sel]
    rng_ = np.where(np.isfinite(kap), kap, np.maximum(d_est, far))
    src = est.direction[sel] * rng_[:, None]
    res = crlb_paths(
        est.alpha[sel],
        src,
        p,
        est.mu_f[sel],
        est.mu_t[sel],
        config.fc,
        config.n_tones,
        config.n_symbols,
        float(noise_power),
        spatial="structured",
    )
    cov = res["source_cov"]
    d = C / (2 * np.pi * config.tone_spacing) * res["mu_f"]
    ok = np.all(np.isfinite(cov)) and np.all(np.isfinite(d))
    ok = ok and np.all(np.linalg.eigvalsh(0.5 * (cov + np.swapaxes(cov, 1, 2))) > 0)
    if not ok:
        raise np.linalg.LinAlgError("estimate_crlb: Fisher information singular at the estimate")
    return {"source": src, "source_cov": cov, "d": d}


def merged_path(alpha, sources, mu_f, mu_t, pair) -> dict:
    """The path one fitted path becomes when it explains two (an unresolved pair): the pair's
    power-weighted centroid. With weights ``p_k = |alpha_k|^2 / (|alpha_i|^2 + |alpha_j|^2)``
    over the pair ``(i, j)``: the direction ``sum p_k u_k`` normalised, the curvature ``w = sum
    p_k / r_k`` (the wave origin at ``u / w``), ``mu_f`` and ``mu_t`` the weighted means on the
    circle (delay and Doppler phases, :func:`~tunnelkit.extraction.ml.merged.circular_mean`, as
    the ML fit's merged start), and the gain of the summed power, ``sqrt(|alpha_i|^2 +
    |alpha_j|^2)``, with the phase of ``alpha_i + alpha_j`` (of the stronger when they cancel).

    ``alpha`` (L,) complex gains, ``sources`` (L, 3) wave origins (local frame), ``mu_f``,
    ``mu_t`` (L,) [rad], ``pair`` two distinct indices. Returns ``alpha`` (complex), ``source``
    (3,), ``mu_f``, ``mu_t``, ``direction`` (3,) unit and ``w`` [1/m]."""
    alpha = _gains(alpha)
    L = alpha.size
    src = finite_array("sources", sources, shape=(L, 3))
    mu_f = finite_array("mu_f", mu_f, shape=(L,))
    mu_t = finite_array("mu_t", mu_t, shape=(L,))
    i, j = _pair_indices(pair, L)
    pw = np.abs(alpha[[i, j]]) ** 2
    if not pw.sum() > 0:
        raise ValueError("alpha: the pair has no power (both gains zero)")
    p = pw / pw.sum()
    r = np.linalg.norm(src[[i, j]], axis=1)
    if np.any(r == 0):
        raise ValueError("sources: a wave origin of the pair sits at the reference antenna")
    u = p @ (src[[i, j]] / r[:, None])
    if not np.linalg.norm(u) > 0:
        raise ValueError("sources: the pair's directions are opposite (no centroid direction)")
    u = u / np.linalg.norm(u)
    w = float(p @ (1.0 / r))
    s = alpha[i] + alpha[j]
    ph = s / abs(s) if abs(s) > 1e-12 * np.sqrt(pw.sum()) else alpha[[i, j]][np.argmax(pw)]
    ph = ph / abs(ph)
    return {
        "alpha": complex(np.sqrt(pw.sum()) * ph),
        "source": u / w,
        "mu_f": circular_mean(p, mu_f[[i, j]]),
        "mu_t": circular_mean(p, mu_t[[i, j]]),
        "direction": u,
        "w": w,
    }


def _pair_indices(pair, L: int) -> tuple[int, int]:
    pair = sequence("pair", pair)
    if len(pair) != 2:
        raise ValueError(f"pair: expected two path indices, got {len(pair)}")
    i, j = (integer("pair", k, minimum=0, maximum=L - 1) for k in pair)
    if i == j:
        raise ValueError(f"pair: expected two distinct indices, got {i} twice")
    return i, j


def _gains(alpha) -> np.ndarray:
    alpha = finite_array("alpha", alpha, dtype=complex)
    if alpha.ndim != 1 or alpha.size < 2:
        raise ValueError(f"alpha: expected one complex gain per path (L >= 2,), got {alpha.shape}")
    return alpha


def merged_crlb(
    alpha,
    sources,
    element_positions,
    mu_f,
    mu_t,
    fc: float,
    n_tones: int,
    n_symbols: int,
    noise_power: float,
    pair,
) -> dict:
    """The bound an unresolved pair is judged against: where two paths are closer than the data
    resolve (``ml.pair_test``), the two-path CRLB is not attainable; one fitted path at the
    pair's power-weighted centroid (:func:`merged_path`) is what the estimate can reach. The
    structured CRLB (:func:`source_crlb`) of the model with the pair ``(i, j)`` replaced by that
    one path, jointly with the other ``L - 2`` paths, read out for the merged path.

    Arguments as :func:`source_crlb` (``alpha`` (L,), ``sources`` (L, 3) local frame, ...) plus
    ``pair`` (two distinct indices). Returns :func:`merged_path`'s centroid (``alpha``,
    ``source``, ``mu_f``, ``mu_t``, ``direction``, ``w``) and the merged path's standard
    deviations ``sd_mu_f``, ``sd_mu_t`` [rad], ``sd_direction`` [rad], ``sd_kappa`` [m] (range
    of the wave origin; ``sd_kappa * w^2`` bounds ``w``)."""
    alpha = _gains(alpha)
    L = alpha.size
    src = finite_array("sources", sources, shape=(L, 3))
    mu_f = finite_array("mu_f", mu_f, shape=(L,))
    mu_t = finite_array("mu_t", mu_t, shape=(L,))
    i, j = _pair_indices(pair, L)
    m = merged_path(alpha, src, mu_f, mu_t, (i, j))
    rest = np.array([k for k in range(L) if k not in (i, j)], int)
    b = source_crlb(
        np.append(m["alpha"], alpha[rest]),
        np.vstack([m["source"], src[rest]]),
        element_positions,
        np.append(m["mu_f"], mu_f[rest]),
        np.append(m["mu_t"], mu_t[rest]),
        fc,
        n_tones,
        n_symbols,
        noise_power,
    )
    return {**m, **{f"sd_{k}": float(b[k][0]) for k in ("mu_f", "mu_t", "direction", "kappa")}}
