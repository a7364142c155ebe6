"""The result of an extraction: per-path estimates in one container, whatever the route."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import boolean, integer, nonnegative, sequence
from ..constants import C

__all__ = ["PathEstimates", "path_estimates"]

_KINDS = {"real": "iuf", "complex": "iufc", "bool": "b"}


#: fields that may hold NaN or inf: a far-field path has no curvature
_NOT_FINITE_OK = ("kappa", "kappa_nf")
#: fields that may hold +inf: a path with no other path near it has an infinite separation
_INF_OK = ("resolution",)


def _per_path(name: str, value, n: int, kind: str, *, ndim: int = 1, width: int | None = None):
    """A per-path array of ``n`` rows: numbers of ``kind`` (finite, but for the curvatures in
    ``_NOT_FINITE_OK``), ``ndim`` axes and ``width`` columns when given; errors name ``name``."""
    if isinstance(value, str | bytes) or not isinstance(value, np.ndarray | list | tuple):
        raise TypeError(
            f"{name}: expected an array with one row per path, got {type(value).__name__}"
        )
    arr = np.asarray(value)
    if arr.dtype.kind not in _KINDS[kind]:
        raise TypeError(f"{name}: expected {kind} values, got dtype {arr.dtype}")
    if arr.ndim != ndim or arr.shape[0] != n or (width is not None and arr.shape[1] != width):
        want = f"({n},)" if ndim == 1 else f"({n}, {width if width is not None else 'M'})"
        raise ValueError(f"{name}: expected shape {want} (one row per path), got {arr.shape}")
    inf_ok = name in _INF_OK and arr.dtype.kind == "f"
    bad = ~np.isfinite(arr) & ~(inf_ok & (arr == np.inf)) if arr.dtype.kind in "fc" else None
    if name not in _NOT_FINITE_OK and bad is not None and bad.any():
        raise ValueError(f"{name}: contains NaN or infinite values")


def _physical(d, v, direction) -> np.ndarray:
    """Per path: physically possible — finite, ``|v| < c``, a unit direction of arrival in the
    array's front half-space (local ``z >= 0``)."""
    u = np.asarray(direction, float)
    ok = np.isfinite(d) & np.isfinite(v) & np.all(np.isfinite(u), axis=1) & (np.abs(v) < C)
    return ok & (u[:, 2] >= 0) & (np.abs(np.linalg.norm(u, axis=1) - 1.0) <= 1e-6)


@dataclass(frozen=True)
class PathEstimates:
    """Per-path estimates from one tensor, sorted by ``d`` (earliest first).

    ``alpha`` complex gain (eq. 12, refined), ``d`` distance ``c tau`` including the clock bias [m]
    (eq. 14), ``v`` relative velocity ``c f_d / fc`` [m/s] (eq. 15), ``direction`` (L, 3) unit
    vectors of arrival in the array's local frame, ``kappa`` wavefront radius [m] (NaN when
    far-field), ``near_field`` (bool), ``phi``/``psi`` local azimuth and polar angle (eq. 19
    convention), ``valid`` = Algorithm 1 keeps the path (``d >= 0``), ``kappa_nf`` the raw TLS
    value, ``delta`` (L, M) unwrapped path-length offsets (eq. 16), ``mu_f``/``mu_t`` the roots.
    ``fit`` holds the maximum-likelihood stage's :class:`~tunnelkit.extraction.ml.MLFit` (noise
    power, basin test) on that route, ``None`` on the others; ``significance`` each path's
    log-likelihood ratio against noise on that route (sorted like the rest), ``None`` elsewhere;
    ``fit_ok`` the ML stage's verdict on its own fit (``MLFit.fit_ok``: no structured residual
    left, every path above the noise, every two paths resolved; ``fit.reason`` names a failed
    test), ``None`` on the routes that do not test themselves; ``resolution`` each path's
    smallest distance to another path in standard deviations of their difference (Fisher
    information at the fit, :func:`~tunnelkit.extraction.ml.separations`): below
    ``ml.RESOLVE_Z`` (5) the path is in the threshold region of resolution (its errors are not
    described by the bound, ``fit_ok`` is False), ``None`` on the routes without the ML fit;
    ``below_threshold`` per path, in the estimator's threshold region at the fit
    (:func:`~tunnelkit.extraction.ml.below_threshold`: its SNR below the threshold of the method of
    interval errors, :func:`~tunnelkit.extraction.ml.snr_threshold`, or unresolved): its errors
    may leave the bound; ``fit_ok`` stays the fit's own tests (``None`` off the ML route);
    ``unresolved`` per path, the index (in this order) of the path it is not resolved from by the
    pair test (:func:`~tunnelkit.extraction.ml.pair_test`: one path explains the two as well),
    ``-1`` when resolved from every other; the two are one path's worth of information and are
    judged against the bound of one (``None`` off the ML route).
    """

    alpha: np.ndarray
    d: np.ndarray
    v: np.ndarray
    direction: np.ndarray
    kappa: np.ndarray
    near_field: np.ndarray
    phi: np.ndarray
    psi: np.ndarray
    valid: np.ndarray
    kappa_nf: np.ndarray
    delta: np.ndarray = field(repr=False)
    mu_f: np.ndarray = field(repr=False)
    mu_t: np.ndarray = field(repr=False)
    factors: tuple = field(repr=False)
    rel_error: float = 0.0
    n_iter: int = 0
    converged: bool = True
    fit: object = field(default=None, repr=False)
    significance: np.ndarray | None = field(default=None, repr=False)
    fit_ok: bool | None = None
    resolution: np.ndarray | None = field(default=None, repr=False)
    below_threshold: np.ndarray | None = field(default=None, repr=False)
    unresolved: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self.fit is not None and not all(hasattr(self.fit, a) for a in ("rho", "rho_max")):
            raise TypeError(
                f"fit: expected the ML fit's record (MLFit) or None, got {type(self.fit).__name__}"
            )
        d = self.d
        if isinstance(d, str | bytes) or np.ndim(d) != 1:
            raise ValueError(f"d: expected one distance per path (L,), got shape {np.shape(d)}")
        n = np.shape(d)[0]
        _per_path("d", d, n, "real")
        _per_path("alpha", self.alpha, n, "complex")
        for name in ("v", "kappa", "phi", "psi", "kappa_nf", "mu_f", "mu_t"):
            _per_path(name, getattr(self, name), n, "real")
        _per_path("near_field", self.near_field, n, "bool")
        _per_path("valid", self.valid, n, "bool")
        _per_path("direction", self.direction, n, "real", ndim=2, width=3)
        _per_path("delta", self.delta, n, "real", ndim=2)
        if not isinstance(self.factors, tuple) or len(self.factors) != 3:
            raise TypeError("factors: expected the three factor matrices (A, F, T) as a tuple")
        nonnegative("rel_error", self.rel_error)
        integer("n_iter", self.n_iter, minimum=0)
        boolean("converged", self.converged)
        if self.significance is not None:
            _per_path("significance", self.significance, n, "real")
        if self.fit_ok is not None:
            boolean("fit_ok", self.fit_ok)
        bad = np.flatnonzero(self.valid & ~_physical(d, self.v, self.direction))
        if bad.size:
            i = int(bad[0])
            raise ValueError(
                f"valid: path {i} is marked valid but is not physical (d = {d[i]:g} m, v = "
                f"{self.v[i]:g} m/s, direction {np.asarray(self.direction)[i].tolist()}): a valid "
                "path has |v| < c and a unit direction in the front half-space"
            )
        if self.resolution is not None:
            _per_path("resolution", self.resolution, n, "real")
        if self.below_threshold is not None:
            _per_path("below_threshold", self.below_threshold, n, "bool")
        if self.unresolved is not None:
            _per_path("unresolved", self.unresolved, n, "real")
            u = np.asarray(self.unresolved)
            if u.dtype.kind not in "iu" or np.any((u < -1) | (u >= n)) or np.any(u == np.arange(n)):
                raise ValueError("unresolved: expected per path another path's index or -1")

    def __len__(self) -> int:
        return self.d.shape[0]

    def physical(self) -> np.ndarray:
        """Per path: physically possible (finite, ``|v| < c``, a unit direction in the front
        half-space), what every path marked ``valid`` is."""
        return _physical(self.d, self.v, self.direction)

    def __getitem__(self, key: str):
        return getattr(self, key)

    def model_tensor(self) -> np.ndarray:
        """The (M, Nf, Nt) tensor of eq. 1 the estimates describe: ``sum_l alpha_l a_l (x) f_l
        (x) t_l`` of the ``factors`` (A, F, T) (one column per path) and gains ``alpha``."""
        a, f, t = (np.asarray(x) for x in self.factors)
        n = len(self)
        if any(x.ndim != 2 or x.shape[1] != n for x in (a, f, t)):
            raise ValueError(
                f"factors: expected three matrices with one column per path ({n}), got shapes "
                f"{[x.shape for x in (a, f, t)]}"
            )
        return np.einsum("ml,sl,kl,l->msk", a, f, t, self.alpha)

    def wave_origins(self) -> np.ndarray:
        """``kappa * direction`` (L, 3) in the local frame (NaN rows for far-field paths)."""
        return self.kappa[:, None] * self.direction


def path_estimates(
    alpha, d, v, ang: dict, near, delta, mu_f, mu_t, factors, rel_error, n_iter, converged
) -> PathEstimates:
    """Assemble :class:`PathEstimates` sorted by ``d``: near-field paths take the eq. 19-21
    angles and curvature of ``ang`` (:func:`angles_from_solution`), the others the far-field
    ones (``kappa`` NaN); ``delta`` is (L, M), ``factors`` the three (., L) factor matrices."""
    L = np.shape(d)[0] if np.ndim(d) == 1 else -1
    for name, a, nd in (
        ("d", d, 1),
        ("alpha", alpha, 1),
        ("v", v, 1),
        ("near", near, 1),
        ("delta", delta, 2),
        ("mu_f", mu_f, 1),
        ("mu_t", mu_t, 1),
    ):
        if isinstance(a, str) or np.ndim(a) != nd or np.shape(a)[0] != L:
            want = "(L,)" if nd == 1 else "(L, M)"
            raise ValueError(f"{name}: expected shape {want} with L = len(d), got {np.shape(a)}")
    if len(sequence("factors", factors)) != 3:
        raise ValueError(
            f"factors: expected the three factor matrices (A, F, T), got {len(factors)}"
        )
    if not isinstance(ang, dict):
        raise TypeError(f"ang: expected the dict of angles_from_solution, got {type(ang).__name__}")
    direction = np.where(near[:, None], ang["dir_nf"], ang["dir_ff"])
    kappa = np.where(near, ang["kappa_nf"], np.nan)
    phi = np.where(near, ang["phi_nf"], ang["phi_ff"])
    psi = np.where(near, ang["psi_nf"], ang["psi_ff"])
    o = np.argsort(d)
    return PathEstimates(
        alpha[o],
        d[o],
        v[o],
        direction[o],
        kappa[o],
        near[o],
        phi[o],
        psi[o],
        (d >= 0)[o] & _physical(d, v, direction)[o],
        ang["kappa_nf"][o],
        delta[o],
        mu_f[o],
        mu_t[o],
        tuple(B[:, o] for B in factors),
        rel_error,
        n_iter,
        converged,
    )
