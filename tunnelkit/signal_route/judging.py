"""A fit judged against noise plus the impairment power the route was told about.

The ML extraction tests its own fit against white noise (``fit_ok``: the residual's energy and
its strongest single-path component, :mod:`tunnelkit.extraction.ml`). Eq. 1 leaves the array's
calibration error and the diffuse multipath out, so on an impaired channel the residual also
carries model error and the test flags fits that found every path: on the 28 GHz example at
0.5 deg of phase error, 7 of 10 epochs on 4 x 4 and 10 of 10 on 8 x 8, none on the ideal
channel. A route told its impairment levels (:attr:`RouteOptions.model_error_floor`) re-judges
such a fit with :func:`model_error_test`, the same two tests
with a floor of the impairments' share of the received power added (:func:`rejudge`: the
diffuse share and :func:`calibration_floor`; :func:`impairment_share` their expectation).

**The calibration share** (:func:`calibration_share`). One element's calibration gain is
``g = 10^(e/20) exp(j phi)``, ``phi ~ N(0, sigma_phi^2)``, ``e ~ N(0, sigma_dB^2)``
(:func:`tunnelkit.calibration.draw_calibration`); with ``s = sigma_dB ln(10) / 20`` the log-gain is
``N(0, s^2)``, so ``E g = exp(-sigma_phi^2 / 2) exp(s^2 / 2)`` and ``E |g|^2 = exp(2 s^2)``. The
part of the received power a calibrated model can carry is ``|E g|^2 / E |g|^2``; the rest,

    share_cal = 1 - exp(-sigma_phi^2 - s^2),

is the power of the element-to-element scatter about it, the model error of every path. It is
the share's **expectation over the array's draw**, not a bound on one draw. The fit's free
parameters absorb the scatter's projection on their tangent space (the mean gain into each
path's ``c``, its linear phase across the aperture into the direction, its quadratic phase into
the curvature): about ``5 L`` of the ``M`` dimensions, most of it on a small array (the 28 GHz
example's flagged fits needed 0.01-0.29 of the closed form on 4 x 4 and 8 x 8). On a large array
the fit absorbs little, and the scatter one drawn array leaves is ``S = sum_m w_m |delta_m|^2``
with ``w_m`` the share of the received power at element ``m``: 2 deg on 16 x 16, run 9 of seed
0, needed 1.11-1.16 times the closed form at 36 of 40 epochs, each fit at its maximum-likelihood
basin (restarted at the truth: the same cost), and every such epoch flagged left the tracker
dead-reckoning (settled error p90 7.5 cm against 1.7-3.3 cm on the other runs).

**The calibration floor** (:func:`calibration_floor`) is therefore the share at a stated
false-alarm rate over the draw, ``1 -`` :data:`FLOOR_FALSE_ALARM` (the residual tests' own
rate): ``S`` is a weighted sum of independent terms, one per element, whose cumulants are
``kappa_r(S) = kappa_r sum_m w_m^r`` with ``kappa_r`` those of one element's ``|g - E g|^2 /
E|g|^2`` (its first three moments by Gauss-Hermite quadrature over the log-gain and the phase;
the mean is the closed form above to 1e-12). The three-moment (Pearson type III) fit ``S ~ a + b
chi2_d``, ``b = kappa_3 / (4 kappa_2)``, ``d = 8 kappa_2^3 / kappa_3^2``, ``a = kappa_1 - b d``
gives the quantile. Against drawn arrays (M = 16, 64, 256; equal, two-wave interference and
log-normal weights): within 2 % of the 99 % quantile of ``S`` up to 20 deg and 2 dB (0.92-1.01
at 60 deg; with 3 dB of gain error 0.99-1.15; with 6 dB 0.37-1.17, the log-normal tail heavier
than three moments say). What a fit leaves is the scatter about the weighted sample mean (each
path's free gain takes the mean; its direction and curvature take more): against that quantile
the floor is conservative at every level tried (1.00-2.0), so the false-alarm rate after a fit
is at most about 1 %. The weights come from the fit's model tensor (what the receiver has, no
truth); the less equal they are, the higher the floor (run 9's epoch 12: ``1 / sum w^2`` = 223
of 256 elements, a factor of about 1.24 on the expectation). The diffuse multipath adds its
share of the received power (:class:`tunnelkit.channel.DiffuseSpec`) as it is: its energy spreads
over ``M`` times the effective number of delay taps of independent coefficients (a few % of
relative spread on 16 x 16 at the presets' 410 tones, more on small arrays and narrow bands),
which this floor does not take a quantile of.

**The bias budget** (:class:`BiasBudget`). A re-judged fit's covariance is the CRLB at the
estimate (:func:`~tunnelkit.signal_route.covariance.reported_covariance`, ``judged=False``),
which knows the noise only; the route adds the design's per-path budget of the impairments
(what :func:`tunnelkit.design.errordraws.split` puts on top of the noise
covariance) and hands its repeating share on as ``bias_cov`` (the tracker carries it as a bias
of the path's track). A budget is per candidate path (one slot per surface); the estimates are
matched to the slots by their wave origin's direction and delay (:meth:`BiasBudget.match`:
Hungarian assignment with the clock offset estimated from the matched pairs), never by the
surface's kind: a tunnel has two walls and two road-marking columns, each its own slot.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from .._physical import carrier
from .._validate import finite_array, instance, integer, nonnegative, positive, record, sequence
from ..channel import Impairments
from ..evaluation import match_points
from ..tracking.measurements import PathMeasurements

__all__ = [
    "FLOOR_FALSE_ALARM",
    "MATCH_DIRECTION",
    "MATCH_RANGE_M",
    "BiasBudget",
    "apply_budget",
    "calibration_floor",
    "calibration_share",
    "impairment_share",
    "model_error_test",
    "rejudge",
]

#: :meth:`BiasBudget.match`'s scales: a unit-vector difference of 0.1 (about 6 deg) or a delay
#: difference of 1 m each cost 1; assignments costing more than 10 are refused
MATCH_DIRECTION = 0.1
MATCH_RANGE_M = 1.0


def calibration_share(phase_sigma_deg: float, gain_sigma_db: float) -> float:
    """``1 - exp(-sigma_phi^2 - s^2)``, ``s = gain_sigma_db ln(10) / 20``: the share of the
    received power the per-element calibration error puts outside eq. 1 (module docstring): its
    expectation over the array's draw, not a bound on one draw (:func:`calibration_floor`)."""
    sp = np.radians(nonnegative("phase_sigma_deg", phase_sigma_deg))
    s = nonnegative("gain_sigma_db", gain_sigma_db) * np.log(10.0) / 20.0
    return float(-np.expm1(-(sp * sp) - s * s))


#: the false-alarm rate of :func:`calibration_floor` over the array's calibration draw (the
#: residual tests' own rate, :func:`tunnelkit.extraction.ml.calibrated_threshold`)
FLOOR_FALSE_ALARM = 0.01


def calibration_floor(
    phase_sigma_deg: float,
    gain_sigma_db: float,
    element_power,
    false_alarm: float = FLOOR_FALSE_ALARM,
) -> float:
    """The share of the received power one drawn array's calibration error leaves about its
    expectation, ``S = sum_m w_m |g_m - E g|^2 / E|g|^2``, at ``1 - false_alarm`` over the draw
    (module docstring): the three-moment (Pearson type III) fit to ``S`` from the exact first
    three cumulants of one element's term (Gauss-Hermite quadrature over the log-gain and the
    phase, :func:`_element_cumulants`), ``kappa_r(S) = kappa_r sum_m w_m^r``; ``w_m`` =
    ``element_power`` (M,) normalised (the received power per element, e.g. of the fit's model
    tensor). Its mean is :func:`calibration_share`. 0 without calibration error; at most 1."""
    from scipy.stats import chi2

    share = calibration_share(phase_sigma_deg, gain_sigma_db)
    p = finite_array("element_power", element_power, ndim=1)
    if p.size < 1 or np.any(p < 0) or not p.sum() > 0:
        raise ValueError("element_power: expected (M,) non-negative powers, not all zero")
    a = positive("false_alarm", false_alarm)
    if not a < 0.5:
        raise ValueError(f"false_alarm: a rate below 0.5, got {a:g}")
    if share == 0.0:
        return 0.0
    k1, k2, k3 = _element_cumulants(float(phase_sigma_deg), float(gain_sigma_db))
    w = p / p.max()
    w = w / w.sum()
    K1, K2, K3 = k1, k2 * float(np.sum(w**2)), k3 * float(np.sum(w**3))
    if not K3 > 0:  # the third cumulant underflows at vanishing levels: the normal quantile
        from scipy.stats import norm

        return float(min(K1 + np.sqrt(K2) * norm.ppf(1.0 - a), 1.0))
    b, d = K3 / (4.0 * K2), 8.0 * K2**3 / K3**2
    return float(min(K1 - b * d + b * chi2.ppf(1.0 - a, d), 1.0))


@lru_cache(maxsize=64)
def _element_cumulants(phase_sigma_deg: float, gain_sigma_db: float) -> tuple:
    """The first three cumulants of one element's scatter ``|g - E g|^2 / E|g|^2``, ``g =
    exp(l + j phi)``, ``l ~ N(0, s^2)``, ``phi ~ N(0, sigma_phi^2)``: its first three moments by
    Gauss-Hermite quadrature (80 x 80 nodes; the mean agrees with :func:`calibration_share` to
    1e-12 up to 60 deg and 6 dB, ``tests/test_route_judging.py``)."""
    x, wq = np.polynomial.hermite_e.hermegauss(80)
    wq = wq / wq.sum()
    sp = np.radians(phase_sigma_deg)
    s = gain_sigma_db * np.log(10.0) / 20.0
    eg = np.exp(-sp * sp / 2 + s * s / 2)
    g = np.exp(s * x[:, None] + 1j * sp * x[None, :])
    X = np.abs(g - eg) ** 2 / np.exp(2 * s * s)
    W = wq[:, None] * wq[None, :]
    m1, m2, m3 = (float(np.sum(W * X**r)) for r in (1, 2, 3))
    return m1, m2 - m1 * m1, m3 - 3 * m1 * m2 + 2 * m1**3


def impairment_share(impairments: Impairments) -> float:
    """The model-error floor of a route with ``impairments``: :func:`calibration_share` of its
    calibration levels plus the diffuse multipath's share (0 without), at most 1."""
    instance("impairments", impairments, Impairments)
    share = calibration_share(impairments.phase_sigma_deg, impairments.gain_sigma_db)
    if impairments.dmc is not None:
        share += float(impairments.dmc.share)
    return min(share, 1.0)


def rejudge(est, H, element_positions, fc: float, share: float, calibration=None):
    """The ML fit ``est`` (a :class:`tunnelkit.extraction.PathEstimates` with its ``fit``) of
    the received tensor ``H`` (M, Nf, Nt) of an array with ``element_positions`` at carrier
    ``fc`` judged against noise plus ``share`` of the received power, plus, with
    ``calibration`` = ``(phase_sigma_deg, gain_sigma_db)``, the :func:`calibration_floor` of
    those levels with the fit's model tensor's power per element (``share`` then holds the
    rest: the diffuse share).

    :func:`model_error_test` of its residual ``H - mu`` (eq. 1
    of the estimates' model tensor, :meth:`~tunnelkit.extraction.PathEstimates.model_tensor`),
    the received energy ``||H||^2`` and the noise power the fit tested against gives each
    test's share, the residual energy's at the fit's own threshold ``fit.rho_max``, not at the
    test's default ``1 + z / sqrt(N)``: the fit's also allows for a noise power estimated from
    the tensor, and the stricter one flags fits the extraction itself passes (28 GHz example,
    4 x 4, 0.5 deg, epoch 0: ``rho`` 1.021 below the fit's 1.036, share 4.2e-4 needed by the
    other). Only a fit flagged by its residual tests alone is re-judged; a path below the noise
    or an unresolved pair stays flagged (``residual_only`` False). Returns the test's dict with
    ``passed``, ``needed`` (the larger of the two shares, at least 0), ``share`` (the floor
    applied, calibration included), ``calibration_floor`` (0 without), ``residual_only``."""

    fit = getattr(est, "fit", None)
    if fit is None:
        raise ValueError("est: expected estimates of the ML route (with a fit), got none")
    pos = finite_array("element_positions", element_positions, ndim=2)
    if pos.shape[0] < 1 or pos.shape[1] != 3:
        raise ValueError(f"element_positions: expected shape (M, 3), got {pos.shape}")
    if not np.iscomplexobj(H):
        raise TypeError(f"H: expected a complex channel tensor, got dtype {np.asarray(H).dtype}")
    H = finite_array("H", H, ndim=3, dtype=complex)
    if H.shape[0] != pos.shape[0]:
        raise ValueError(f"H: expected an (M, Nf, Nt) tensor of the array's M, got {H.shape}")
    fc = carrier("fc", fc)
    share = nonnegative("share", share)
    if share > 1.0:
        raise ValueError(f"share: a share of the received power, at most 1, got {share:g}")
    element_positions = pos
    e_y, n0, L = float(np.vdot(H, H).real), float(fit.noise_power), len(est)
    mu = est.model_tensor()
    residual = H - mu
    floor = 0.0
    if calibration is not None:
        cal = finite_array("calibration", sequence("calibration", calibration), ndim=1)
        if cal.shape != (2,):
            raise ValueError(
                f"calibration: expected (phase_sigma_deg, gain_sigma_db), got {cal.size} values"
            )
        floor = calibration_floor(*cal, np.sum(np.abs(mu) ** 2, axis=(1, 2)))
        share = min(share + floor, 1.0)
    out = model_error_test(
        residual, L, e_y, element_positions, fc, n0, share, rho_max=float(fit.rho_max)
    )
    reasons = {r.strip() for r in str(fit.reason).split(",") if r.strip()}
    residual_only = reasons <= {"residual peak", "residual energy"}
    out.update(
        passed=bool(residual_only and out["passed"]),
        share=float(share),
        calibration_floor=float(floor),
        residual_only=bool(residual_only),
    )
    return out


@dataclass(frozen=True)
class BiasBudget:
    """The design's per-path impairment budget over a route's epochs, by candidate slot.

    ``source`` (T, P, 3) each slot's wave origin (the UE or its virtual image), ``exists``
    (T, P), ``origin`` (T, 3) the reference antenna of the array facing the vehicle, ``extra``
    (T, P, 4, 4) the covariance of ``[phi, psi, kappa, d]`` (world frame) the impairments add
    to the noise's, ``repeating`` (T, P, 4, 4) its share one drive repeats every epoch (both
    zero where a slot is absent)."""

    source: np.ndarray
    exists: np.ndarray
    origin: np.ndarray
    extra: np.ndarray
    repeating: np.ndarray

    def __post_init__(self) -> None:
        blocks = ("T", "P", 4, 4)
        record(self, shapes={"source": ("T", "P", 3), "exists": ("T", "P"), "origin": ("T", 3),
                             "extra": blocks, "repeating": blocks})  # fmt: skip
        for name in ("source", "origin", "extra", "repeating"):
            finite_array(name, getattr(self, name))
        if np.asarray(self.exists).dtype != bool:
            raise TypeError(f"exists: expected a boolean (T, P) mask, got {self.exists.dtype}")

    def match(self, k: int, d, direction) -> np.ndarray:
        """The slot (index into P, -1 if none) of each estimate at epoch ``k``: ``d`` (K,) its
        biased distance, ``direction`` (K, 3) its world unit vector; matched on direction and
        delay with the clock offset unknown (first by the earliest arrivals, then by the median
        over the matched pairs)."""
        k = integer("k", k, minimum=0, maximum=self.exists.shape[0] - 1)
        d = finite_array("d", d, ndim=1)
        u = finite_array("direction", direction, ndim=2)
        if u.shape != (d.size, 3):
            raise ValueError(
                f"d, direction: expected one (3,) direction per d ({d.size}), got {u.shape}"
            )
        slots = np.flatnonzero(self.exists[k])
        out = -np.ones(d.size, int)
        if not d.size or not slots.size:
            return out
        rel = self.source[k, slots] - self.origin[k]
        r = np.linalg.norm(rel, axis=1)
        ut = rel / r[:, None]
        offset = float(d.min() - r.min())
        for _ in range(2):
            idx = match_points(
                d - offset, u, r, ut, direction_scale=MATCH_DIRECTION, range_scale=MATCH_RANGE_M
            )
            ok = idx >= 0
            if ok.any():
                offset = float(np.median(d[ok] - r[idx[ok]]))
        out[ok] = slots[idx[ok]]
        return out


def apply_budget(meas, budget: BiasBudget, k: int):
    """``meas`` (a :class:`~tunnelkit.tracking.javelin.PathMeasurements` with
    reported covariances) with the budget of its matched slots added: ``cov`` + the ``(phi, psi,
    kappa)`` block of ``extra``, ``sigma_d`` in quadrature with its ``d`` variance, ``bias_cov``
    the slots' ``repeating`` (zero for an estimate matched to no slot)."""
    instance("meas", meas, PathMeasurements)
    instance("budget", budget, BiasBudget)
    integer("k", k, minimum=0, maximum=budget.exists.shape[0] - 1)
    if meas.cov is None or not len(meas):
        return meas
    slot = budget.match(k, meas.d, meas.direction)
    hit = slot >= 0
    extra = np.zeros((len(meas), 4, 4))
    rep = np.zeros((len(meas), 4, 4))
    extra[hit] = budget.extra[k, slot[hit]]
    rep[hit] = budget.repeating[k, slot[hit]]
    return replace(
        meas,
        cov=meas.cov + extra[:, :3, :3],
        sigma_d=np.sqrt(meas.sigma_d**2 + extra[:, 3, 3]),
        bias_cov=rep,
    )


def model_error_test(
    residual,
    n_paths: int,
    received_energy: float,
    element_positions,
    fc: float,
    noise_power: float,
    share: float,
    rho_max: float | None = None,
) -> dict:
    """The extraction's residual tests with a stated model-error floor.

    A fit's residual ``residual`` (M, Nf, Nt) of ``n_paths`` paths passes when its strongest
    single-path component (the periodogram peak of
    :func:`~tunnelkit.extraction.ml.residual_peak`, times ``noise_power``) is at most the
    noise-only threshold (:func:`~tunnelkit.extraction.ml.calibrated_threshold`) times
    ``noise_power`` plus ``share * E_rx``, and its energy at most the basin test's
    ``rho_max (N - 2.5 L) noise_power`` plus ``share * E_rx``; ``E_rx = received_energy -
    N noise_power`` (``received_energy`` = ``||Y||^2`` of the snapshot): the model error the
    deployed system allows, stated as a share of the received power (like a DMC share; the
    residual a fit leaves at the pseudo-true paths, :func:`pseudo_true`, is what it stands for
    and what no deployed system knows). ``share = 0`` is the plain test. ``rho_max`` (> 0) is
    the energy test's threshold; ``None`` takes ``1 + z / sqrt(N)`` (:data:`RHO_Z`); a fit's own
    ``fit.rho_max``, which also allows for a noise power estimated from the tensor, is the
    looser one its extraction applied.

    Returns ``passed``, ``needed`` the smallest share that passes, ``share_peak`` /
    ``share_energy`` each test's, ``peak`` (noise powers) and ``rho``."""
    from ..arrays import check_element_positions
    from ..extraction.ml import calibrated_threshold, residual_peak
    from ..extraction.ml.fitting import RHO_Z

    R = np.asarray(residual)
    if R.ndim != 3 or not np.iscomplexobj(R) or not np.all(np.isfinite(R)):
        raise ValueError(f"residual: expected a finite complex (M, Nf, Nt) tensor, got {R.shape}")
    pos = check_element_positions("element_positions", element_positions, m=R.shape[0])
    fc = carrier("fc", fc)
    n0 = positive("noise_power", noise_power)
    L = integer("n_paths", n_paths, minimum=0, maximum=R.size)
    e_y = positive("received_energy", received_energy)
    share = nonnegative("share", share)
    N = R.size
    rho_max = 1.0 + RHO_Z / np.sqrt(N) if rho_max is None else positive("rho_max", rho_max)
    e_rx = max(e_y - N * n0, 1e-300 * e_y)
    peak = residual_peak(R, pos, fc, n0)[0]
    thr = calibrated_threshold(pos, fc, R.shape)
    energy = float(np.vdot(R, R).real)
    s_peak = (peak - thr) * n0 / e_rx
    s_energy = (energy - rho_max * (N - 2.5 * L) * n0) / e_rx
    needed = max(s_peak, s_energy, 0.0)
    return {
        "passed": bool(needed <= share),
        "needed": float(needed),
        "share_peak": float(s_peak),
        "share_energy": float(s_energy),
        "peak": float(peak),
        "rho": energy / ((N - 2.5 * L) * n0),
    }
