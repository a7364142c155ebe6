"""Channel-parameter extraction from the SRS tensor (Italiano et al. 2026, eq. 11-24, Algorithm 1).

Route, one named piece each:

1. :func:`cpd` — canonical polyadic decomposition of ``H`` (eq. 3, 11) with tensorly's
   ``parafac``. ``method="fast"`` compresses ``H`` to an ``L x L x min(L, Nt)`` core (truncated
   HOSVD with a randomised range finder), initialises the core factors algebraically (ESPRIT on the
   Vandermonde frequency factor: the delay roots are the eigenvalues of the shift-invariance
   matrix), refines them with ``parafac(init=..., linesearch=True)`` and lifts them back.
   ``method="plain"`` is ``parafac(H, L, init="svd", linesearch=True)`` on the full tensor.
   :func:`check_rank` refuses a rank Kruskal's condition cannot identify.
2. :func:`normalize_factors` — the scaling fix ``B <- B diag^-1(B[0, :])`` and eq. 12 gains.
3. :func:`vandermonde_roots` — eq. 13 shift-invariance roots, then eq. 14 (``d``) and eq. 15
   (``v``). Eq. 13 is unbiased but not efficient for long factors (its error telescopes to the end
   samples); :func:`refine_roots` polishes each root to the periodogram peak of its column (the
   single-tone maximum-likelihood estimate), which reaches the Cramér-Rao bound.
4. :func:`unwrap_spatial` — eq. 16: phase of the spatial factor unwrapped in 2-D on a URA grid
   (``skimage.restoration.unwrap_phase``, Herráez et al. 2002, the paper's ref. 25), along a
   minimum spanning tree otherwise.
5. :func:`solve_near_field` (TLS of eq. 17-18) and :func:`solve_far_field` (LS).
6. :func:`angles_from_solution` — eq. 19-24. **Convention**: eq. 19 writes the wave origin as
   ``kappa (cos phi sin psi, sin phi sin psi, .)`` so ``psi`` is the *polar angle from the array
   normal*; eq. 22/24 instead return ``acos(rho / kappa)``, which is the angle *above the array
   plane* (``pi/2 - psi``). We follow eq. 19 (``psi = asin(rho / kappa)``) and report an unambiguous
   unit ``direction`` in the local frame (front half-space, local z > 0).
7. :func:`algorithm1` — ExtractMeas' consistency checks: discard ``d < 0``; far-field when
   ``kappa < 0``; near-field otherwise.

Public entry: :func:`extract_paths`. ``H`` follows eq. 1 exactly as printed (spatial phase
``+2 pi fc/c delta``, frequency phase ``-2 pi s Df tau``, time phase ``+2 pi k f_d T0``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import tensorly as tl
from tensorly.cp_tensor import CPTensor
from tensorly.decomposition import parafac

from ._validate import integer, positive
from .arrays import check_element_positions
from .constants import C

__all__ = [
    "CPDConvergenceWarning",
    "CPDResult",
    "PathEstimates",
    "algorithm1",
    "angles_from_solution",
    "check_rank",
    "cp_rel_error",
    "cpd",
    "crlb_paths",
    "extract_paths",
    "kruskal_rank",
    "max_identifiable_rank",
    "normalize_factors",
    "path_estimates",
    "refine_joint",
    "refine_roots",
    "solve_far_field",
    "solve_near_field",
    "unwrap_spatial",
    "vandermonde_roots",
]


class CPDConvergenceWarning(UserWarning):
    """The CP decomposition stopped at ``n_iter_max`` before reaching ``tol``."""


# --- identifiability ----------------------------------------------------------------------------


def max_identifiable_rank(shape) -> int:
    """Largest ``L`` for which Kruskal's condition can hold for a tensor of ``shape``.

    With generic factors ``kr(B_i) = min(I_i, L)``; eq. 11's condition ``sum kr >= 2 L + 2`` is
    then a condition on the dimensions alone (a rank-1 CPD is always unique).
    """
    dims = [int(s) for s in shape]
    best = 1
    for L in range(2, sum(dims) + 1):
        if sum(min(i, L) for i in dims) >= 2 * L + 2:
            best = L
    return best


def check_rank(shape, n_paths) -> int:
    """``n_paths`` as an int, or ``ValueError`` if Kruskal's condition cannot identify it."""
    n = integer("n_paths", n_paths, minimum=1)
    top = max_identifiable_rank(shape)
    if n > top:
        raise ValueError(
            f"n_paths: {n} paths cannot be identified in a tensor of shape {tuple(shape)}: "
            f"Kruskal's condition kr(Bs)+kr(Bf)+kr(Bt) >= 2L+2 allows at most L = {top}"
        )
    return n


def kruskal_rank(B, tol: float = 1e-6) -> int:
    """Kruskal rank of ``B`` (brute force): the largest k such that every k columns are independent.

    A column set counts as independent when its smallest singular value exceeds ``tol`` times the
    largest one (columns normalised first), so nearly collinear columns lower the rank.
    """
    from itertools import combinations

    B = np.asarray(B)
    B = B / np.maximum(np.linalg.norm(B, axis=0, keepdims=True), 1e-300)
    L = B.shape[1]
    kr = 0
    for k in range(1, min(L, B.shape[0]) + 1):
        for cols in combinations(range(L), k):
            s = np.linalg.svd(B[:, cols], compute_uv=False)
            if s[-1] <= tol * s[0]:
                return kr
        kr = k
    return kr


# --- CPD ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CPDResult:
    """Factor matrices ``(A, B, C)`` with ``H ~ sum_l a_l o b_l o c_l`` (weights folded into A)."""

    factors: tuple[np.ndarray, np.ndarray, np.ndarray]
    rel_error: float
    n_iter: int
    converged: bool
    method: str


def _range_basis(X: np.ndarray, r: int, rng: np.random.Generator) -> np.ndarray:
    """Orthonormal basis (rows, r) of the dominant column space of ``X`` (randomised, 1 power step)."""
    n = X.shape[0]
    if r >= n:
        return np.eye(n, dtype=complex)
    k = min(n, r + 6)
    om = rng.standard_normal((X.shape[1], k)) + 1j * rng.standard_normal((X.shape[1], k))
    Q, _ = np.linalg.qr(X @ om)
    Q, _ = np.linalg.qr(X @ (X.conj().T @ Q))
    B = Q.conj().T @ X
    _w, V = np.linalg.eigh(B @ B.conj().T)  # ascending eigenvalues of the small Gram matrix
    return Q @ V[:, ::-1][:, :r]


def _split_rank1(K: np.ndarray, r_a: int, r_b: int):
    """Rows of ``K`` (L, r_a * r_b) as rank-1 products ``x_l o y_l`` (best rank-1 by SVD)."""
    L = K.shape[0]
    X = np.empty((r_a, L), complex)
    Y = np.empty((r_b, L), complex)
    for j_ in range(L):
        u, s, vh = np.linalg.svd(K[j_].reshape(r_a, r_b), full_matrices=False)
        X[:, j_] = u[:, 0] * s[0]
        Y[:, j_] = vh[0]
    return X, Y


def _shift_pairs(element_positions) -> list[tuple[np.ndarray, np.ndarray]]:
    """Index pairs (m, m') of neighbouring elements along each grid axis of a URA/ULA."""
    if element_positions is None:
        return []
    grid = _grid_index(np.asarray(element_positions, float))
    if grid is None:
        return []
    r, c, nr, nc = grid
    where = -np.ones((nr, nc), int)
    where[r, c] = np.arange(r.size)
    pairs = []
    if nc > 1:
        pairs.append((where[:, :-1].ravel(), where[:, 1:].ravel()))
    if nr > 1:
        pairs.append((where[:-1, :].ravel(), where[1:, :].ravel()))
    return pairs


def _esprit_init(G: np.ndarray, basis: np.ndarray, mode: int, pairs=None, seed: int = 0):
    """Algebraic CPD of the core ``G`` from the shift invariance of one mode's basis.

    ``basis`` (I, L) spans the factor of ``mode`` (0: spatial, rows paired by ``pairs``, the
    neighbours of a URA, nearly shift-invariant for a far-ish source; 1: frequency, exactly
    Vandermonde). With ``basis = B T`` the shift matrices ``Psi_i = T diag(z_i) T^-1`` share the
    eigenvectors ``T``, which are the core factor of that mode; a random combination of the
    ``Psi_i`` separates paths that differ along any shift axis.
    """
    L = G.shape[mode]
    if pairs is None:
        pairs = [(np.arange(basis.shape[0] - 1), np.arange(1, basis.shape[0]))]
    w = np.random.default_rng(seed).standard_normal(len(pairs))
    Psi = sum(
        wi * np.linalg.lstsq(basis[a], basis[b], rcond=None)[0] for wi, (a, b) in zip(w, pairs)
    )
    _, T = np.linalg.eig(Psi)
    rest = [i for i in range(3) if i != mode]
    K = np.linalg.solve(T, np.moveaxis(G, mode, 0).reshape(L, -1))
    X, Y = _split_rank1(K, G.shape[rest[0]], G.shape[rest[1]])
    out: list = [None, None, None]
    out[mode], out[rest[0]], out[rest[1]] = T, X, Y
    return out


def _core_cpd(G: np.ndarray, init, n_iter_max: int, tol: float):
    """tensorly ``parafac`` of the (small) core from ``init``; returns factors, error, iterations."""
    scale = np.linalg.norm(G)
    L = init[0].shape[1]
    start = [init[0] / scale, init[1], init[2]]
    cp, errs = parafac(
        tl.tensor(G / scale),
        L,
        init=CPTensor((np.ones(L), start)),
        linesearch=True,
        n_iter_max=n_iter_max,
        tol=tol,
        return_errors=True,
    )
    fa = [np.asarray(f) for f in cp.factors]
    fa[0] = fa[0] * np.asarray(cp.weights)[None, :] * scale
    g_hat = np.einsum("al,bl,cl->abc", *fa, optimize=True)
    return fa, float(np.linalg.norm(G - g_hat)), len(errs)


def _als_polish(H: np.ndarray, factors, n_sweeps: int):
    """ALS sweeps on the full tensor (normal equations with Hadamard products of Gram matrices)."""
    A, B, Cm = (np.array(f) for f in factors)
    M, nf, nt = H.shape
    Hm = H.reshape(M * nf, nt)
    for _ in range(n_sweeps):
        HC = (Hm @ Cm.conj()).reshape(M, nf, -1)  # shared by the A and B updates
        A = np.einsum("msl,sl->ml", HC, B.conj()) @ np.linalg.pinv(
            ((B.conj().T @ B) * (Cm.conj().T @ Cm)).conj()
        )
        B = np.einsum("msl,ml->sl", HC, A.conj()) @ np.linalg.pinv(
            ((A.conj().T @ A) * (Cm.conj().T @ Cm)).conj()
        )
        AB = (A.conj()[:, None, :] * B.conj()[None, :, :]).reshape(M * nf, -1)
        Cm = (Hm.T @ AB) @ np.linalg.pinv(((A.conj().T @ A) * (B.conj().T @ B)).conj())
    return A, B, Cm


def cpd(
    H,
    n_paths: int,
    *,
    method: str = "fast",
    n_iter_max: int = 200,
    tol: float = 1e-10,
    seed: int = 0,
    element_positions=None,
    polish: int = 2,
) -> CPDResult:
    """CP decomposition of the 3-way tensor ``H`` into ``n_paths`` rank-1 terms (eq. 11).

    ``method="fast"``: compress (truncated HOSVD, randomised range finder) -> algebraic ESPRIT
    initialisations from the spatial shift invariance of a URA (when ``element_positions`` is
    given) and from the Vandermonde frequency factor -> tensorly ``parafac`` (linesearch) on the
    small core from each, keeping the better fit -> lift -> ``polish`` ALS sweeps on the full
    tensor (they recover what the rank-L compression of a nearly collinear mode loses to noise).
    ``method="plain"``: tensorly ``parafac(H, L, init="svd", linesearch=True)`` on the full tensor.
    ``seed`` fixes the randomised range finder (the result is deterministic). Warns with
    :class:`CPDConvergenceWarning` (stating the final error) when ``n_iter_max`` is reached.
    """
    H = _check_tensor(H)
    L = check_rank(H.shape, n_paths)
    n_iter_max = integer("n_iter_max", n_iter_max, minimum=1)
    tol = positive("tol", tol)
    polish = integer("polish", polish, minimum=0)
    if method == "plain":
        cp, errs = parafac(
            tl.tensor(H),
            L,
            init="svd",
            linesearch=True,
            n_iter_max=n_iter_max,
            tol=tol,
            return_errors=True,
        )
        factors = [np.asarray(f) for f in cp.factors]
        factors[0] = factors[0] * np.asarray(cp.weights)[None, :]
        res = CPDResult(tuple(factors), float(errs[-1]), len(errs), len(errs) < n_iter_max, "plain")
    elif method == "fast":
        pos = None if element_positions is None else np.asarray(element_positions, float)
        res = _cpd_fast(H, L, n_iter_max, tol, seed, pos, polish)
    else:
        raise ValueError(f"method: expected 'fast' or 'plain', got {method!r}")
    if not res.converged:
        warnings.warn(
            CPDConvergenceWarning(
                f"CPD ({res.method}) did not converge in {n_iter_max} iterations; final relative error "
                f"{res.rel_error:.3g}"
            ),
            stacklevel=2,
        )
    return res


def _cpd_fast(
    H: np.ndarray, L: int, n_iter_max: int, tol: float, seed: int, element_positions, polish: int
) -> CPDResult:
    M, Nf, Nt = H.shape
    rng = np.random.default_rng(seed)
    U2 = _range_basis(np.moveaxis(H, 1, 0).reshape(Nf, -1), L, rng)
    H2 = np.matmul(U2.conj().T[None], H)  # (M, r2, Nt)
    U1 = _range_basis(H2.reshape(M, -1), L, rng)
    H12 = np.tensordot(U1.conj(), H2, axes=(0, 0))
    U3 = _range_basis(np.moveaxis(H12, 2, 0).reshape(Nt, -1), min(L, Nt), rng)
    G = H12 @ U3.conj()
    inits = []
    pairs = _shift_pairs(element_positions)
    candidates = []
    if pairs and U1.shape[1] == L and len(pairs[0][0]) >= L:
        candidates.append((U1, 0, pairs))
    if Nf >= L + 1 and U2.shape[1] == L:
        candidates.append((U2, 1, None))
    for basis, mode, pr in candidates:
        try:
            inits.append(_esprit_init(G, basis, mode, pr, seed))
        except np.linalg.LinAlgError:  # degenerate shift structure: try the next one
            continue
    if not inits:  # no shift invariance to exploit: plain CPD of the full tensor
        return cpd(H, L, method="plain", n_iter_max=n_iter_max, tol=tol)
    best = None
    for init in inits:
        fa, err, n_it = _core_cpd(G, init, n_iter_max, max(tol, 1e-6))
        if best is None or err < best[1]:
            best = (fa, err, n_it)
    fa, err, n_it = best
    factors = (U1 @ fa[0], U2 @ fa[1], U3 @ fa[2])
    nh2 = float(np.vdot(H, H).real)
    if polish:
        factors = _als_polish(H, factors, polish)
        rel = cp_rel_error(H, factors, nh2)
    else:  # ||H - Hhat||^2 = ||H||^2 - ||G||^2 + ||G - Ghat||^2 (orthonormal bases)
        rel = float(np.sqrt((max(nh2 - np.linalg.norm(G) ** 2, 0.0) + err**2) / nh2))
    return CPDResult(tuple(factors), rel, n_it, n_it < n_iter_max, "fast")


# --- eq. 12-15 -----------------------------------------------------------------------------------


def normalize_factors(factors):
    """Scaling fix ``B <- B diag^-1(B[0, :])`` for each factor, and eq. 12 ``alpha = prod B[0, l]``."""
    out, alpha = [], 1.0
    for B in factors:
        first = B[0]
        if np.any(np.abs(first) < 1e-300):
            raise ValueError(
                "factors: a factor column has a zero first entry; cannot fix the scale"
            )
        out.append(B / first[None, :])
        alpha = alpha * first
    return out, np.asarray(alpha)


def vandermonde_roots(B) -> np.ndarray:
    """Eq. 13: ``mu = angle(diag(B_-^H B_+))`` for a (normalised) Vandermonde factor ``B`` (N, L)."""
    B = np.asarray(B)
    return np.angle(np.sum(B[:-1].conj() * B[1:], axis=0))


def refine_roots(B, mu, n_steps: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Newton steps to the peak of ``|sum_n B[n] exp(-j mu n)|^2`` per column (single-tone ML).

    Returns the refined roots and the fitted amplitude ``beta = mean_n B[n] exp(-j mu n)`` (1 for
    a perfect normalised Vandermonde column). Steps are limited to a quarter of a bin.
    """
    B = np.asarray(B)
    N = B.shape[0]
    n = np.arange(N)[:, None]
    mu = np.array(mu, dtype=float)
    for _ in range(n_steps):
        e = np.exp(-1j * n * mu[None, :])
        S = np.sum(B * e, axis=0)
        S1 = np.sum(-1j * n * B * e, axis=0)
        S2 = np.sum(-(n**2) * B * e, axis=0)
        d1 = 2 * np.real(S.conj() * S1)
        d2 = 2 * (np.abs(S1) ** 2 + np.real(S.conj() * S2))
        step = np.where(d2 < 0, -d1 / np.where(d2 < 0, d2, -1.0), 0.0)
        mu = mu + np.clip(step, -np.pi / (2 * N), np.pi / (2 * N))
    beta = np.mean(B * np.exp(-1j * n * mu[None, :]), axis=0)
    return np.angle(np.exp(1j * mu)), beta


def cp_rel_error(H: np.ndarray, factors, nh2: float | None = None) -> float:
    """``||H - [[A, B, C]]|| / ||H||`` without forming the model tensor: the cross term is one
    contraction of ``H``, the model's energy the Hadamard product of the factors' Gram matrices."""
    A, B, Cm = factors
    nh2 = float(np.vdot(H, H).real) if nh2 is None else nh2
    fit = _contract(H, B.conj(), Cm.conj())  # <H, model> per component before summing
    gram = (A.conj().T @ A) * (B.conj().T @ B) * (Cm.conj().T @ Cm)
    err2 = nh2 - 2 * float(np.sum(np.real(A.conj() * fit))) + float(np.real(gram.sum()))
    return float(np.sqrt(max(err2, 0.0) / nh2))


def _contract(H: np.ndarray, F: np.ndarray, T: np.ndarray) -> np.ndarray:
    """``sum_{s,k} H[m, s, k] F[s, l] T[k, l]`` (M, L) via one matrix product and a reduction."""
    M, nf, nt = H.shape
    tmp = (H.reshape(M * nf, nt) @ T).reshape(M, nf, -1)
    return np.einsum("msl,sl->ml", tmp, F)


def refine_joint(H, mu_f, mu_t, n_steps: int = 6):
    """Joint ML refinement of all roots with free spatial factors (variable projection).

    Model ``H[m, s, k] = sum_l A[m, l] exp(j mu_f,l s) exp(j mu_t,l k)``: for fixed roots the
    spatial factors ``A`` are linear least squares; the roots take damped Gauss-Newton steps with
    the Kaufman Jacobian ``a_l o P_perp dw_l/dmu`` (``w_l = f_l kron t_l``). All Gram matrices
    factorise over the two Vandermonde modes, so one step costs three contractions of ``H``. This
    is the maximum-likelihood estimate of the model a CPD fits plus the Vandermonde structure; it
    approaches ``crlb_paths(spatial="free")`` where per-column estimates (eq. 13) do not.
    Returns ``(mu_f, mu_t, A)``.
    """
    M, nf, nt = H.shape
    s = np.arange(nf)[:, None]
    k = np.arange(nt)[:, None]
    mu = np.concatenate([np.asarray(mu_f, float), np.asarray(mu_t, float)])
    L = mu.size // 2
    x2 = float(np.vdot(H, H).real)
    Hm = H.reshape(M * nf, nt)

    def fit(m):
        F, T = np.exp(1j * s * m[None, :L]), np.exp(1j * k * m[None, L:])
        G = (F.conj().T @ F) * (T.conj().T @ T)  # W^H W
        HT = (Hm @ T.conj()).reshape(M, nf, L)  # reused by the next gradient
        B = np.einsum("msl,sl->ml", HT, F.conj())  # X conj(W)
        A = np.linalg.solve(G, B.T).T
        return F, T, G, A, HT, x2 - float(np.sum(np.real(A.conj() * B)))

    F, T, G, A, HT, cost = fit(mu)
    max_step = np.concatenate([np.full(L, np.pi / (2 * nf)), np.full(L, np.pi / (2 * nt))])
    lam = 1e-6
    for _ in range(n_steps):
        Fs, Tk = s * F, k * T
        FF, TT = F.conj().T @ F, T.conj().T @ T
        WD = np.concatenate([1j * (F.conj().T @ Fs) * TT, 1j * FF * (T.conj().T @ Tk)], axis=1)
        XD = -1j * np.concatenate(
            [np.einsum("msl,sl->ml", HT, Fs.conj()), _contract(H, F.conj(), Tk.conj())], axis=1
        )
        RD = XD - A @ WD.conj()  # R conj(D)
        Aa = np.concatenate([A, A], axis=1)
        grad = np.real(np.sum(Aa.conj() * RD, axis=0))
        Dff = (Fs.conj().T @ Fs) * TT
        Dft = (Fs.conj().T @ F) * (T.conj().T @ Tk)
        Dtt = FF * (Tk.conj().T @ Tk)
        DD = np.block([[Dff, Dft], [Dft.conj().T, Dtt]])
        PP = DD - WD.conj().T @ np.linalg.solve(G, WD)
        JtJ = np.real((Aa.conj().T @ Aa) * PP)
        improved = done = False
        for _ in range(10):
            step = np.linalg.solve(JtJ + lam * np.diag(np.diag(JtJ)), grad)
            step = np.clip(step, -max_step, max_step)  # trust region: a quarter of a bin
            out = fit(mu + step)
            if out[-1] <= cost:
                mu = mu + step
                F, T, G, A, HT, new = out
                # converged when the step is far below the noise-limited precision of the roots
                done = np.max(np.abs(step)) < 1e-9 or cost - new <= 1e-12 * cost
                cost, lam, improved = new, max(lam / 10, 1e-12), True
                break
            lam *= 10
        if not improved or done:
            break
    return mu[:L], mu[L:], A


# --- eq. 16-24 -----------------------------------------------------------------------------------


def _grid_index(p: np.ndarray, tol: float = 1e-6):
    """(rows, cols) integer grid coordinates if the xy positions form a full rectangular lattice."""
    out = []
    for ax in (1, 0):
        v = p[:, ax]
        u = np.unique(v)
        levels = u[np.concatenate([[True], np.diff(u) > tol])]  # values closer than tol merge
        if levels.size == 1:
            out.append((np.zeros(p.shape[0], int), 1))
            continue
        # the step from the float positions (rounding them to tol first lets the rounding error
        # accumulate along the axis: a 32 x 32 URA at 28 GHz was not recognised as a grid)
        idx = np.round((v - levels[0]) / np.min(np.diff(levels))).astype(int)
        step = float(np.sum(idx * (v - levels[0])) / np.sum(idx * idx))
        if not np.allclose(levels[0] + idx * step, v, rtol=0.0, atol=10 * tol):
            return None
        out.append((idx, int(idx.max()) + 1))
    (r, nr), (c, nc) = out
    if nr * nc != p.shape[0] or len(set(zip(r.tolist(), c.tolist()))) != p.shape[0]:
        return None
    return r, c, nr, nc


def unwrap_spatial(b, element_positions) -> np.ndarray:
    """Eq. 16 without the ``c / (2 pi fc)`` factor: unwrapped phase (M, L) of the spatial factor.

    ``b`` (M, L) normalised so that ``b[0] = 1``. On a full rectangular grid (a URA, or a ULA) the
    phase image is unwrapped with scikit-image's ``unwrap_phase`` (Herráez et al. 2002); for other
    planar layouts it is unwrapped along a minimum spanning tree of the elements. The result is
    shifted so that the reference element has phase 0 (eq. 2: ``delta_0 = 0``).
    """
    b = np.asarray(b)
    p = np.asarray(element_positions, float)
    ph = np.angle(b)
    grid = _grid_index(p)
    out = np.empty_like(ph)
    if grid is not None and min(grid[2], grid[3]) > 1:
        from skimage.restoration import unwrap_phase

        r, c, nr, nc = grid
        for j_ in range(ph.shape[1]):
            img = np.zeros((nr, nc))
            img[r, c] = ph[:, j_]
            un = unwrap_phase(img)
            out[:, j_] = un[r, c]
    elif grid is not None:  # one row or column: 1-D unwrap in element order along the line
        r, c, nr, nc = grid
        order = np.argsort(r * nc + c)
        out[order] = np.unwrap(ph[order], axis=0)
    else:
        from scipy.sparse.csgraph import breadth_first_order, minimum_spanning_tree

        dist = np.linalg.norm(p[:, None, :2] - p[None, :, :2], axis=-1)
        tree = minimum_spanning_tree(dist)
        order, pred = breadth_first_order(tree, 0, directed=False)
        out[0] = ph[0]
        for i in order[1:]:
            j = pred[i]
            out[i] = out[j] + np.angle(np.exp(1j * (ph[i] - ph[j])))
    return out - out[0]


def _line_direction(p: np.ndarray, rtol: float = 1e-12):
    """Unit in-plane direction ``e`` (2,) if the elements' xy positions are collinear, else None.

    The reference antenna is at the origin, so a linear array lies on the line ``t e``; any
    direction counts (a ULA along local x *or* y, or diagonal).
    """
    xy = p[:, :2]
    far = int(np.argmax(np.linalg.norm(xy, axis=1)))
    size = float(np.linalg.norm(xy[far]))
    if size == 0:
        return None
    e = xy[far] / size
    off = np.abs(xy[:, 0] * e[1] - xy[:, 1] * e[0])  # distance from the line through 0 along e
    return e if np.max(off) <= rtol * size else None


def solve_near_field(delta, element_positions) -> np.ndarray:
    """TLS solution ``x = (x_l, y_l, kappa_l)`` of eq. 18 for each column of ``delta`` (M, L).

    Rows ``2 [x_m, y_m, delta_m] x = r_m^2 - delta_m^2`` (m >= 1); the TLS solution is the last
    right singular vector of ``[2 A, -y]`` scaled to a unit last entry. For a linear array (a
    ULA along any direction ``e`` of the array plane) the columns ``x_m, y_m`` are replaced by the
    coordinate ``t_m = e . p_m`` along the line and the returned ``(x, y)`` is ``t e`` (the
    component across the line is unobservable and returned as 0). Returns (L, 3).
    """
    delta = np.atleast_2d(np.asarray(delta, float).T).T
    p = np.asarray(element_positions, float)
    xm, ym = p[1:, 0], p[1:, 1]
    r2 = np.sum(p[1:] ** 2, axis=1)
    line = _line_direction(p)
    linear = line is not None
    tm = p[1:, :2] @ line if linear else None  # coordinate along the array's line
    out = np.empty((delta.shape[1], 3))
    for j_ in range(delta.shape[1]):
        dm = delta[1:, j_]
        cols = [tm, dm] if linear else [xm, ym, dm]
        A = 2 * np.stack(cols, axis=1)
        aug = np.column_stack([A, -(r2 - dm**2)])
        aug_scale = np.linalg.norm(aug, axis=0)
        aug_scale[aug_scale == 0] = 1.0
        _, _, vh = np.linalg.svd(aug / aug_scale, full_matrices=False)
        v = vh[-1] / aug_scale
        sol = v[:-1] / v[-1] if abs(v[-1]) > 1e-300 else np.full(len(cols), np.nan)
        out[j_] = [*(sol[0] * line), sol[1]] if linear else sol
    return out


def solve_far_field(delta, element_positions) -> np.ndarray:
    """LS far-field solution of ``[x_m, y_m] u = -delta_m``: ``u = (cos phi sin psi, sin phi sin psi)``.

    In the far field ``delta_m = -u . p_m`` (eq. 17 with ``kappa -> inf``). Returns (L, 2); for a
    linear array along ``e`` only ``u . e`` is observable and ``(u . e) e`` is returned.
    """
    delta = np.atleast_2d(np.asarray(delta, float).T).T
    p = np.asarray(element_positions, float)
    line = _line_direction(p)
    A = (p[1:, :2] @ line)[:, None] if line is not None else p[1:, :2]
    sol = np.linalg.lstsq(A, -delta[1:], rcond=None)[0].T
    return sol[:, :1] * line[None, :] if line is not None else sol


def angles_from_solution(x_nf, u_ff):
    """Eq. 19-24 in the eq. 19 convention; returns dict of phi/psi/direction for NF and FF.

    NF: ``rho = ||(x, y)||``, ``psi = asin(rho / kappa)`` (polar angle from the array normal),
    ``direction = (x, y, sqrt(kappa^2 - rho^2)) / kappa``. FF: ``direction = (u_x, u_y,
    sqrt(1 - |u|^2))``. Ratios above 1 (noise) are clipped to 1.
    """
    x_nf = np.atleast_2d(x_nf)
    u_ff = np.atleast_2d(u_ff)
    kap = x_nf[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        s_nf = np.clip(np.hypot(x_nf[:, 0], x_nf[:, 1]) / np.abs(kap), 0.0, 1.0)
    phi_nf = np.arctan2(x_nf[:, 1], x_nf[:, 0])
    dir_nf = np.column_stack([s_nf * np.cos(phi_nf), s_nf * np.sin(phi_nf), np.sqrt(1 - s_nf**2)])
    s_ff = np.clip(np.hypot(u_ff[:, 0], u_ff[:, 1]), 0.0, 1.0)
    phi_ff = np.arctan2(u_ff[:, 1], u_ff[:, 0])
    dir_ff = np.column_stack([s_ff * np.cos(phi_ff), s_ff * np.sin(phi_ff), np.sqrt(1 - s_ff**2)])
    return {
        "phi_nf": phi_nf,
        "psi_nf": np.arcsin(s_nf),
        "dir_nf": dir_nf,
        "kappa_nf": kap,
        "phi_ff": phi_ff,
        "psi_ff": np.arcsin(s_ff),
        "dir_ff": dir_ff,
    }


# --- the public entry ----------------------------------------------------------------------------


@dataclass(frozen=True)
class PathEstimates:
    """Per-path estimates from one tensor, sorted by ``d`` (earliest first).

    ``alpha`` complex gain (eq. 12, refined), ``d`` distance ``c tau`` including the clock bias [m]
    (eq. 14), ``v`` relative velocity ``c f_d / fc`` [m/s] (eq. 15), ``direction`` (L, 3) unit
    vectors of arrival in the array's local frame, ``kappa`` wavefront radius [m] (NaN when
    far-field), ``near_field`` (bool), ``phi``/``psi`` local azimuth and polar angle (eq. 19
    convention), ``valid`` = Algorithm 1 keeps the path (``d >= 0``), ``kappa_nf`` the raw TLS
    value, ``delta`` (L, M) unwrapped path-length offsets (eq. 16), ``mu_f``/``mu_t`` the roots.
    """

    alpha: np.ndarray
    d: np.ndarray
    v: np.ndarray
    direction: np.ndarray
    kappa: np.ndarray
    near_field: np.ndarray
    phi: np.ndarray
    psi: np.ndarray
    valid: np.ndarray
    kappa_nf: np.ndarray
    delta: np.ndarray = field(repr=False)
    mu_f: np.ndarray = field(repr=False)
    mu_t: np.ndarray = field(repr=False)
    factors: tuple = field(repr=False)
    rel_error: float = 0.0
    n_iter: int = 0
    converged: bool = True

    def __len__(self) -> int:
        return self.d.shape[0]

    def __getitem__(self, key: str):
        return getattr(self, key)

    def wave_origins(self) -> np.ndarray:
        """``kappa * direction`` (L, 3) in the local frame (NaN rows for far-field paths)."""
        return self.kappa[:, None] * self.direction


def _check_tensor(H) -> np.ndarray:
    if H is None:
        raise TypeError("H: expected a complex 3-D array, got None")
    try:
        arr = np.asarray(H, dtype=complex)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"H: expected a complex 3-D array, got {type(H).__name__}") from exc
    if arr.ndim != 3:
        raise ValueError(f"H: expected a 3-D tensor (M x Nf x Nt), got shape {arr.shape}")
    if min(arr.shape) < 2:
        raise ValueError(f"H: every dimension must be >= 2, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("H: contains NaN or infinite values")
    if not np.any(arr):
        raise ValueError("H: is all zeros")
    return arr


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
    H = _check_tensor(H)
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


def path_estimates(
    alpha, d, v, ang: dict, near, delta, mu_f, mu_t, factors, rel_error, n_iter, converged
) -> PathEstimates:
    """Assemble :class:`PathEstimates` sorted by ``d``: near-field paths take the eq. 19-21
    angles and curvature of ``ang`` (:func:`angles_from_solution`), the others the far-field
    ones (``kappa`` NaN); ``delta`` is (L, M), ``factors`` the three (., L) factor matrices."""
    direction = np.where(near[:, None], ang["dir_nf"], ang["dir_ff"])
    kappa = np.where(near, ang["kappa_nf"], np.nan)
    phi = np.where(near, ang["phi_nf"], ang["phi_ff"])
    psi = np.where(near, ang["psi_nf"], ang["psi_ff"])
    o = np.argsort(d)
    return PathEstimates(
        alpha[o],
        d[o],
        v[o],
        direction[o],
        kappa[o],
        near[o],
        phi[o],
        psi[o],
        d[o] >= 0,
        ang["kappa_nf"][o],
        delta[o],
        mu_f[o],
        mu_t[o],
        tuple(B[:, o] for B in factors),
        rel_error,
        n_iter,
        converged,
    )


def algorithm1(est: PathEstimates) -> np.ndarray:
    """Algorithm 1 (ExtractMeas) checks: indices of the kept paths (``d >= 0``).

    The near/far choice (``kappa < 0`` -> far-field angles, no kappa) is already applied in
    :func:`extract_paths`; this returns the paths that survive line 5-6.
    """
    if not isinstance(est, PathEstimates):
        raise TypeError(f"est: expected PathEstimates, got {type(est).__name__}")
    return np.flatnonzero(est.valid)


# --- Cramér-Rao bound of the structured model -----------------------------------------------------


def crlb_paths(
    alpha,
    sources,
    element_positions,
    mu_f,
    mu_t,
    fc: float,
    n_tones: int,
    n_symbols: int,
    noise_power: float,
    *,
    spatial: str = "structured",
) -> dict[str, np.ndarray]:
    """CRLB of the eq. 1 model, all paths jointly.

    Per path the unknowns are ``Re alpha, Im alpha, mu_f, mu_t`` (the Vandermonde frequencies)
    and the spatial factor: with ``spatial="structured"`` the wave origin (3, local frame, exact
    spherical wavefront); with ``spatial="free"`` every entry ``a_m, m >= 1`` (real and imaginary
    part, ``a_0 = 1``): the model a CPD actually fits. ``alpha`` includes ``sqrt(P_t)``. The FIM
    ``2/N0 Re(J^H J)`` is assembled from the rank-1 structure (inner products factorise over the
    three modes). Returns the bound's standard deviations for ``mu_f``, ``mu_t`` (rad) and, when
    structured, the (L, 3, 3) covariance of each wave origin.
    """
    if spatial not in ("structured", "free"):
        raise ValueError(f"spatial: expected 'structured' or 'free', got {spatial!r}")
    alpha = np.atleast_1d(np.asarray(alpha, complex))
    src = np.atleast_2d(np.asarray(sources, float))
    p = np.asarray(element_positions, float)
    L = alpha.size
    k0 = 2 * np.pi * fc / C
    s = np.arange(n_tones)[:, None]
    kk = np.arange(n_symbols)[:, None]
    rng_m = np.linalg.norm(src[None, :, :] - p[:, None, :], axis=-1)  # (M, L)
    a = np.exp(1j * k0 * (rng_m - rng_m[0]))
    f = np.exp(1j * s * np.asarray(mu_f)[None, :])
    t = np.exp(1j * kk * np.asarray(mu_t)[None, :])
    # gradient of a_m w.r.t. the source: j k0 a_m (u_m - u_0), u_m = (src - p_m)/||src - p_m||
    u = (src[None, :, :] - p[:, None, :]) / rng_m[..., None]
    da = 1j * k0 * a[..., None] * (u - u[:1])  # (M, L, 3)
    X, Y, Z = [], [], []  # mode vectors of the 7 L rank-1 derivative terms
    for j_ in range(L):
        al = alpha[j_]
        terms = [
            (a[:, j_], f[:, j_], t[:, j_]),
            (1j * a[:, j_], f[:, j_], t[:, j_]),
            (al * a[:, j_], 1j * s[:, 0] * f[:, j_], t[:, j_]),
            (al * a[:, j_], f[:, j_], 1j * kk[:, 0] * t[:, j_]),
        ]
        if spatial == "structured":
            terms += [(al * da[:, j_, i], f[:, j_], t[:, j_]) for i in range(3)]
        else:
            eye = np.eye(a.shape[0])[:, 1:]
            terms += [(al * e, f[:, j_], t[:, j_]) for e in eye.T]
            terms += [(1j * al * e, f[:, j_], t[:, j_]) for e in eye.T]
        for x, y, z in terms:
            X.append(x)
            Y.append(y)
            Z.append(z)
    X, Y, Z = (np.stack(v, axis=1) for v in (X, Y, Z))
    gram = (X.conj().T @ X) * (Y.conj().T @ Y) * (Z.conj().T @ Z)
    fim = 2.0 / noise_power * gram.real
    # Jacobi scaling before the inverse: the parameters differ by many orders of magnitude
    dsc = 1.0 / np.sqrt(np.diag(fim))
    cov = dsc[:, None] * np.linalg.inv(dsc[:, None] * fim * dsc[None, :]) * dsc[None, :]
    n_per = fim.shape[0] // L
    idx = np.arange(L) * n_per
    out = {"mu_f": np.sqrt(cov[idx + 2, idx + 2]), "mu_t": np.sqrt(cov[idx + 3, idx + 3])}
    if spatial == "structured":
        out["source_cov"] = np.stack([cov[i + 4 : i + 7, i + 4 : i + 7] for i in idx])
    return out
