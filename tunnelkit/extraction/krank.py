"""The Kruskal rank of a factor matrix (:func:`kruskal_rank`): how many columns are always
independent, the quantity in Kruskal's condition for a unique CP decomposition (the extraction's
:func:`~tunnelkit.extraction.decomposition.check_rank` uses its generic bound instead)."""

from __future__ import annotations

from itertools import combinations
from math import comb

import numpy as np

from .._validate import finite_array, positive

__all__ = ["kruskal_rank"]


def kruskal_rank(B, tol: float = 1e-6) -> int:
    """Kruskal rank of ``B`` (brute force): the largest k such that every k columns are independent.

    A column set counts as independent when its smallest singular value exceeds ``tol`` times the
    largest one (columns normalised first), so nearly collinear columns lower the rank.
    """
    B = finite_array("B", B, ndim=2, dtype=complex)
    tol = positive("tol", tol)
    B = B / np.maximum(np.linalg.norm(B, axis=0, keepdims=True), 1e-300)
    L = B.shape[1]
    if 0 < L <= B.shape[0]:
        # polynomial shortcut: singular values of a column subset interlace the full set's, so a
        # well-conditioned full set makes every subset independent (k-rank = L)
        s = np.linalg.svd(B, compute_uv=False)
        if s[-1] > tol * s[0]:
            return L
    if sum(comb(L, k) for k in range(1, min(L, B.shape[0]) + 1)) > 200_000:
        raise ValueError(
            f"B: {L} dependent columns: the exact Kruskal rank would test over 200,000 column "
            "subsets (drop dependent columns or pass fewer)"
        )
    kr = 0
    for k in range(1, min(L, B.shape[0]) + 1):
        for cols in combinations(range(L), k):
            s = np.linalg.svd(B[:, cols], compute_uv=False)
            if s[-1] <= tol * s[0]:
                return kr
        kr = k
    return kr
