"""TeNFiLoc, the snapshot baseline of Italiano et al. 2026 (section 4.3, after their ref. 13).

Per epoch, without memory (:meth:`TeNFiLoc.locate`, a :class:`TeNFiLocFix`): the LoS path's
``(phi, psi, kappa)`` gives the fix; without a LoS path, the least-squares solution of eq. 69
(ours: squared residuals, optionally the clock bias as a fourth unknown). Every branch refuses a
fix farther than ``max_range`` from the base station; the tracking loop then holds the previous
fix.

How it works, and where it departs from the paper: docs/internals/tracking.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.optimize import least_squares

from ..._checks import attributes, real_array
from ..._validate import choice, instance, integer, positive, record, vector
from ...constants import C
from ..registry import register
from .lostest import los_test
from .measurement import PathMeasurements

__all__ = ["TeNFiLoc", "TeNFiLocFix"]


#: what :meth:`TeNFiLoc.for_drive` reads of a drive
_DRIVE = ("condition", "base_station", "clock_bias_limit")


@dataclass
class TeNFiLocFix:
    """A snapshot fix: ``position`` (3,) or ``None``, the ``mode`` used and the path(s)."""

    position: np.ndarray | None
    mode: str  # "los-kappa" | "los-d" | "nlos" | "none"
    paths: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        record(self, shapes={"position": (3,)}, may_be_empty=("paths",))
        choice("mode", self.mode, ("los-kappa", "los-d", "nlos", "none"))


@dataclass
@register("italiano2026", "TeNFiLoc")
class TeNFiLoc:
    """Snapshot localisation from one epoch's paths (LoS tuple, else eq. 69).

    The LoS path is the one passing eq. 60-61; with ``assume_los`` (the paper's TeNFiLoc-L, LoS
    known to exist) the earliest arrival is taken when the test fails, as it is when no path has a
    curvature. Its curvature gives the range if plausible (``0 < kappa <= max_range`` and
    ``|d - kappa| <= bias_limit``), else its delay distance ``d`` does. ``bias_limit`` [m] is the
    support of the clock bias times c (default: the 100 ns of section 4.2, 30 m). Fixes farther
    than ``max_range`` from the base station are refused on every branch.
    """

    name: ClassVar[str] = "TeNFiLoc"
    los_gamma: float = 0.2
    base_station: tuple[float, float, float] = (0.0, 0.0, 0.0)
    estimate_bias: bool = True
    nlos: bool = True
    assume_los: bool = False
    max_range: float = 200.0
    bias_limit: float = C * 100e-9

    def __post_init__(self) -> None:
        record(self, skip=("base_station",))
        positive("max_range", self.max_range)
        positive("bias_limit", self.bias_limit)
        g = positive("los_gamma", self.los_gamma)
        if g > 1:
            raise ValueError(f"los_gamma: must lie in (0, 1], got {g}")
        self.base_station = tuple(float(v) for v in vector("base_station", self.base_station, 3))

    # -- the family protocol (tunnelkit.tracking.registry, "italiano2026") ----------------------
    @classmethod
    def for_drive(cls, drive, design=None) -> TeNFiLoc:
        """The baseline for a simulated drive: the base station at its reference antenna, LoS
        assumed when the drive's condition keeps it (TeNFiLoc-L), the clock-bias support of its
        route. ``design`` must be ``None`` (TeNFiLoc has no tracker design)."""
        if design is not None:
            raise ValueError(f"design: TeNFiLoc takes no tracker design, got {design!r}")
        attributes("drive", drive, _DRIVE, "a simulated drive (simulation.DriveData)")
        cond = drive.condition
        return cls(
            base_station=tuple(float(v) for v in drive.base_station),
            assume_los=cond is None or cond.los_probability == 1.0,
            bias_limit=C * max(drive.clock_bias_limit, 1e-12),
        )

    def track(self, drive) -> tuple[np.ndarray, np.ndarray]:
        """Fixes per epoch (T, 3) and which epochs had a fix; without a fix the previous one is
        held (the true start position before the first), so every epoch has an estimate."""
        attributes("drive", drive, ("truth", "epochs"), "a simulated drive (simulation.DriveData)")
        out = np.empty_like(np.asarray(drive.truth, dtype=float))
        ok = np.zeros(len(drive.epochs), bool)
        last = np.asarray(drive.truth[0], dtype=float).copy()
        for k, m in enumerate(drive.epochs):
            fix = self.locate(m, initial=last)
            if fix.position is not None and np.all(np.isfinite(fix.position)):
                last = fix.position
                ok[k] = True
            out[k] = last
        return out, ok

    def locate(
        self, paths: PathMeasurements | None, *, los_path: int | None = None, initial=None
    ) -> TeNFiLocFix:
        """Fix from ``paths``; ``los_path`` forces the LoS path (else eq. 60-61 decides)."""
        if paths is not None:
            instance("paths", paths, PathMeasurements)
        if los_path is not None:
            integer("los_path", los_path, minimum=0)
        if initial is not None:
            vector("initial", initial, 3)
        if paths is None or len(paths) == 0:
            return TeNFiLocFix(None, "none")
        b = np.asarray(self.base_station)
        u = paths.direction
        j = los_path if los_path is not None else los_test(paths.d, paths.kappa, self.los_gamma)
        no_kappa = not np.isfinite(paths.kappa).any()
        if j is None and (no_kappa or self.assume_los) and np.isfinite(paths.d).any():
            j = int(np.nanargmin(paths.d))  # the LoS is the earliest arrival
        if j is not None:
            fix = self._los(paths, u, b, int(j))
            if fix is not None:
                return fix
        if not self.nlos:
            return TeNFiLocFix(None, "none")
        return self._nlos(paths, u, b, initial)

    def plausible_kappa(self, kappa: float, d: float) -> bool:
        """Whether a LoS curvature can be a range: positive, within ``max_range``, and (when the
        delay is known) within the clock-bias support of it, ``|d - kappa| <= bias_limit``."""
        real_array("kappa", kappa, ndim=0), real_array("d", d, ndim=0)
        if not (np.isfinite(kappa) and 0.0 < kappa <= self.max_range):
            return False
        return not np.isfinite(d) or abs(d - kappa) <= self.bias_limit

    def _los(self, paths, u, b, j: int) -> TeNFiLocFix | None:
        """LoS fix from path ``j``: its curvature if plausible, else its delay distance."""
        kappa, d = float(paths.kappa[j]), float(paths.d[j])
        if self.plausible_kappa(kappa, d):
            return TeNFiLocFix(b + kappa * u[j], "los-kappa", (j,))
        if np.isfinite(d) and 0.0 < d <= self.max_range:
            return TeNFiLocFix(b + d * u[j], "los-d", (j,))
        return None

    def _nlos(self, paths, u, b, initial) -> TeNFiLocFix:
        kappa = np.where(np.isfinite(paths.kappa), paths.kappa, -1.0)
        ok = np.flatnonzero((kappa > 0) & (kappa <= self.max_range) & np.isfinite(paths.d))
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
            or (self.estimate_bias and abs(sol.x[3]) > self.bias_limit)
        ):
            return TeNFiLocFix(None, "none")
        return TeNFiLocFix(sol.x[:3], "nlos", tuple(int(k) for k in ok))
