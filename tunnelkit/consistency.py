"""Geometry consistency of one snapshot's first-order paths: do they agree with one UE position?

A first-order specular path from a UE at ``p`` off a known plane arrives from the UE's mirror
image (its VUE, ``mirror(p)``); its delay is the VUE's distance plus the common clock-bias range
``beta``. One snapshot's paths (world directions ``u_j``, biased ranges ``d_j`` seen from the
array's reference antenna ``o``) therefore agree with one ``(p, beta)`` through the tunnel's
planes, whatever their individual fit to the tensor. :func:`geometry_consistency` finds that
``(p, beta)`` and tests each path against it:

1. hypotheses: each of the ``n_los`` earliest paths taken as the LoS; the UE on its ray at the
   point whose mirror image in a plane lies on another path's ray (two rays, closest points: the
   virtual station's triangulation), for every other path and plane; ``beta`` from the LoS delay;
2. each hypothesis scored by ``sum_j min(r_j^2, g)``, ``r_j^2`` the squared normalised residual of
   path ``j`` (azimuth, elevation, range) under its best-fitting plane (or the LoS), ``g`` the
   per-path chi-square(3) threshold at the false-alarm rate ``pfa``;
3. the best hypothesis refined by least squares over ``(p, beta)`` on the paths within ``g``;
4. the snapshot's statistic ``T``: the least-squares fit of every path (planes as assigned),
   ``T = sum_j r_j^2`` there, against the chi-square(``3 K - 4``) threshold at ``pfa``
   (``consistent``); returned: per path ``r_j^2`` (of the fit of all when consistent, else of
   the inliers' fit), its plane (-1: the LoS), ``keep = r_j^2 <= g``, the UE and ``beta``.

The residuals are normalised by ``sigma^2 = sigma_bound^2 + floor^2`` per component: the bound's
standard deviations (e.g. the CRLB the extraction reports) and a stated model-error floor
(``floor_angle`` [rad], ``floor_range`` [m]; zero by default, the test of eq. 1 itself).
Without ``cov`` the correlations within a path and between paths are left out (the statistic
then over-rejects: the ML fit's paths are correlated up to 0.9 at the presets' geometry); with
the joint covariance ``cov`` of all paths the statistic is the generalised least-squares
chi-square. :func:`consistent_paths` runs it on a
route's measurements (the rows of a :class:`tunnelkit.tracking.javelin.PathMeasurements`).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_triangular
from scipy.optimize import least_squares
from scipy.stats import chi2

from ._validate import (
    finite_array,
    instance,
    integer,
    nonnegative,
    probability,
    sequence,
    vector,
)
from .geometry import Plane

__all__ = ["consistent_paths", "geometry_consistency", "plane_kinds", "tunnel_planes"]


def _distinct_planes(tunnel) -> list:
    """The first surface of ``tunnel`` on each distinct plane (``(normal, offset)`` to 1e-9)."""
    from .propagation import Tunnel3D

    instance("tunnel", tunnel, Tunnel3D)
    seen, out = set(), []
    for f in tunnel.surfaces:
        pl = f.plane
        key = tuple(np.round(np.append(pl.normal, pl.offset), 9))
        if key not in seen:
            seen.add(key)
            out.append(f)
    return out


def tunnel_planes(tunnel) -> list[Plane]:
    """The distinct planes of ``tunnel``'s reflecting surfaces (facets and road markings; one
    plane per ``(normal, offset)`` to 1e-9)."""
    return [f.plane for f in _distinct_planes(tunnel)]


def plane_kinds(tunnel) -> tuple[str, ...]:
    """The surface kind of each plane of :func:`tunnel_planes` (``"wall"``, ``"ceiling"``,
    ``"road"``, ``"rrm"``), in its order: ``plane_kinds(t)[i]`` is the kind of the paths
    :func:`geometry_consistency` assigns to plane ``i``."""
    return tuple(f.kind for f in _distinct_planes(tunnel))


def _mirror_all(points: np.ndarray, normals: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """``points`` (..., 3) mirrored in every plane: (..., P + 1, 3), index 0 the point itself."""
    s = points @ normals.T + offsets  # (..., P)
    m = points[..., None, :] - 2.0 * s[..., None] * normals
    return np.concatenate([points[..., None, :], m], axis=-2)


def _angles(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r = np.linalg.norm(v, axis=-1)
    return np.arctan2(v[..., 1], v[..., 0]), np.arcsin(np.clip(v[..., 2] / r, -1, 1)), r


def _residuals(p, beta, o, phi, psi, d, normals, offsets, sig):
    """Normalised residuals (K, P + 1, 3) of every path under every plane (0: the LoS)."""
    vue = _mirror_all(np.asarray(p, float), normals, offsets) - o  # (P + 1, 3)
    a, e, r = _angles(vue)
    dphi = np.angle(np.exp(1j * (phi[:, None] - a[None])))
    res = np.stack([dphi, psi[:, None] - e[None], d[:, None] - r[None] - beta], axis=-1)
    return res / sig[:, None, :]


def _triangulate(o, u_los, u_k, normals, offsets) -> np.ndarray:
    """Range ``t`` along the LoS ray whose mirror in each plane lies closest to ray ``u_k``:
    (P,) (NaN where the rays are parallel or ``t <= 0``)."""
    o_m = _mirror_all(o, normals, offsets)[1:]  # (P, 3)
    u_m = u_los - 2.0 * (u_los @ normals.T)[:, None] * normals  # (P, 3) reflected directions
    # minimise |o_m + t u_m - (o + s u_k)|^2 over (t, s)
    w = o_m - o
    b = u_m @ u_k
    den = 1.0 - b**2
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (b * (w @ u_k) - (w * u_m).sum(-1)) / den
    t[(den < 1e-12) | ~(t > 0)] = np.nan
    return t


def geometry_consistency(
    direction,
    d,
    origin,
    planes,
    sigma_phi,
    sigma_psi,
    sigma_d,
    *,
    pfa: float = 0.01,
    floor_angle: float = 0.0,
    floor_range: float = 0.0,
    n_los: int = 3,
    coarse: tuple[float, float] = (1e-3, 0.05),
    inside=None,
    cov=None,
) -> dict:
    """The geometry-consistency test of one snapshot's paths (module docstring).

    ``direction`` (K, 3) world unit vectors of arrival, ``d`` (K,) biased ranges [m] (delay times
    c), ``origin`` (3,) the reference antenna, ``planes`` the known reflecting planes
    (:func:`tunnel_planes`), ``sigma_phi`` / ``sigma_psi`` [rad] and ``sigma_d`` [m] the bound's
    standard deviations (scalars or (K,)), ``pfa`` the false-alarm rate of both tests,
    ``floor_angle`` / ``floor_range`` the model-error floor, ``n_los`` how many of the earliest
    paths are tried as the LoS, ``coarse`` the (angle [rad], range [m]) floor under which the
    hypotheses are ranked (the plane assignment is chosen there, then refined at ``sigma``),
    ``inside`` (optional) a callable ``p -> bool`` that a hypothesised UE must pass (e.g.
    ``tunnel.contains``), ``cov`` (optional) the bound's joint (3 K, 3 K) covariance of every
    path's ``(phi, psi, d)`` (row ``3 j + i``; e.g.
    :func:`tunnelkit.path_consistency.joint_bound`): then the snapshot's statistic is the
    generalised least-squares fit ``min z^T (cov + F)^-1 z`` (``F`` the floors squared on the
    diagonal; correlations within and between paths included) and each path's ``r2`` uses its
    3 x 3 block (the ``sigma_*`` still rank the hypotheses and assign the planes). Returns a dict: ``r2`` (K,), ``plane`` (K,) (-1 LoS),
    ``keep`` (K,) bool, ``statistic``, ``dof``, ``threshold``, ``consistent``, ``ue`` (3,),
    ``beta`` [m]; with fewer than two paths nothing is testable (``consistent`` True, all kept,
    ``dof`` 0)."""
    u = finite_array("direction", direction)
    if u.ndim != 2 or u.shape[1] != 3:
        raise ValueError(f"direction: expected (K, 3) unit vectors, got shape {u.shape}")
    K = u.shape[0]
    d = finite_array("d", d)
    if d.shape != (K,):
        raise ValueError(f"d: expected {K} values (one per path), got shape {d.shape}")
    o = vector("origin", origin, 3)
    pl = [instance(f"planes[{i}]", p, Plane) for i, p in enumerate(sequence("planes", planes))]
    if not pl or any(p.dim != 3 for p in pl):
        raise ValueError("planes: expected one or more 3-D planes")
    pfa = probability("pfa", pfa)
    fa, fr = nonnegative("floor_angle", floor_angle), nonnegative("floor_range", floor_range)
    n_los = integer("n_los", n_los, minimum=1)
    sig = []
    for name, s, floor in (
        ("sigma_phi", sigma_phi, fa),
        ("sigma_psi", sigma_psi, fa),
        ("sigma_d", sigma_d, fr),
    ):
        s = np.broadcast_to(finite_array(name, s), (K,)).astype(float)
        if np.any(s < 0):
            raise ValueError(f"{name}: must be >= 0")
        s = np.sqrt(s**2 + floor**2)
        if np.any(s <= 0):
            raise ValueError(f"{name}: zero with a zero floor leaves the test undefined")
        sig.append(s)
    sig = np.stack(sig, axis=-1)  # (K, 3)
    chol = None
    if cov is not None:
        cv = finite_array("cov", cov)
        if cv.shape != (3 * K, 3 * K) or not np.allclose(cv, cv.T, rtol=1e-9, atol=0.0):
            raise ValueError(f"cov: expected a symmetric ({3 * K}, {3 * K}) matrix, got {cv.shape}")
        cv = cv + np.diag(np.tile([fa**2, fa**2, fr**2], K))
        try:
            chol = np.linalg.cholesky(cv)
        except np.linalg.LinAlgError as exc:
            raise ValueError("cov: not positive definite") from exc
    g = float(chi2.ppf(1.0 - pfa, 3))
    if K < 2:
        return {"r2": np.zeros(K), "plane": -np.ones(K, int), "keep": np.ones(K, bool),
                "statistic": 0.0, "dof": 0, "threshold": np.nan, "consistent": True,
                "ue": np.full(3, np.nan), "beta": np.nan}  # fmt: skip
    u = u / np.linalg.norm(u, axis=1, keepdims=True)
    normals = np.array([p.normal for p in pl])
    offsets = np.array([p.offset for p in pl])
    phi, psi, _ = _angles(u)
    order = np.argsort(d)
    ca, cr = (nonnegative("coarse", c) for c in vector("coarse", coarse, 2))
    sig_c = np.maximum(sig, [ca, ca, cr])
    if inside is not None and not callable(inside):
        raise TypeError(f"inside: expected a callable p -> bool, got {type(inside).__name__}")
    best = None
    for i in order[: min(n_los, K)]:
        ts = [_triangulate(o, u[i], u[k], normals, offsets) for k in range(K) if k != i]
        ts = np.concatenate(ts)
        for t in ts[np.isfinite(ts)]:
            p, beta = o + t * u[i], d[i] - t
            if inside is not None and not bool(np.all(inside(p))):
                continue
            r2 = (_residuals(p, beta, o, phi, psi, d, normals, offsets, sig_c) ** 2).sum(-1)
            cost = float(np.minimum(r2.min(1), g).sum())
            if best is None or cost < best[0]:
                best = (cost, p, beta)
    if best is None:  # no triangulation: the LoS range from its delay, beta = 0
        best = (np.inf, o + d[order[0]] * u[order[0]], 0.0)
    x = np.append(best[1], best[2])
    prev = None
    for it in range(8):  # refine on the inliers of the current plane assignment until it settles
        s_it = sig_c if it == 0 else sig  # the coarse assignment first
        r2 = (_residuals(x[:3], x[3], o, phi, psi, d, normals, offsets, s_it) ** 2).sum(-1)
        plane, inl = r2.argmin(1), r2.min(1) <= g
        if inl.sum() < 2 or (prev is not None and np.array_equal(prev, np.where(inl, plane, -9))):
            break
        prev = np.where(inl, plane, -9) if it else None
        rows = np.flatnonzero(inl)

        def f(z, rows=rows, plane=plane, s_it=s_it):
            res = _residuals(z[:3], z[3], o, phi[rows], psi[rows], d[rows], normals, offsets,
                             s_it[rows])  # fmt: skip
            return res[np.arange(rows.size), plane[rows]].ravel()

        x = least_squares(f, x, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    r2 = (_residuals(x[:3], x[3], o, phi, psi, d, normals, offsets, sig) ** 2).sum(-1)
    plane, r2 = r2.argmin(1), r2.min(1)
    dof = 3 * K - 4
    thr = float(chi2.ppf(1.0 - pfa, dof))
    # the snapshot's statistic: the least-squares fit of every path (planes as assigned)
    rows = np.arange(K)

    def f_all(z):
        res = _residuals(z[:3], z[3], o, phi, psi, d, normals, offsets, sig)
        return res[rows, plane].ravel()

    if chol is None:
        x_all = least_squares(f_all, x, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        r2_all = (f_all(x_all).reshape(K, 3) ** 2).sum(-1)
        stat = float(r2_all.sum())
    else:  # generalised least squares: the residuals whitened by the joint covariance
        one = np.ones_like(sig)

        def raw(z):
            return _residuals(z[:3], z[3], o, phi, psi, d, normals, offsets, one)[rows, plane]

        def f_gls(z):
            return solve_triangular(chol, raw(z).ravel(), lower=True)

        x_all = least_squares(f_gls, x, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        stat = float(np.sum(f_gls(x_all) ** 2))
        blocks = np.stack([cv[3 * j : 3 * j + 3, 3 * j : 3 * j + 3] for j in range(K)])

        def block_r2(z):
            e = raw(z)
            return np.einsum("ki,ki->k", e, np.linalg.solve(blocks, e[..., None])[..., 0])

        r2_all = block_r2(x_all)
        r2 = block_r2(x)
    ok = stat <= thr
    if ok:  # consistent: every path judged against the fit of all
        x, r2 = x_all, r2_all
    return {
        "r2": r2,
        "plane": plane - 1,
        "keep": r2 <= g,
        "statistic": stat,
        "dof": dof,
        "threshold": thr,
        "consistent": bool(ok),
        "ue": x[:3].copy(),
        "beta": float(x[3]),
    }


def consistent_paths(measurements, tunnel, origin=None, **kw) -> dict:
    """:func:`geometry_consistency` of a route's measurements (``phi``, ``psi``, ``d``,
    ``direction``, ``origin`` and, when the route reports them, ``cov`` / ``sigma_d``: the bound
    the residuals are normalised by; without them ``kw`` must give ``sigma_phi``, ``sigma_psi``,
    ``sigma_d``) through ``tunnel``'s planes; ``kw`` the test's options."""
    from .propagation import Tunnel3D

    m = measurements
    for name in ("phi", "psi", "d", "direction", "origin"):
        if not hasattr(m, name):
            raise TypeError(f"measurements: expected a PathMeasurements, got {type(m).__name__}")
    instance("tunnel", tunnel, Tunnel3D)
    o = m.origin if origin is None else vector("origin", origin, 3)
    if o is None:
        raise ValueError("origin: the measurements carry no origin; give the array's position")
    if getattr(m, "cov", None) is not None and "sigma_phi" not in kw:
        kw.setdefault("sigma_phi", np.sqrt(m.cov[:, 0, 0]))
        kw.setdefault("sigma_psi", np.sqrt(m.cov[:, 1, 1]))
        kw.setdefault("sigma_d", m.sigma_d)
    missing = [k for k in ("sigma_phi", "sigma_psi", "sigma_d") if k not in kw]
    if missing:
        raise ValueError(
            f"{', '.join(missing)}: the measurements report no covariance; give the bound's sigmas"
        )
    kw.setdefault("inside", tunnel.contains)
    return geometry_consistency(m.direction, m.d, o, tunnel_planes(tunnel), **kw)
