"""Channel-parameter extraction from the SRS tensor (Italiano et al. 2026, eq. 11-24, Algorithm 1).

One module per stage, :func:`extract_paths` in front:

- :mod:`.decomposition` — the CP decomposition of ``H`` (eq. 3, 11, 12) with tensorly, rank checks;
- :mod:`.paper` — the paper's route from CPD factors to path parameters (eq. 13-24, Algorithm 1);
- :mod:`.coherent` — paths the CPD merged, separated by the array (beyond the paper);
- :mod:`.ml` — the joint maximum-likelihood fit of eq. 1 at the Cramér-Rao bound, started from
  the two above (the default route of :func:`extract_paths`);
- :mod:`.bounds` — Cramér-Rao bounds of the eq. 1 model;
- :mod:`.estimates` — :class:`PathEstimates`, the container every route returns.

``H`` follows eq. 1 exactly as printed (spatial phase ``+2 pi fc/c delta``, frequency phase
``-2 pi s Df tau``, time phase ``+2 pi k f_d T0``).
"""

from __future__ import annotations

import numpy as np

from .._validate import positive
from ..arrays import check_element_positions
from ..constants import C
from .bounds import crlb_paths, estimate_crlb, path_crlb
from .decomposition import (
    CPDConvergenceWarning,
    CPDResult,
    check_rank,
    check_tensor,
    cp_rel_error,
    cpd,
    kruskal_rank,
    max_identifiable_rank,
    normalize_factors,
)
from .estimates import PathEstimates, path_estimates
from .paper import (
    algorithm1,
    angles_from_solution,
    refine_joint,
    refine_roots,
    solve_far_field,
    solve_near_field,
    unwrap_spatial,
    vandermonde_roots,
)

__all__ = [
    "ROUTES",
    "CPDConvergenceWarning",
    "CPDResult",
    "PathEstimates",
    "algorithm1",
    "angles_from_solution",
    "check_rank",
    "check_tensor",
    "cp_rel_error",
    "cpd",
    "crlb_paths",
    "estimate_crlb",
    "extract_paths",
    "kruskal_rank",
    "max_identifiable_rank",
    "normalize_factors",
    "path_crlb",
    "path_estimates",
    "refine_joint",
    "refine_roots",
    "solve_far_field",
    "solve_near_field",
    "unwrap_spatial",
    "vandermonde_roots",
]


ROUTES = ("ml", "coherent", "joint", "column", "none")


def extract_paths(
    H,
    n_paths: int,
    element_positions,
    fc: float,
    subcarrier_spacing: float,
    symbol_period: float,
    *,
    method: str = "fast",
    refine: str = "ml",
    n_iter_max: int = 200,
    tol: float = 1e-10,
    polish: int | None = None,
    noise_power: float | None = None,
) -> PathEstimates:
    """Path parameters from the channel tensor, one entry per path.

    Parameters
    ----------
    H : (M, Nf, Nt) complex tensor following eq. 1 as printed (see module docstring).
    n_paths : number of paths L (known, as in the paper); refused beyond Kruskal's condition.
    element_positions : (M, 3) local-frame positions, ``z = 0``, reference antenna at the origin.
    fc : carrier [Hz]; subcarrier_spacing : spacing ``Delta f`` of the tones along axis 1 [Hz];
    symbol_period : ``T0`` between the samples along axis 2 [s].
    method : "fast" (compressed, ESPRIT-initialised) or "plain" (``parafac(init='svd')``).
    refine : the route.

        - "ml" (default) — the joint maximum-likelihood fit of the exact eq. 1 model, started from
          the CPD and the coherent split, with SAGE-like re-seeding (:mod:`.ml`): efficient (at
          the structured CRLB, :func:`path_crlb`) in direction, curvature, delay and Doppler;
        - "coherent" — "joint", then the coherent split (:func:`.coherent.resolve_coherent`);
        - the paper's route (eq. 13-24): "joint" — after eq. 13, maximum-likelihood refinement
          of all roots together with free spatial factors (:func:`refine_joint`); "column" —
          each root to the periodogram peak of its own factor column (:func:`refine_roots`);
          "none" — the paper's eq. 13 roots and eq. 12 gains as they are.
    polish : ALS sweeps on the full tensor after the compressed CPD (default 2, or 0 with
        ``refine="joint"``, which supersedes them).
    noise_power : noise power per sample for the "ml" route (default: estimated from ``H``).

    Returns a :class:`PathEstimates` (``alpha, d, v, direction, kappa, near_field`` and more); it
    also supports ``est["d"]``. On the "ml" route see :func:`.ml.ml_paths` for what each field
    holds (``kappa`` is finite for every near-field wave; ``fit`` has the noise floor test).
    """
    H = check_tensor(H)
    M, _Nf, _Nt = H.shape
    L = check_rank(H.shape, n_paths)
    pos = check_element_positions("element_positions", element_positions, m=M)
    fc = positive("fc", fc)
    df = positive("subcarrier_spacing", subcarrier_spacing)
    T0 = positive("symbol_period", symbol_period)
    if refine not in ROUTES:
        raise ValueError(f"refine: expected one of {ROUTES}, got {refine!r}")
    if refine == "ml":
        from .ml import _ml_paths

        if noise_power is not None:
            noise_power = positive("noise_power", noise_power)
        return _ml_paths(H, L, pos, fc, df, T0, noise_power=noise_power)
    if noise_power is not None:
        raise ValueError(f"noise_power: only used by refine='ml', not {refine!r}")
    if refine == "coherent":
        from .coherent import resolve_coherent

        est = _paper_route(H, L, pos, fc, df, T0, "joint", method, n_iter_max, tol, polish)
        return resolve_coherent(H, est, pos, fc, df, T0, L)
    return _paper_route(H, L, pos, fc, df, T0, refine, method, n_iter_max, tol, polish)


def _paper_route(
    H, L, pos, fc, df, T0, refine, method="fast", n_iter_max=200, tol=1e-10, polish=None
) -> PathEstimates:
    """CPD and eq. 13-24 on checked arguments (``refine`` in "joint", "column", "none")."""
    if polish is None:
        polish = 0 if refine == "joint" else 2
    res = cpd(
        H, L, method=method, n_iter_max=n_iter_max, tol=tol, element_positions=pos, polish=polish
    )
    (bs, bf, bt), alpha = normalize_factors(res.factors)
    mu_f, mu_t = vandermonde_roots(bf), vandermonde_roots(bt)  # eq. 13
    if refine in ("column", "joint"):
        mu_f, beta_f = refine_roots(bf, mu_f)
        mu_t, beta_t = refine_roots(bt, mu_t)
        alpha = alpha * beta_f * beta_t
    if refine == "joint":
        # project the spatial mode on the span of the CPD's spatial factors first: the roots'
        # information lies there, and each Gauss-Newton step gets M / L times cheaper
        Q, _ = np.linalg.qr(res.factors[0])
        mu_f, mu_t, Ac = refine_joint(np.tensordot(Q.conj(), H, axes=(0, 0)), mu_f, mu_t)
        A = Q @ Ac
        alpha = A[0].copy()
        bs = A / A[0][None, :]
    d = -C / (2 * np.pi * df) * mu_f  # eq. 14
    v = C / (2 * np.pi * fc * T0) * mu_t  # eq. 15
    delta = C / (2 * np.pi * fc) * unwrap_spatial(bs, pos)  # eq. 16
    x_nf = solve_near_field(delta, pos)
    u_ff = solve_far_field(delta, pos)
    ang = angles_from_solution(x_nf, u_ff)
    near = np.isfinite(ang["kappa_nf"]) & (ang["kappa_nf"] > 0)
    return path_estimates(
        alpha,
        d,
        v,
        ang,
        near,
        delta.T,
        mu_f,
        mu_t,
        (bs, bf, bt),
        res.rel_error,
        res.n_iter,
        res.converged,
    )
