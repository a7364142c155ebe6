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
path by path, that is::

    H[m, s, k] = sum_p conj(gain[m, p]) exp(-j 2 pi s Df tau[m, p]) exp(+j 2 pi k f_d[m, p] T0)

(the tone reversal's constant phase ``exp(j 2 pi (Nf - 1) Df tau)`` is left out: it would be a
per-element spatial-wideband term of the wrong sign). Each element gets its own traced delay,
so the spatial-wideband term is in the tensor by construction, as with
``channel_tensor(..., spatial_wideband=True)``; amplitudes and reflection coefficients are
Sionna's (ITU slabs, polarimetric), so a path's complex amplitude differs from the image method's
by a constant per path, which the extraction estimates anyway.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import integer

__all__ = ["ElementPaths", "element_tensor"]


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


def element_tensor(
    paths: ElementPaths,
    tone_spacing: float,
    n_tones: int,
    symbol_period: float,
    n_symbols: int,
    *,
    select: np.ndarray | None = None,
) -> np.ndarray:
    """Eq. 1's noiseless tensor (M, Nf, Nt) of the paths ``select`` (an (M, P) mask; all valid
    paths by default), in the module docstring's convention, for a unit transmit power and no
    clock bias (:func:`tunnelkit.channel.tensor_snapshot` adds both, and the noise)."""
    if not isinstance(paths, ElementPaths):
        raise TypeError(f"paths: expected an ElementPaths, got {type(paths).__name__}")
    nf = integer("n_tones", n_tones, minimum=1)
    nt = integer("n_symbols", n_symbols, minimum=1)
    sel = paths.valid if select is None else np.asarray(select, bool) & paths.valid
    if sel.shape != paths.valid.shape:
        raise ValueError(f"select: expected shape {paths.valid.shape}, got {sel.shape}")
    k = np.arange(nt)
    H = np.zeros((paths.M, nf, nt), complex)
    for m in range(paths.M):
        j = np.flatnonzero(sel[m])
        if j.size == 0:
            continue
        # tone s of path p: conj(gain) z_p^s with z_p = exp(-j 2 pi Df tau_p), by recurrence
        # (a product of unit phasors: float64 rounding ~ Nf * 1e-16, far cheaper than Nf exps)
        ef = np.empty((nf, j.size), complex)
        ef[0] = np.conj(paths.gain[m, j])
        if nf > 1:
            ef[1:] = np.exp(-2j * np.pi * tone_spacing * paths.tau[m, j])
            np.cumprod(ef, axis=0, out=ef)
        et = np.exp(2j * np.pi * symbol_period * np.outer(k, paths.doppler[m, j]))
        H[m] = ef @ et.T
    return H
