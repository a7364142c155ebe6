"""Channel-parameter extraction from the SRS tensor (Italiano et al. 2026, eq. 11-24, Algorithm 1).

One module per stage, :func:`extract_paths` in front:

- :mod:`.decomposition` — the CP decomposition of ``H`` (eq. 3, 11, 12) with tensorly, rank checks;
- :mod:`.paper` — the paper's route from CPD factors to path parameters (eq. 13-24, Algorithm 1);
- :mod:`.coherent` — paths the CPD merged, separated by the array (beyond the paper);
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
from .bounds import crlb_paths, path_crlb
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


def extract_paths(
    H,
    n_paths: int,
    element_positions,
    fc: float,
    subcarrier_spacing: float,
    symbol_period: float,
    *,
    method: str = "fast",
    refine: str = "joint",
    n_iter_max: int = 200,
    tol: float = 1e-10,
    polish: int | None = None,
) -> PathEstimates:
    """Path parameters from the channel tensor (eq. 11-24), one entry per CPD component.

    Parameters
    ----------
    H : (M, Nf, Nt) complex tensor following eq. 1 as printed (see module docstring).
    n_paths : number of paths L (known, as in the paper); refused beyond Kruskal's condition.
    element_positions : (M, 3) local-frame positions, ``z = 0``, reference antenna at the origin.
    fc : carrier [Hz]; subcarrier_spacing : spacing ``Delta f`` of the tones along axis 1 [Hz];
    symbol_period : ``T0`` between the samples along axis 2 [s].
    method : "fast" (compressed, ESPRIT-initialised) or "plain" (``parafac(init='svd')``).
    refine : "joint" (default) — after eq. 13, maximum-likelihood refinement of all roots
        together with free spatial factors (:func:`refine_joint`); "column" — each root to the
        periodogram peak of its own factor column (:func:`refine_roots`); "none" — the paper's
        eq. 13 roots and eq. 12 gains as they are.
    polish : ALS sweeps on the full tensor after the compressed CPD (default 2, or 0 with
        ``refine="joint"``, which supersedes them).

    Returns a :class:`PathEstimates` (``alpha, d, v, direction, kappa, near_field`` and more); it
    also supports ``est["d"]``.
    """
    H = check_tensor(H)
    M, _Nf, _Nt = H.shape
    L = check_rank(H.shape, n_paths)
    pos = check_element_positions("element_positions", element_positions, m=M)
    fc = positive("fc", fc)
    df = positive("subcarrier_spacing", subcarrier_spacing)
    T0 = positive("symbol_period", symbol_period)
    if refine not in ("none", "column", "joint"):
        raise ValueError(f"refine: expected 'joint', 'column' or 'none', got {refine!r}")
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
