"""TeNFiLoc, the snapshot baseline of Italiano et al. 2026 (section 4.3, after their ref. 13).

Per epoch, without memory:

- LoS: the tuple ``(phi, psi, kappa)`` of the LoS path gives ``p_u = b + kappa u(phi, psi)``;
  without a curvature the delay distance ``d`` (carrying the clock bias) replaces ``kappa``;
- NLoS: minimise eq. 69 over ``p_u``. The paper prints a plain sum of residuals
  ``sum_l w_l (||p_u - p_s,l|| - d_l + kappa_l)``, which is unbounded below; we minimise the sum of
  *squared* residuals (least squares, the form the paper's "LS algorithm" needs) and, ours,
  optionally solve for the clock bias as a fourth unknown (``d_l = kappa_l + ||p_u - p_s,l|| + beta``)
  instead of assuming perfect synchronisation. ``p_s,l = b + kappa_l u_l`` is the reflector of
  eq. 19.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ..._validate import positive, vector
from .manage import los_test
from .measurement import PathMeasurements

__all__ = ["TeNFiLoc", "TeNFiLocFix"]


@dataclass
class TeNFiLocFix:
    """A snapshot fix: ``position`` (3,) or ``None``, the ``mode`` used and the path(s)."""

    position: np.ndarray | None
    mode: str  # "los-kappa" | "los-d" | "nlos" | "none"
    paths: tuple[int, ...] = ()


@dataclass
class TeNFiLoc:
    """Snapshot localisation from one epoch's paths (LoS tuple, else eq. 69).

    The LoS path is the one passing eq. 60-61; with ``assume_los`` (the paper's TeNFiLoc-L, LoS
    known to exist) the earliest arrival is taken when the test fails, as it is when no path has a
    curvature. NLoS fixes farther than ``max_range`` from the base station are refused.
    """

    los_gamma: float = 0.2
    base_station: tuple[float, float, float] = (0.0, 0.0, 0.0)
    estimate_bias: bool = True
    nlos: bool = True
    assume_los: bool = False
    max_range: float = 200.0

    def __post_init__(self) -> None:
        positive("max_range", self.max_range)
        g = positive("los_gamma", self.los_gamma)
        if g > 1:
            raise ValueError(f"los_gamma: must lie in (0, 1], got {g}")
        self.base_station = tuple(float(v) for v in vector("base_station", self.base_station, 3))

    def locate(
        self, paths: PathMeasurements | None, *, los_path: int | None = None, initial=None
    ) -> TeNFiLocFix:
        """Fix from ``paths``; ``los_path`` forces the LoS path (else eq. 60-61 decides)."""
        if paths is None or len(paths) == 0:
            return TeNFiLocFix(None, "none")
        b = np.asarray(self.base_station)
        u = paths.directions()
        j = los_path if los_path is not None else los_test(paths.d, paths.kappa, self.los_gamma)
        no_kappa = not np.isfinite(paths.kappa).any()
        if j is None and (no_kappa or self.assume_los) and np.isfinite(paths.d).any():
            j = int(np.nanargmin(paths.d))  # the LoS is the earliest arrival
        if j is not None:
            if np.isfinite(paths.kappa[j]):
                return TeNFiLocFix(b + paths.kappa[j] * u[j], "los-kappa", (int(j),))
            if np.isfinite(paths.d[j]):
                return TeNFiLocFix(b + paths.d[j] * u[j], "los-d", (int(j),))
        if not self.nlos:
            return TeNFiLocFix(None, "none")
        return self._nlos(paths, u, b, initial)

    def _nlos(self, paths, u, b, initial) -> TeNFiLocFix:
        ok = np.flatnonzero(np.isfinite(paths.kappa) & np.isfinite(paths.d))
        need = 4 if self.estimate_bias else 3
        if ok.size < need:
            return TeNFiLocFix(None, "none")
        ps = b + paths.kappa[ok, None] * u[ok]
        excess = paths.d[ok] - paths.kappa[ok]

        def resid(theta):
            beta = theta[3] if self.estimate_bias else 0.0
            return np.linalg.norm(theta[:3] - ps, axis=1) - excess + beta

        p0 = np.mean(ps, axis=0) if initial is None else np.asarray(initial, dtype=float)
        theta0 = np.append(p0, 0.0) if self.estimate_bias else p0
        sol = least_squares(resid, theta0, method="lm" if ok.size > theta0.size else "trf")
        if (
            not (sol.success and np.all(np.isfinite(sol.x)))
            or np.linalg.norm(sol.x[:3] - b) > self.max_range
        ):
            return TeNFiLocFix(None, "none")
        return TeNFiLocFix(sol.x[:3], "nlos", tuple(int(k) for k in ok))
