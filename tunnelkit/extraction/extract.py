"""The front of the extraction: :func:`extract_paths`, one call for every route."""

from __future__ import annotations

from .._validate import boolean, choice, integer, positive
from .coherent import resolve_coherent
from .decomposition import MAX_SWEEPS, check_rank, check_tensor
from .estimates import PathEstimates
from .ml import ml_paths
from .paper import paper_route
from .radio import check_array, check_srs

__all__ = ["ROUTES", "extract_paths"]

#: the routes of :func:`extract_paths` (``refine``)
ROUTES = ("ml", "coherent", "joint", "column", "none")


def extract_paths(
    H,
    n_paths: int,
    array,
    srs,
    *,
    refine: str = "ml",
    method: str = "fast",
    n_iter_max: int = 200,
    tol: float = 1e-10,
    polish: int | None = None,
    noise_power: float | None = None,
    search: str = "residual",
    wideband: bool = False,
) -> PathEstimates:
    """Path parameters from the channel tensor, one entry per path.

    Parameters
    ----------
    H : (M, Nf, Nt) complex tensor following eq. 1 as printed (see the package docstring).
    n_paths : number of paths L (known, as in the paper); refused beyond Kruskal's condition.
    array : a :class:`tunnelkit.arrays.ArrayGeometry` (its ``local`` element positions are used)
        or an (M, 3) array of local-frame positions (``z = 0``, reference antenna at the origin).
    srs : a :class:`tunnelkit.channel.SRSConfig`: the carrier ``fc``, the spacing ``Delta f`` of
        the tones along axis 1 (``tone_spacing``) and the period ``T0`` of the samples along
        axis 2 (``symbol_period``).
    refine : the route: "ml" (default; the joint maximum-likelihood fit, :mod:`.ml`), "coherent"
        (:func:`.coherent.resolve_coherent`), or the paper's route (:func:`.paper.paper_route`)
        with "joint", "column" or "none" refinement of the eq. 13 roots.
    method : "fast" (compressed, ESPRIT-initialised) or "plain" (``parafac(init='svd')``).
    polish : ALS sweeps on the full tensor after the compressed CPD (default 2, or 0 with
        ``refine="joint"``, which supersedes them).
    noise_power : noise power per sample for the "ml" route (default: estimated from ``H``).
    search : the "ml" route's search, "residual" (default) or "basic"; see
        :func:`.ml.fitting.fit_problem`.
    wideband : the "ml" route's model carries the spatial-wideband term (:mod:`.ml.wideband`); off
        by default (eq. 1).

    Returns a :class:`PathEstimates` (``alpha, d, v, direction, kappa, near_field`` and more); it
    also supports ``est["d"]``. On the "ml" route see :func:`.ml.ml_paths` for what each field
    holds (``kappa`` is finite for every near-field wave; ``fit`` has the noise floor test).
    Each route and search in full: docs/internals/extraction-ml.md.
    """
    H = check_tensor(H)
    L = check_rank(H.shape, n_paths)
    pos = check_array(array, m=H.shape[0])
    srs = check_srs(srs)
    if refine not in ROUTES:
        raise ValueError(f"refine: expected one of {ROUTES}, got {refine!r}")
    wideband = boolean("wideband", wideband)
    # the CPD's knobs are checked on every route (the "ml" route starts from its own CPD)
    choice("method", method, ("fast", "plain"))
    integer("n_iter_max", n_iter_max, minimum=1, maximum=MAX_SWEEPS)
    positive("tol", tol)
    if polish is not None:
        integer("polish", polish, minimum=0, maximum=MAX_SWEEPS)
    if refine == "ml":
        noise_power = positive("noise_power", noise_power, none=True)
        return ml_paths(H, L, pos, srs, noise_power=noise_power, search=search, wideband=wideband)
    if noise_power is not None:
        raise ValueError(f"noise_power: only used by refine='ml', not {refine!r}")
    if search != "residual":
        raise ValueError(f"search: only used by refine='ml', not {refine!r}")
    if wideband:
        raise ValueError(f"wideband: only modelled by refine='ml', not {refine!r}")
    cpd_kw = {"method": method, "n_iter_max": n_iter_max, "tol": tol, "polish": polish}
    if refine == "coherent":
        est = paper_route(H, L, pos, srs, refine="joint", **cpd_kw)
        return resolve_coherent(H, est, pos, srs, L)
    return paper_route(H, L, pos, srs, refine=refine, **cpd_kw)
