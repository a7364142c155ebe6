"""Every path the ray tracer returns, per antenna element, and the SRS tensor synthesised from them.

:class:`ElementPaths` holds Sionna RT's output with ``synthetic_array=False`` (one receiver per
element): for element ``m`` and path slot ``p``, the delay ``tau[m, p]``, the complex field
coefficient ``gain[m, p]`` (physical convention, carrier phase included:
``a exp(-j 2 pi fc tau)`` with Sionna's ``a``), the Doppler shift, the number of interactions
``order`` (0 = LoS), whether any interaction was diffuse, and the object id of the first bounce.

:func:`element_tensor` turns them into eq. 1's tensor. Eq. 1 as printed (:mod:`tunnelkit.channel`)
carries the carrier phase across the array with the sign opposite to the physical one
(``exp(+j k0 delta_lm)`` with ``delta_lm = d_lm - d_l0``) while its tone and symbol factors keep the
physical signs (``exp(-j 2 pi s Df tau)``, ``exp(+j 2 pi k f_d T0)``). Conjugating a physical
tensor reverses all three; reversing the tones and the symbols back gives eq. 1's form. Written
path by path, with the carrier ``fc`` at the band's centre tone ``s_c = (Nf - 1) / 2``::

    H[m, s, k] = sum_p conj(gain[m, p]) exp(-j 2 pi (s - s_c) Df tau[m, p]) exp(+j 2 pi k f_d[m, p] T0)

so element ``m``'s phase at tone ``s`` is ``k0 delta_lm (1 - (s - s_c) Df / fc)``: the carrier
phase at the centre tone, the spatial-wideband term (:func:`~tunnelkit.channel.channel_tensor`
with ``spatial_wideband=True``) around it. The tone reference matters: measured from tone 0
instead (the tensor before 2026-12-06), the whole band sat on one side of the carrier, which
scaled every path's direction cosines, as a narrowband model reads them, by ``1 - s_c Df / fc``
(0.9917 at the paper's 410 tones of 240 kHz at 5.9 GHz), which no physical mechanism does: on
the straight drive's 10 x 10 the direct fit's noiseless azimuth erred +0.07 to +0.19 deg at
7-34 m from it (``docs/results/traced-models.md``).

The sum costs ``Nf Nt P`` complex products per element (about 1.5e9 per epoch at the paper's
array with ~3,000 traced paths per element). Per element it is a two-dimensional type-1
non-uniform FFT: with ``x_p = -2 pi Df tau_p`` and ``y_p = 2 pi T0 f_d,p`` (folded into
[-pi, pi), exact since ``s`` and ``k`` are integers) it reads
``H[s, k] = sum_p c_p exp(i (s x_p + k y_p))``, which FINUFFT evaluates for the centred modes
``s - Nf//2``, ``k - Nt//2`` (the shift is a phase ``exp(i (Nf//2 x_p + Nt//2 y_p))`` on
``c_p``) to a requested relative tolerance ``eps`` in ``O(P w^2 + Nf Nt log(Nf Nt))``
(``method="nufft"``). ``method="direct"`` is the path-by-path sum (tones by recurrence, a
matrix product over paths), the reference the fast one is tested against; ``"auto"`` takes the
NUFFT when ``finufft`` is installed and an element has more than :data:`NUFFT_MIN_PATHS`
paths. Each element gets its own traced delay,
so the spatial-wideband term is in the tensor by construction, as with
``channel_tensor(..., spatial_wideband=True)``; amplitudes and reflection coefficients are
Sionna's (ITU slabs, polarimetric), so a path's complex amplitude differs from the image method's
by a constant per path, which the extraction estimates anyway.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._physical import tone_step
from .._validate import choice, finite_array, integer, positive, record
from ..budget import check_elements

__all__ = ["NUFFT_MIN_PATHS", "SYNTHESIS_METHODS", "ElementPaths", "element_tensor"]

#: how :func:`element_tensor` sums the paths
SYNTHESIS_METHODS = ("auto", "nufft", "direct")
#: with ``method="auto"``, the NUFFT is used above this many paths in an element
NUFFT_MIN_PATHS = 64


@dataclass(frozen=True)
class ElementPaths:
    """All traced paths per element (module docstring); arrays (M, P), ``valid`` marks the slots
    that hold a path at that element."""

    tau: np.ndarray
    gain: np.ndarray
    doppler: np.ndarray
    valid: np.ndarray
    order: np.ndarray
    diffuse: np.ndarray
    first_object: np.ndarray

    def __post_init__(self) -> None:
        shape = np.shape(self.tau)
        if len(shape) != 2:
            raise ValueError(f"tau: expected an (M, P) array, got shape {shape}")
        for name in ("gain", "doppler", "valid", "order", "diffuse", "first_object"):
            if np.shape(getattr(self, name)) != shape:
                raise ValueError(
                    f"{name}: expected shape {shape} like tau, got {np.shape(getattr(self, name))}"
                )
        record(self, allow_nan=("tau", "gain", "doppler"))  # numbers; unused slots hold anything
        for name in ("tau", "gain", "doppler"):  # the paths themselves are finite
            finite_array(name, np.asarray(getattr(self, name))[np.asarray(self.valid, bool)],
                         dtype=complex if name == "gain" else float)  # fmt: skip

    @property
    def M(self) -> int:
        """Number of elements."""
        return int(self.tau.shape[0])

    def mask(self, kind: str) -> np.ndarray:
        """(M, P) mask of the valid paths of ``kind``: "los", "specular1" (one specular bounce),
        "specular2+" (two or more, all specular), "diffuse" (any diffuse interaction), "all"."""
        v = self.valid
        masks = {
            "los": v & (self.order == 0),
            "specular1": v & (self.order == 1) & ~self.diffuse,
            "specular2+": v & (self.order >= 2) & ~self.diffuse,
            "diffuse": v & self.diffuse,
            "all": v,
        }
        if kind not in masks:
            raise ValueError(f"kind: expected one of {list(masks)}, got {kind!r}")
        return masks[kind]

    def power(self, kind: str = "all") -> float:
        """Mean received power per element [W per W transmitted] of the paths of ``kind``
        (:meth:`mask`), incoherent sum."""
        return float(np.sum(np.abs(self.gain) ** 2 * self.mask(kind)) / self.M)

    def count(self, kind: str = "all") -> float:
        """Mean number of paths of ``kind`` per element."""
        return float(self.mask(kind).sum() / self.M)


def _finufft():
    try:
        import finufft
    except ImportError:
        return None
    return finufft


def _direct(tau, c, dop, df, nf, T0, nt) -> np.ndarray:
    """The (Nf, Nt) sum over paths of ``c exp(-j 2 pi s Df tau) exp(j 2 pi k T0 f_d)``."""
    # tone s of path p: c_p z_p^s with z_p = exp(-j 2 pi Df tau_p), by recurrence
    # (a product of unit phasors: float64 rounding ~ Nf * 1e-16, far cheaper than Nf exps)
    ef = np.empty((nf, tau.size), complex)
    ef[0] = c
    if nf > 1:
        ef[1:] = np.exp(-2j * np.pi * df * tau)
        np.cumprod(ef, axis=0, out=ef)
    et = np.exp(2j * np.pi * T0 * np.outer(np.arange(nt), dop))
    return ef @ et.T


def _fold(x: np.ndarray) -> np.ndarray:
    """``x`` folded into [-pi, pi)."""
    return np.mod(x + np.pi, 2 * np.pi) - np.pi


def element_tensor(
    paths: ElementPaths,
    tone_spacing: float,
    n_tones: int,
    symbol_period: float,
    n_symbols: int,
    *,
    select: np.ndarray | None = None,
    method: str = "auto",
    eps: float = 1e-9,
) -> np.ndarray:
    """Eq. 1's noiseless tensor (M, Nf, Nt) of the paths ``select`` (an (M, P) mask; all valid
    paths by default), in the module docstring's convention, for a unit transmit power and no
    clock bias (:func:`tunnelkit.signal_route.raytraced.tensor_snapshot` adds both, and the noise).

    ``method`` (:data:`SYNTHESIS_METHODS`): "nufft" (FINUFFT, relative tolerance ``eps``),
    "direct" (the sum path by path) or "auto" (module docstring)."""
    if not isinstance(paths, ElementPaths):
        raise TypeError(f"paths: expected an ElementPaths, got {type(paths).__name__}")
    df = tone_step("tone_spacing", tone_spacing)
    T0 = positive("symbol_period", symbol_period)
    nf = integer("n_tones", n_tones, minimum=1)
    nt = integer("n_symbols", n_symbols, minimum=1)
    check_elements(
        "n_tones, n_symbols", paths.M * nf * nt, 16, f"{paths.M} x {nf} x {nt} complex tensor"
    )
    choice("method", method, SYNTHESIS_METHODS)
    eps = positive("eps", eps)
    if not 1e-15 <= eps <= 1e-3:
        raise ValueError(f"eps: expected a relative tolerance in [1e-15, 1e-3], got {eps}")
    if select is not None and np.asarray(select).dtype != bool:
        raise TypeError(f"select: expected a boolean (M, P) mask, got {np.asarray(select).dtype}")
    sel = paths.valid if select is None else np.asarray(select, bool) & paths.valid
    if sel.shape != paths.valid.shape:
        raise ValueError(f"select: expected shape {paths.valid.shape}, got {sel.shape}")
    fin = None if method == "direct" else _finufft()
    if method == "nufft" and fin is None:
        raise ImportError(
            "method: 'nufft' needs the finufft package (`pip install -e '.[rt]'`); "
            "method='direct' sums path by path"
        )
    plan = None
    H = np.zeros((paths.M, nf, nt), complex)
    for m in range(paths.M):
        j = np.flatnonzero(sel[m])
        if j.size == 0:
            continue
        tau, dop = paths.tau[m, j], paths.doppler[m, j]
        c = np.conj(paths.gain[m, j]) * np.exp(1j * np.pi * (nf - 1) * df * tau)  # tone s_c
        if fin is None or (method == "auto" and j.size <= NUFFT_MIN_PATHS):
            H[m] = _direct(tau, c, dop, df, nf, T0, nt)
            continue
        if plan is None:
            plan = fin.Plan(1, (nf, nt), eps=eps, isign=1, nthreads=1, dtype="complex128")
        x = _fold(-2 * np.pi * df * tau)
        y = _fold(2 * np.pi * T0 * dop)
        plan.setpts(x, y)
        H[m] = plan.execute(c * np.exp(1j * ((nf // 2) * x + (nt // 2) * y)))
    return H
