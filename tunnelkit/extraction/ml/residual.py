"""The residual test of the maximum-likelihood stage: the largest peak of the residual's
single-path periodogram against its noise-only distribution (:func:`residual_peak`,
:func:`peak_threshold`).

The statistic is also the GLRT of one path more. The threshold the fit uses is calibrated by
simulation on noise-only tensors of the same array and shape (:func:`peak_null`,
:func:`calibrated_threshold`, at ``FALSE_ALARM``); the notebooks' calibrations are stored in
:data:`STORE` (:func:`calibration_store`).

How it works: docs/internals/extraction-ml.md.
"""

from __future__ import annotations

import hashlib
import json

import numpy as np
import scipy.fft

from ..._physical import carrier
from ..._validate import finite_array, integer, positive
from ...budget import check_elements
from ..numerics import scan_grid

__all__ = [
    "CALIBRATION_DRAWS",
    "FALSE_ALARM",
    "OVERSAMPLING_CELLS",
    "STORE",
    "calibrated_threshold",
    "calibration_store",
    "peak_null",
    "peak_threshold",
    "residual_peak",
]

#: false-alarm rate of the residual test on a right fit (per snapshot)
FALSE_ALARM = 0.01
#: effective independent cells per grid point of the oversampled search (noise-only calibration)
OVERSAMPLING_CELLS = 16.0
#: noise-only draws of a calibration (:func:`calibrated_threshold`), and the seed it draws with
CALIBRATION_DRAWS = 200
CALIBRATION_SEED = 20231123
#: share of the draws above the tail's start (the tail fitted above that quantile)
TAIL_SHARE = 0.25
#: the stored calibrations, under the data folder (:func:`tunnelkit.scenarios.data_dir`)
STORE = "extraction/residual-null.json"
#: what a stored calibration must have been made with
_SETTINGS = {"draws": CALIBRATION_DRAWS, "seed": CALIBRATION_SEED, "tail_share": TAIL_SHARE,
             "n_cells": 8}  # fmt: skip
_NULL_CACHE: dict = {}
_STORED: dict = {}


def peak_threshold(n_samples: int, false_alarm: float = FALSE_ALARM) -> float:
    """The threshold ``t`` on the largest normalised periodogram peak (:func:`residual_peak`)
    exceeded by noise alone with probability ``false_alarm``: ``P(max > t) = 1 - (1 -
    e^{-t})^K = false_alarm`` with ``K = OVERSAMPLING_CELLS * n_samples`` cells."""
    n = integer("n_samples", n_samples, minimum=1)
    pfa = _check_pfa(false_alarm)
    K = OVERSAMPLING_CELLS * n
    return float(-np.log(-np.expm1(np.log1p(-pfa) / K)))


def residual_peak(R, element_positions, fc: float, noise_power: float, *, n_cells: int = 8):
    """Largest peak of the single-path periodogram of the residual ``R`` (M, Nf, Nt) in units of
    the noise power (exponential with mean 1 per point under noise) and where it lies.

    Returns ``(peak, (u_x, u_y, mu_f, mu_t), x)``: the peak, its far-field direction cosines and
    Vandermonde frequencies, and the spatial vector ``x`` (M,) of its delay-Doppler cell (a
    start for a single-source fit). ``element_positions`` (M, 3) local, ``fc`` the carrier.
    """
    R = np.asarray(R)
    if R.ndim != 3 or not np.iscomplexobj(R):
        raise ValueError(f"R: expected a complex (M, Nf, Nt) tensor, got {R.dtype} {R.shape}")
    finite_array("R", R, dtype=complex)
    p = np.ascontiguousarray(finite_array("element_positions", element_positions))
    if p.ndim != 2 or p.shape != (R.shape[0], 3):
        raise ValueError(f"element_positions: expected shape ({R.shape[0]}, 3), got {p.shape}")
    fc = carrier("fc", fc)
    sigma2 = positive("noise_power", noise_power)
    n_cells = integer("n_cells", n_cells, minimum=1)
    M, nf, nt = R.shape
    nf2, nt2 = 2 * nf, 2 * nt
    # <f(mu) o t(nu), R[m]> = sum_s,k R conj(e^{j s mu} e^{j k nu}): the FFT at mu = 2 pi i / nf2
    Y = scipy.fft.fft2(R.astype(np.complex64), s=(nf2, nt2), axes=(1, 2), workers=1)
    E = np.einsum("mij,mij->ij", Y.real, Y.real) + np.einsum("mij,mij->ij", Y.imag, Y.imag)
    top = np.argpartition(E.ravel(), -n_cells)[-n_cells:]
    u, A = scan_grid(p, fc)
    X = Y.reshape(M, -1)[:, top].astype(complex)  # (M, n_cells)
    S = np.abs(A.conj().T @ X) ** 2  # (G, n_cells)
    g, c = np.unravel_index(int(np.argmax(S)), S.shape)
    i, j = np.unravel_index(int(top[c]), E.shape)
    peak = float(S[g, c] / (R.size * sigma2))
    mu_f = float(np.angle(np.exp(2j * np.pi * i / nf2)))
    mu_t = float(np.angle(np.exp(2j * np.pi * j / nt2)))
    return peak, (float(u[g, 0]), float(u[g, 1]), mu_f, mu_t), X[:, c]


def _check_pfa(false_alarm) -> float:
    pfa = positive("false_alarm", false_alarm)
    if pfa >= 1.0:
        raise ValueError(f"false_alarm: expected a probability below 1, got {pfa}")
    return pfa


def _check_null_args(element_positions, fc, shape):
    """``(positions (M, 3), fc, (M, Nf, Nt))`` checked, each error naming its parameter."""
    try:
        M, nf, nt = (int(v) for v in shape)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"shape: expected (M, Nf, Nt), got {shape!r}") from exc
    if min(M, nf, nt) < 1 or M * nf * nt > 10**8:
        raise ValueError(f"shape: expected positive sizes, at most 1e8 samples, got {shape!r}")
    try:
        p = np.ascontiguousarray(element_positions, float)
    except (TypeError, ValueError) as exc:
        raise ValueError("element_positions: expected a real (M, 3) array") from exc
    if p.ndim != 2 or p.shape != (M, 3) or not np.all(np.isfinite(p)):
        raise ValueError(f"element_positions: expected finite ({M}, 3), got {p.shape}")
    return p, carrier("fc", fc), (M, nf, nt)


def peak_null(
    element_positions, fc: float, shape, rng, *, n_draws: int = CALIBRATION_DRAWS, n_cells: int = 8
) -> tuple[float, float]:
    """The noise-only law of :func:`residual_peak` at this array, carrier and tensor ``shape``
    (M, Nf, Nt): ``n_draws`` tensors of unit-power white circular Gaussian noise drawn from
    ``rng`` (a ``numpy.random.Generator``), the largest peak of each, and an exponential tail
    fitted above their ``1 - TAIL_SHARE`` quantile ``x_q`` (the tail of the largest of many
    near-exponential cells; its scale ``s`` the mean excess over ``x_q``, the maximum-likelihood
    estimate). Returns ``(x_q, s)``: ``P(peak > t) = TAIL_SHARE e^{-(t - x_q) / s}`` for ``t >=
    x_q``."""
    p, fc, (M, nf, nt) = _check_null_args(element_positions, fc, shape)
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"rng: expected a numpy.random.Generator, got {type(rng).__name__}")
    n_draws = integer("n_draws", n_draws, minimum=10)
    check_elements("n_draws", n_draws, what=f"{n_draws} noise-only peaks")
    n_cells = integer("n_cells", n_cells, minimum=1)
    pk = np.empty(n_draws)
    for i in range(n_draws):
        pk[i] = residual_peak(_noise(rng, (M, nf, nt)), p, fc, 1.0, n_cells=n_cells)[0]
    x_q = float(np.quantile(pk, 1.0 - TAIL_SHARE))
    return x_q, float(np.mean(pk[pk > x_q] - x_q))


def calibrated_threshold(
    element_positions, fc: float, shape, false_alarm: float = FALSE_ALARM
) -> float:
    """The threshold on :func:`residual_peak` that noise alone exceeds with probability
    ``false_alarm`` at this array, carrier and tensor ``shape``: :func:`peak_null` with
    ``CALIBRATION_DRAWS`` draws from a generator seeded ``CALIBRATION_SEED`` (reproducible; one
    calibration per array and shape, kept for the process), ``t = x_q + s ln(TAIL_SHARE / pfa)``
    for ``false_alarm <= TAIL_SHARE`` (``ValueError`` above: use the empirical quantile)."""
    pfa = _check_pfa(false_alarm)
    if pfa > TAIL_SHARE:
        raise ValueError(f"false_alarm: the calibrated tail holds up to {TAIL_SHARE}, got {pfa}")
    p, fc, shape = _check_null_args(element_positions, fc, shape)
    key = (p.shape, np.round(p, 9).tobytes(), round(fc, 3), shape)
    if key not in _NULL_CACHE:
        law = _stored_law(p, fc, shape)
        if law is None:
            law = peak_null(p, fc, shape, np.random.default_rng(CALIBRATION_SEED))
        _NULL_CACHE[key] = (*law, p, fc, shape)
    x_q, s = _NULL_CACHE[key][:2]
    return float(x_q + s * np.log(TAIL_SHARE / pfa))


def _noise(rng, shape) -> np.ndarray:
    """One noise-only tensor of unit-power white circular Gaussian noise."""
    return rng.standard_normal((*shape, 2)).view(complex)[..., 0] * np.sqrt(0.5)


def _first_peak(p, fc, shape) -> float:
    """The peak of a calibration's first noise-only draw (its check on load)."""
    R = _noise(np.random.default_rng(CALIBRATION_SEED), shape)
    return residual_peak(R, p, fc, 1.0, n_cells=_SETTINGS["n_cells"])[0]


def _entry_key(p, fc, shape) -> tuple:
    digest = hashlib.sha256(np.round(p, 9).astype("<f8").tobytes()).hexdigest()
    return digest, round(float(fc), 3), tuple(int(n) for n in shape)


def _stored_law(p, fc, shape):
    """``(x_q, s)`` of the stored calibration of this array, carrier and shape, or None (none
    stored, made with other settings, or its first draw's peak not reproduced now)."""
    if "entries" not in _STORED:
        from ...scenarios import data_dir

        path, entries = data_dir() / STORE, {}
        if path.is_file():
            rec = json.loads(path.read_text())
            if rec.get("settings") == _SETTINGS:
                for e in rec.get("entries", []):
                    entries[(e["positions"], e["fc"], tuple(e["shape"]))] = e
        _STORED["entries"] = entries
    e = _STORED["entries"].get(_entry_key(p, fc, shape))
    if e is None or _first_peak(p, fc, shape) != e["first_peak"]:
        return None
    return float(e["x_q"]), float(e["s"])


def calibration_store() -> dict:
    """This process's calibrations (every array, carrier and shape :func:`calibrated_threshold`
    met) as the record :data:`STORE` holds: ``settings`` and per calibration the digest of the
    element positions, ``fc``, ``shape``, the tail ``x_q`` and ``s``, and ``first_peak`` (the
    first draw's peak, checked on load)."""
    entries = []
    for x_q, s, p, fc, shape in _NULL_CACHE.values():
        digest, fc_r, shp = _entry_key(p, fc, shape)
        entries.append({"positions": digest, "M": int(p.shape[0]), "fc": fc_r, "shape": list(shp),
                        "x_q": x_q, "s": s, "first_peak": _first_peak(p, fc, shape)})  # fmt: skip
    entries.sort(key=lambda e: (e["M"], e["fc"], e["shape"], e["positions"]))
    return {"procedure": f"{__name__}.peak_null", "settings": dict(_SETTINGS), "entries": entries}
