"""Stage 1 of the extraction: the CP decomposition of the channel tensor (Italiano et al. 2026, eq. 3, 11, 12).

:func:`cpd` — canonical polyadic decomposition of ``H`` with tensorly's ``parafac``.
``method="fast"`` compresses ``H`` to an ``L x L x min(L, Nt)`` core (truncated HOSVD with a
randomised range finder), initialises the core factors algebraically (ESPRIT on the Vandermonde
frequency factor: the delay roots are the eigenvalues of the shift-invariance matrix), refines them
with ``parafac(init=..., linesearch=True)`` and lifts them back. ``method="plain"`` is
``parafac(H, L, init="svd", linesearch=True)`` on the full tensor. :func:`check_rank` refuses a
rank Kruskal's condition cannot identify; :func:`normalize_factors` is the scaling fix
``B <- B diag^-1(B[0, :])`` and the eq. 12 gains.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import tensorly as tl
from tensorly.cp_tensor import CPTensor
from tensorly.decomposition import parafac

from .._validate import choice, finite_array, integer, positive, record, sequence
from ..arrays import check_element_positions
from .numerics import contract, grid_index

__all__ = [
    "MAX_SWEEPS",
    "CPDConvergenceWarning",
    "CPDResult",
    "check_rank",
    "check_tensor",
    "cp_rel_error",
    "cpd",
    "max_identifiable_rank",
    "normalize_factors",
]

#: cap on the iterations of the CPD (``n_iter_max``) and its ALS sweeps (``polish``): one sweep
#: costs about one pass over the tensor (~10 ms at M = 100, Nf = 410, Nt = 12), so 10,000 are
#: minutes, the time budget of one snapshot many times over; more is a mistake, refused
MAX_SWEEPS = 10_000


class CPDConvergenceWarning(UserWarning):
    """The CP decomposition stopped at ``n_iter_max`` before reaching ``tol``."""


class CheckedTensor(np.ndarray):
    """A channel tensor that passed :func:`check_tensor` (a view of it, no copy), so the stages
    it is handed on to (CPD, the paper's route, the coherent split, the ML fit) need not scan it
    again. Arithmetic on it gives plain arrays: only the checked tensor itself is marked."""

    def __array_wrap__(self, arr, context=None, return_scalar=False):
        out = np.asarray(arr).view(np.ndarray)
        return out[()] if return_scalar else out


def check_tensor(H) -> np.ndarray:
    """``H`` as a complex 3-D tensor, every dimension >= 2, finite and not all zeros, else an
    error naming ``H``; returned as a :class:`CheckedTensor` view, which passes again at once."""
    if isinstance(H, CheckedTensor) and H.ndim == 3 and min(H.shape) >= 2:
        return H
    if H is None:
        raise TypeError("H: expected a complex 3-D array, got None")
    raw = np.asarray(H) if not isinstance(H, np.ndarray) else H
    if raw.dtype.kind in "biuf":
        raise TypeError(
            f"H: expected a complex channel tensor, got real values ({raw.dtype}); the phase "
            "carries delay, direction and Doppler, so a real part or a magnitude (np.abs(H)) "
            "cannot be fitted"
        )
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
    return arr.view(CheckedTensor)


def max_identifiable_rank(shape) -> int:
    """Largest ``L`` for which Kruskal's condition can hold for a tensor of ``shape``.

    With generic factors ``kr(B_i) = min(I_i, L)``; eq. 11's condition ``sum kr >= 2 L + 2`` is
    then a condition on the dimensions alone (a rank-1 CPD is always unique).
    """
    if isinstance(shape, str | bytes) or not hasattr(shape, "__len__"):
        raise TypeError(f"shape: expected a tensor shape (M, Nf, Nt), got {shape!r}")
    dims = [integer("shape", s, minimum=1) for s in shape]
    best = 1
    for L in range(2, sum(dims) + 1):
        if sum(min(i, L) for i in dims) >= 2 * L + 2:
            best = L
    return best


def check_rank(shape, n_paths) -> int:
    """``n_paths`` as an int, or ``ValueError`` if Kruskal's condition cannot identify it."""
    n = integer("n_paths", n_paths, minimum=1)
    if isinstance(shape, str | bytes) or not hasattr(shape, "__len__") or len(shape) != 3:
        raise ValueError(f"shape: expected a 3-way tensor shape (M, Nf, Nt), got {shape!r}")
    top = max_identifiable_rank(shape)
    if n > top:
        raise ValueError(
            f"n_paths: {n} paths cannot be identified in a tensor of shape {tuple(shape)}: "
            f"Kruskal's condition kr(Bs)+kr(Bf)+kr(Bt) >= 2L+2 allows at most L = {top}"
        )
    return n


@dataclass(frozen=True)
class CPDResult:
    """Factor matrices ``(A, B, C)`` with ``H ~ sum_l a_l o b_l o c_l`` (weights folded into A)."""

    factors: tuple[np.ndarray, np.ndarray, np.ndarray]
    rel_error: float
    n_iter: int
    converged: bool
    method: str

    def __post_init__(self) -> None:
        record(self, shapes={"factors": (3,)}, nonnegative=("rel_error", "n_iter"))
        choice("method", self.method, ("fast", "plain"))
        _check_factors(self.factors)


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
    grid = grid_index(np.asarray(element_positions, float))
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
    H = check_tensor(H)
    L = check_rank(H.shape, n_paths)
    n_iter_max = integer("n_iter_max", n_iter_max, minimum=1, maximum=MAX_SWEEPS)
    tol = positive("tol", tol)
    polish = integer("polish", polish, minimum=0, maximum=MAX_SWEEPS)
    integer("seed", seed, minimum=0)
    if element_positions is not None:
        check_element_positions("element_positions", element_positions, m=H.shape[0])
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


def _check_factors(factors, name: str = "factors") -> list[np.ndarray]:
    """Three finite factor matrices (rows, L) with the same number of columns ``L``, as arrays;
    errors name ``name``."""
    out = sequence(name, factors)
    if len(out) != 3:
        raise ValueError(f"{name}: expected the three factor matrices (A, F, T), got {len(out)}")
    out = [finite_array(f"{name}[{i}]", B, ndim=2, dtype=complex) for i, B in enumerate(out)]
    if len({B.shape[1] for B in out}) != 1:
        raise ValueError(f"{name}: one column per component in each, got {[B.shape for B in out]}")
    return out


def normalize_factors(factors):
    """Scaling fix ``B <- B diag^-1(B[0, :])`` for each factor, and eq. 12 ``alpha = prod B[0, l]``."""
    out, alpha = [], 1.0
    for B in _check_factors(factors):
        first = B[0]
        if np.any(np.abs(first) < 1e-300):
            raise ValueError(
                "factors: a factor column has a zero first entry; cannot fix the scale"
            )
        out.append(B / first[None, :])
        alpha = alpha * first
    return out, np.asarray(alpha)


def cp_rel_error(H: np.ndarray, factors, nh2: float | None = None) -> float:
    """``||H - [[A, B, C]]|| / ||H||`` without forming the model tensor: the cross term is one
    contraction of ``H``, the model's energy the Hadamard product of the factors' Gram matrices."""
    H = check_tensor(H)
    A, B, Cm = _check_factors(factors)
    nh2 = float(np.vdot(H, H).real) if nh2 is None else positive("nh2", nh2)
    fit = contract(H, B.conj(), Cm.conj())  # <H, model> per component before summing
    gram = (A.conj().T @ A) * (B.conj().T @ B) * (Cm.conj().T @ Cm)
    err2 = nh2 - 2 * float(np.sum(np.real(A.conj() * fit))) + float(np.real(gram.sum()))
    return float(np.sqrt(max(err2, 0.0) / nh2))
