"""Design tables of the SR-NF validity: every bound beside the exact value, per design point.

:func:`mmax_summary` gathers the closed-form bounds of :mod:`tunnelkit.fresnel.bounds` and the
exact searches of :mod:`tunnelkit.fresnel.exact` for one geometry (:class:`MmaxSummary`);
:func:`design_report` makes a :class:`tunnelkit.report.Report` of them, one row per point, for
notebook 02's tables and the ``tunnelkit mmax`` command.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from .._physical import carrier
from .._validate import boolean, integer, positive, record, text
from ..report import Report
from .bounds import (
    mmax_2d,
    mmax_3d,
    mmax_fraunhofer,
    mmax_nonparaxial,
    paraxial_ratio,
    wall_geometry,
)
from .exact import M_LIMIT, M_LIMIT_URA, mmax_exact, mmax_exact_ura

__all__ = ["FC_PRESETS", "MmaxSummary", "design_report", "mmax_summary"]

#: carrier presets used by the explorer, the notebook's design table and the CLI [Hz]
FC_PRESETS: dict[str, float] = {"3.5 GHz": 3.5e9, "5.9 GHz": 5.9e9, "28 GHz": 28e9}


@dataclass(frozen=True)
class MmaxSummary:
    """Bounds and exact values for one design point (a row of a design table)."""

    R: float
    W: float
    y_u: float
    z_u: float
    fc: float
    eps_phi: float
    paraxial_ratio: float  #: |2W - y_u| / R (eq. 25 assumes << 1)
    eq25: float  #: mmax_2d
    eq37: float  #: mmax_3d at p_v = (R, 2W - y_u, z_u)
    nonparaxial: float  #: mmax_nonparaxial
    exact: int  #: mmax_exact (ULA)
    exact_ura: int  #: mmax_exact_ura (M x M URA of section 4.1)
    fraunhofer: float  #: mmax_fraunhofer(R)
    exact_capped: bool = False  #: the ULA search hit its limit: ``exact`` is a lower bound only
    exact_ura_capped: bool = False  #: the URA search hit its limit: ``exact_ura`` is a lower bound

    def __post_init__(self) -> None:
        record(
            self,
            positive=("R", "W", "fc", "eps_phi", "exact"),
            nonnegative=("paraxial_ratio", "eq25", "eq37", "nonparaxial", "fraunhofer"),
        )
        carrier("fc", self.fc)
        integer("exact_ura", self.exact_ura, minimum=-1)  # -1: the URA search was skipped

    @property
    def ratio(self) -> float | None:
        """eq. 25 over the exact ULA value (< 1: the bound is conservative); None when capped."""
        return None if self.exact_capped else self.eq25 / self.exact

    def as_dict(self) -> dict[str, float]:
        return {**asdict(self), "ratio": self.ratio}


def mmax_summary(
    R: float, W: float, y_u: float, fc: float, eps_phi: float, *, z_u: float = 0.0, ura: bool = True
) -> MmaxSummary:
    """All bounds and exact values for one design point (``ura=False`` skips the URA search)."""
    fc, eps_phi = carrier("fc", fc), positive("eps_phi", eps_phi)
    ura = boolean("ura", ura)
    s = dict(R=R, W=W, y_u=y_u, fc=fc, eps_phi=eps_phi)
    R_, W_, y_, z_ = (float(v) for v in wall_geometry(R, W, y_u, z_u))
    exact = mmax_exact(R_, W_, y_, float(fc), float(eps_phi), z_u=z_)
    exact_ura = mmax_exact_ura(R_, W_, y_, float(fc), float(eps_phi), z_u=z_) if ura else -1
    # an exact answer is always below the search limit; equal to it means the search stopped
    return MmaxSummary(
        R=R_,
        W=W_,
        y_u=y_,
        z_u=z_,
        fc=float(fc),
        eps_phi=float(eps_phi),
        paraxial_ratio=float(paraxial_ratio(R, W, y_u)),
        eq25=float(mmax_2d(**s)),
        eq37=float(mmax_3d([R_, 2 * W_ - y_, z_], fc, eps_phi)),
        nonparaxial=float(mmax_nonparaxial(**s, z_u=z_u)),
        exact=exact,
        exact_ura=exact_ura,
        fraunhofer=float(mmax_fraunhofer(R, fc)),
        exact_capped=exact >= M_LIMIT,
        exact_ura_capped=exact_ura >= M_LIMIT_URA,
    )


def design_report(points, *, title: str = "SR-NF validity: bounds vs exact Mmax", ura: bool = True):
    """A :class:`tunnelkit.report.Report` (text or JSON table), one row per design point.

    ``points`` is an iterable of dicts with keys ``R, W, y_u, fc, eps_phi`` (and optionally
    ``z_u``, ``label``).
    """
    if isinstance(points, str | bytes) or not hasattr(points, "__iter__"):
        raise TypeError(f"points: expected an iterable of dicts, got {type(points).__name__}")
    title, ura = text("title", title), boolean("ura", ura)
    points = list(points)
    if not points:
        raise ValueError("points: expected at least one design point")
    rows, recs = [], []
    for i, p in enumerate(points):
        if not isinstance(p, dict):
            raise TypeError(f"points: item {i} is a {type(p).__name__}, expected a dict")
        p = dict(p)
        label = str(p.pop("label", ""))
        s = mmax_summary(**p, ura=ura)
        recs.append(s)
        rows.append(
            [
                label,
                s.R,
                s.W,
                s.y_u,
                s.z_u,
                s.fc / 1e9,
                s.eps_phi,
                s.paraxial_ratio,
                s.eq25,
                s.eq37,
                s.nonparaxial,
                f">= {s.exact}" if s.exact_capped else s.exact,
                (f">= {s.exact_ura}" if s.exact_ura_capped else s.exact_ura) if ura else None,
                None if s.ratio is None else round(s.ratio, 3),
            ]
        )
    cols = [
        "case",
        "R [m]",
        "W [m]",
        "y_u [m]",
        "z_u [m]",
        "fc [GHz]",
        "eps [rad]",
        "(2W-y_u)/R",
        "eq.25",
        "eq.37",
        "2nd-order",
        "exact ULA",
        "exact URA MxM",
        "eq.25/exact",
    ]
    notes = [
        "eq.25: Theorem 3.1 (paraxial, assumes (2W-y_u)/R << 1); eq.37: Theorem 3.4 as printed",
        "2nd-order: eq. 41 corrected (SR curvature kept, no paraxial assumption)",
        "exact: largest M whose exact phase mismatch over the array stays <= eps (no expansion)",
    ]
    if any(s.exact_capped or s.exact_ura_capped for s in recs):
        notes.append(
            "'>= N': the exact search stopped at its limit N with the mismatch still <= eps; "
            "N is a lower bound, not the exact value (and eq.25/exact is left out)"
        )
    return Report(title=title, columns=cols, rows=rows, notes=notes)
