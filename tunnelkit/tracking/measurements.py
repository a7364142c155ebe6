"""The one measurement container from the extraction to the trackers: the sanitised path
parameters of one epoch (:class:`PathMeasurements`, Algorithm 1 lines 4-12 of Italiano et al.
2026), and the warning of a fault in that stream (:class:`JavelinWarning`).

The signal route builds it from the raw estimates (``signal_route.measurements_from_estimates``)
and every tracker of the Italiano family reads it; it lives apart from the trackers so that
building a route does not load them.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from .._checks import series, unchecked
from .._validate import boolean, real, vector
from ..constants import C

__all__ = ["JavelinWarning", "PathMeasurements"]


class JavelinWarning(UserWarning):
    """A fault in the measurement stream the tracker works around (dropped path, missing message)."""


def _opt(name: str, value, n: int) -> np.ndarray:
    if value is None:
        return np.full(n, np.nan)
    arr = np.asarray(value, dtype=float).reshape(-1)
    if arr.size != n:
        raise ValueError(f"{name}: expected {n} values (one per path), got {arr.size}")
    return arr.copy()


def _reported(cov, sigma_d, n: int):
    """Checked ``cov`` (n, 3, 3) and ``sigma_d`` (n,): both given or both ``None``."""
    if cov is None and sigma_d is None:
        return None, None
    from .reported import checked_reported  # an extraction that reports its uncertainty

    return checked_reported(cov, sigma_d, n)


def _bias(bias_cov, cov, sigma_d, n: int):
    """Checked ``bias_cov`` (n, 4, 4): symmetric, positive semi-definite, and no larger than the
    reported covariance it is a share of (``cov`` / ``sigma_d``) in any direction."""
    if bias_cov is None:
        return None
    from .reported import checked_bias  # a reported uncertainty with a repeating share

    return checked_bias(bias_cov, cov, sigma_d, n)


@dataclass
class PathMeasurements:
    """Sanitised path parameters of one epoch (Algorithm 1, lines 4-12): what the signal route
    gives (:func:`tunnelkit.signal_route.measurements_from_estimates`) and the trackers take.

    Arrays have one entry per kept path: ``phi``/``psi`` azimuth and elevation (eq. 46-47),
    ``kappa`` the curvature radius (NaN where only the far-field estimate is valid), ``d`` the
    delay distance with the clock bias and ``v`` the radial speed (NaN where unknown). ``source``
    keeps each kept path's row in the input. ``origin`` (3,): the world position the angles are
    seen from (``None``: not said); ``site`` (3,): the position the tracker evaluates the measurement
    model from (``None``: the tracker's own base station). The route sorts the paths by ``d``;
    ``delta_d``, ``z`` (eq. 52, 54), ``near_field``, ``direction`` and ``wave_origins`` are derived.

    Optional (ours): ``cov`` (n, 3, 3) of ``(phi, psi, kappa)`` and ``sigma_d`` (n,), both or
    neither, used by ``measurement_noise="reported"``; ``bias_cov`` (n, 4, 4), with them only, their
    share over ``(phi, psi, kappa, d)`` that repeats from epoch to epoch. Field by field, and what
    this container is not: docs/internals/tracking.md.
    """

    phi: np.ndarray
    psi: np.ndarray
    kappa: np.ndarray
    d: np.ndarray
    v: np.ndarray
    source: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    cov: np.ndarray | None = None
    sigma_d: np.ndarray | None = None
    bias_cov: np.ndarray | None = None
    origin: np.ndarray | None = None
    site: np.ndarray | None = None

    def __post_init__(self) -> None:
        # built directly (not through from_arrays): 1-D float arrays of one length, and a
        # default ``source`` so that ``subset`` works (NaN angles: the tracker sanitises them)
        for name in ("phi", "psi", "kappa", "d", "v", "source"):
            series(name, getattr(self, name), finite=name == "source")
        for name in ("phi", "psi", "kappa", "d", "v"):
            setattr(self, name, np.asarray(getattr(self, name), dtype=float).reshape(-1))
        # a measured radial speed may be an extraction's outlier (the tracker gates it), never
        # faster than light
        fast = np.abs(self.v[np.isfinite(self.v)])
        if fast.size and fast.max() >= C:
            raise ValueError(
                f"v: a measured radial speed of {fast.max():.4g} m/s, faster than light"
            )
        n = self.phi.size
        for name in ("psi", "kappa", "d", "v"):
            if getattr(self, name).size != n:
                raise ValueError(
                    f"{name}: expected {n} values (one per path), got {getattr(self, name).size}"
                )
        src = np.asarray(self.source, dtype=int).reshape(-1)
        if src.size == 0 and n:
            src = np.arange(n)
        if src.size != n:
            raise ValueError(f"source: expected {n} values (one per path), got {src.size}")
        self.source = src
        self.cov, self.sigma_d = _reported(self.cov, self.sigma_d, n)
        self.bias_cov = _bias(self.bias_cov, self.cov, self.sigma_d, n)
        if self.origin is not None:
            self.origin = vector("origin", self.origin, 3)
        if self.site is not None:
            self.site = vector("site", self.site, 3)

    @property
    def reported(self) -> bool:
        """Whether the extraction reported a covariance for every path."""
        return self.cov is not None

    @property
    def near_field(self) -> np.ndarray:
        """Whether each path carries a curvature (a near-field estimate, ``kappa`` not NaN)."""
        return np.isfinite(self.kappa)

    @property
    def delta_d(self) -> np.ndarray:
        """``d - d[0]``: the delay differences to the first path (eq. 52, ``delta_d[0] = 0``)."""
        return self.d - self.d[0] if self.d.size else self.d.copy()

    @property
    def z(self) -> np.ndarray:
        """Eq. 54 stacked vector ``[phi; psi; kappa; delta_d[1:]]`` (kappa NaN for far-field)."""
        return np.concatenate([self.phi, self.psi, self.kappa, self.delta_d[1:]])

    @property
    def direction(self) -> np.ndarray:
        """Unit arrival directions from ``phi``/``psi`` (elevation), shape (n, 3)."""
        c = np.cos(self.psi)
        return np.column_stack([c * np.cos(self.phi), c * np.sin(self.phi), np.sin(self.psi)])

    @property
    def wave_origins(self) -> np.ndarray:
        """``origin + kappa * direction`` (n, 3), NaN rows for far-field paths (Fig. 5); needs
        ``origin``."""
        if self.origin is None:
            raise ValueError("origin: not given, so the wave origins have no position")
        return self.origin + self.kappa[:, None] * self.direction

    def sanitised(self, min_d: float = 0.0) -> tuple[PathMeasurements, int]:
        """These paths through the checks of Algorithm 1 (idempotent), and how many were dropped.

        ``source`` keeps pointing into the original input."""
        real("min_d", min_d)
        # this record's fields were checked when it was built: Algorithm 1's tests alone (what
        # from_arrays does after its checks), the kept paths a record built unchecked (the
        # tracker sanitises every epoch's paths)
        keep = np.isfinite(self.phi) & np.isfinite(self.psi) & ~(self.d < min_d)
        idx = np.flatnonzero(keep)
        kappa = np.where(np.isfinite(self.kappa) & (self.kappa > 0), self.kappa, np.nan)
        d = np.where(np.isfinite(self.d), self.d, np.nan)
        v = np.where(np.isfinite(self.v), self.v, np.nan)
        sub = [None if a is None else a[idx] for a in (self.cov, self.sigma_d, self.bias_cov)]
        clean = unchecked(
            PathMeasurements, self.phi[idx], self.psi[idx], kappa[idx], d[idx], v[idx],
            self.source[idx], *sub, self.origin, self.site,
        )  # fmt: skip
        return clean, len(self) - len(clean)

    @classmethod
    def from_arrays(
        cls,
        phi,
        psi,
        kappa=None,
        d=None,
        v=None,
        *,
        warn: bool = True,
        cov=None,
        sigma_d=None,
        min_d: float = 0.0,
        bias_cov=None,
    ) -> PathMeasurements:
        """Apply the consistency checks of Algorithm 1 and drop unusable paths.

        (i) ``d < min_d``: path discarded (``min_d = 0`` as printed; ``-c b_max`` keeps what the
        clock bias explains, see :func:`tunnelkit.extraction.algorithm1`); (ii) ``kappa < 0``
        (or NaN): far field, no curvature; ours: a path with a NaN/inf angle is discarded with a
        :class:`JavelinWarning`. ``cov`` / ``sigma_d`` / ``bias_cov``: the reported uncertainty
        of every input path and its repeating share (see the class).
        """
        for name, value in (("phi", phi), ("psi", psi), ("kappa", kappa), ("d", d), ("v", v)):
            if value is not None:
                series(name, value)
        boolean("warn", warn), real("min_d", min_d)
        phi = np.asarray(phi, dtype=float).reshape(-1)
        n = phi.size
        psi = _opt("psi", psi, n)
        kappa, d, v = _opt("kappa", kappa, n), _opt("d", d, n), _opt("v", v, n)
        bad_angle = ~(np.isfinite(phi) & np.isfinite(psi))
        if warn and np.any(bad_angle):
            warnings.warn(
                f"{int(bad_angle.sum())} path(s) with a NaN angle dropped",
                JavelinWarning,
                stacklevel=2,
            )
        keep = ~bad_angle & ~(d < min_d)
        kappa = np.where(np.isfinite(kappa) & (kappa > 0), kappa, np.nan)
        d = np.where(np.isfinite(d), d, np.nan)
        v = np.where(np.isfinite(v), v, np.nan)
        idx = np.flatnonzero(keep)
        cov, sigma_d = _reported(cov, sigma_d, n)
        bias_cov = _bias(bias_cov, cov, sigma_d, n)
        if cov is not None:
            cov, sigma_d = cov[idx], sigma_d[idx]
        if bias_cov is not None:
            bias_cov = bias_cov[idx]
        return cls(phi[idx], psi[idx], kappa[idx], d[idx], v[idx], idx, cov, sigma_d, bias_cov)

    @classmethod
    def empty(cls) -> PathMeasurements:
        """No path this epoch (everything missed)."""
        z = np.zeros(0)
        return cls(z, z.copy(), z.copy(), z.copy(), z.copy(), np.zeros(0, dtype=int))

    def __len__(self) -> int:
        return self.phi.size

    def subset(self, idx) -> PathMeasurements:
        """The paths at positions ``idx``."""
        raw = np.asarray(idx) if not isinstance(idx, str | bytes) else None
        if raw is None or raw.ndim != 1 or (raw.size and raw.dtype.kind not in "iu"):
            raise TypeError(f"idx: expected a 1-D array of path indices, got {idx!r:.40}")
        if raw.size and (raw.min() < -len(self) or raw.max() >= len(self)):
            raise ValueError(
                f"idx: path indices must lie in [0, {len(self) - 1}], got {raw.tolist()}"
            )
        idx = np.asarray(idx, dtype=int)
        return PathMeasurements(
            self.phi[idx],
            self.psi[idx],
            self.kappa[idx],
            self.d[idx],
            self.v[idx],
            self.source[idx],
            None if self.cov is None else self.cov[idx],
            None if self.sigma_d is None else self.sigma_d[idx],
            None if self.bias_cov is None else self.bias_cov[idx],
            self.origin,
            self.site,
        )

    def triples(self) -> np.ndarray:
        """``(phi, psi, kappa)`` per path, shape (n, 3) (NaN kappa where far field)."""
        return np.column_stack([self.phi, self.psi, self.kappa])
