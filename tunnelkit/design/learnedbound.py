"""The bound over the drive of a tracker that learns its VUEs: the posterior CRLB whose state is
what JAVELIN estimates when it does not know the surfaces.

:func:`tunnelkit.design.drivebound.drive_pcrlb` takes every surface as known: a reflection then
measures the UE as directly as the LoS does. A JAVELIN that learns its VUEs (Algorithm 3: each
VUE placed from its path's angles and learnt over the drive) estimates ``s = [x_u, y_u, y_v1,
z_v1, ...]`` (the UE's height known, as in the PEB; a VUE shares the UE's ``x``), and a
reflection says where the UE is only as far as its VUE is tied to the UE by the motion: the VUE
moves by the UE's displacement mirrored in its surface (``MirrorMotion``) plus a small random
walk. :func:`learned_pcrlb` runs the posterior CRLB (Tichavsky et al. 1998) of that state:

* prior: the UE ``sigma_p0^2 I_2``; a VUE ``sigma_birth^2 I_2`` from the epoch its path appears
  (again after every epoch its path is missing: the tracker drops a VUE after one miss and
  starts it afresh, so what it had learnt is lost);
* motion: ``F = I``; ``Q`` from the V2X speed and heading noise through ``G`` (the UE's rows and,
  for VUE ``v``, the UE's rows mirrored in its surface, ``M_v G``: one noise drives all), plus
  ``sigma_walk^2 dt I_2`` per VUE;
* information per epoch: ``H^T crlb^-1 H`` of every existing path's ``z = [phi, psi, kappa, d]``
  with ``H`` the map of ``s`` (and of the clock bias ``c b``, eliminated by the Schur complement)
  into it: the LoS through the UE, a reflection through ``(x_u, y_v, z_v)``.

:func:`batch_information` builds the same problem as one information matrix over all epochs
(the test checks the recursion against it). The bound is of the noise only, as ``drive_pcrlb``;
:func:`~tunnelkit.design.drivebound.drive_bound` adds the bias that does not average down.
"""

from __future__ import annotations

import numpy as np

from .._validate import finite_array, nonnegative, positive
from ..budget import check_elements
from .drivebound import drive_motion
from .errormodel import PathErrorModel
from .setup import DesignSetup

__all__ = ["batch_information", "learned_model", "learned_pcrlb"]

#: a VUE's prior standard deviation at birth [m] (JAVELIN's ``sigma_P``: 10 m, diffuse against
#: what one epoch's angles say)
SIGMA_BIRTH = 10.0


def _epoch_rows(model, geometry, k: int, n: int, learned: bool):
    """Epoch ``k``: the rows of the existing paths, ``H`` (4m, n) of the state into them and
    the weights ``W`` (4m, 4m) of ``crlb^-1`` with the clock bias eliminated
    (``W - W h (h^T W h)^-1 h^T W``, ``h`` the ``c b`` column): ``H^T W H`` is the epoch's
    information, ``(H^T W H)^-1 H^T W`` its estimator. ``None`` without a path."""
    from ..geometry import spherical_jacobian

    j = np.flatnonzero(model.exists[k] & geometry.exists[k])
    if not j.size:
        return None
    rel = geometry.source[k, j] - geometry.origin[k]
    Js = spherical_jacobian(rel)  # (m, 3, 3) d(phi, psi, r) / d source
    H = np.zeros((j.size, 4, n))
    for a, p in enumerate(j):
        if p == 0 or not learned:  # through the UE (mirrored in a known surface)
            D = Js[a] @ geometry.mirror[p][:, :2]
            H[a, :3, :2] = D
            H[a, 3, :2] = D[2]
        else:  # through (x_u, y_v, z_v)
            c = 2 + 2 * (p - 1)
            H[a, :3, 0] = Js[a, :, 0]
            H[a, :3, c : c + 2] = Js[a, :, 1:]
            H[a, 3, 0] = Js[a, 2, 0]
            H[a, 3, c : c + 2] = Js[a, 2, 1:]
    rows = (4 * j[:, None] + np.arange(4)).ravel()
    R = model.crlb[k][np.ix_(rows, rows)]
    W = np.linalg.pinv(0.5 * (R + R.T), rcond=1e-15, hermitian=True)
    h = np.zeros(rows.size)
    h[3::4] = 1.0  # c b in every delay distance
    Wh = W @ h
    if h @ Wh > 0:
        W = W - np.outer(Wh, Wh) / (h @ Wh)
    return rows, H.reshape(-1, n), 0.5 * (W + W.T)


def learned_model(
    model: PathErrorModel,
    geometry,
    setup: DesignSetup,
    *,
    vues: str = "learned",
    sigma_speed: float | None = None,
    sigma_heading: float | None = None,
    sigma_walk: float | None = None,
):
    """The pieces of :func:`learned_pcrlb`: ``info`` (T, n, n) the measurement information per
    epoch, ``Q`` (T, n, n) the motion noise into each epoch, ``born`` (T, S) bool (slot ``s``'s
    VUE starts afresh at epoch ``k``) and ``rows`` (per epoch ``(rows, H, W)`` of
    :func:`_epoch_rows` or ``None``). ``vues="learned"``: state ``[x_u, y_u, (y_v, z_v) per
    reflection slot]``; ``"known"``: ``[x_u, y_u]``, every reflection through its known surface
    (the state of :func:`~tunnelkit.design.drivebound.drive_pcrlb`)."""
    from ..studies.drives import SIGMA_HEADING, SIGMA_SPEED
    from ..tracking.javelin.designs import ARRAY_DESIGN_VUE_WALK

    if not isinstance(model, PathErrorModel):
        raise TypeError(f"model: expected a design.PathErrorModel, got {type(model).__name__}")
    if not isinstance(setup, DesignSetup):
        raise TypeError(f"setup: expected a design.DesignSetup, got {type(setup).__name__}")
    from .geometry import RouteGeometry

    if not isinstance(geometry, RouteGeometry):
        raise TypeError(f"geometry: expected a design.RouteGeometry, got {type(geometry).__name__}")
    if geometry.exists.shape != model.exists.shape:
        raise ValueError("geometry: expected the model's epochs and path slots")
    if vues not in ("learned", "known"):
        raise ValueError(f"vues: expected 'learned' or 'known', got {vues!r}")
    sig_nu = positive("sigma_speed", SIGMA_SPEED if sigma_speed is None else sigma_speed)
    sig_th = positive("sigma_heading", SIGMA_HEADING if sigma_heading is None else sigma_heading)
    walk = nonnegative("sigma_walk", ARRAY_DESIGN_VUE_WALK if sigma_walk is None else sigma_walk)
    learned = vues == "learned"
    T, P = model.exists.shape
    S = P - 1 if learned else 0
    n = 2 + 2 * S
    ex = model.exists & geometry.exists
    G, Qn, dt = drive_motion(setup, T, sig_nu, sig_th)
    # every state entry's sensitivity to (nu, theta): the UE's, and its yz part mirrored per VUE
    Gs = np.zeros((T, n, 2))
    Gs[:, :2] = G
    for s in range(S):
        M2 = geometry.mirror[1 + s][1:, 1:]
        Gs[:, 2 + 2 * s : 4 + 2 * s] = np.einsum("ij,tjc->tic", M2[:, :1], G[:, 1:2])
    Q = Gs @ Qn @ np.swapaxes(Gs, 1, 2)
    idx = np.arange(2, n)
    Q[:, idx, idx] += walk**2 * dt[:, None]
    Q += 1e-12 * np.eye(n)  # a standing vehicle: still a valid recursion
    info = np.zeros((T, n, n))
    rows = []
    for k in range(T):
        r = _epoch_rows(model, geometry, k, n, learned)
        rows.append(r)
        if r is not None:
            J = r[1].T @ r[2] @ r[1]
            info[k] = 0.5 * (J + J.T)
    prev = np.vstack([np.zeros((1, S), bool), ex[:-1, 1 : 1 + S]])
    born = ex[:, 1 : 1 + S] & ~prev
    return info, Q, born, rows


def learned_pcrlb(
    model: PathErrorModel,
    geometry,
    setup: DesignSetup,
    *,
    sigma_p0: float = 1.0,
    sigma_birth: float = SIGMA_BIRTH,
    **kw,
) -> tuple[np.ndarray, np.ndarray]:
    """Posterior CRLB (T,) [m] of the UE's 2-D position over the drive for a tracker that learns
    its VUEs (module docstring; ``vues="known"`` in ``kw`` for one that knows the surfaces), and
    the RMS (T,) [m] of the position bias of the filter that attains it (gains
    ``K_k = P_k H_k^T W_k``) under the model's deterministic bias and its calibration error
    over the draw: ``e_k = (I - K_k H_k) e_k-1 + K_k b_k``, the bias ``b_k`` repeating from one
    epoch to the next (one array's calibration draw), a VUE's share reset at its birth. ``kw``
    to :func:`learned_model`."""
    sigma_p0 = positive("sigma_p0", sigma_p0)
    sigma_birth = positive("sigma_birth", sigma_birth)
    info, Q, born, rows = learned_model(model, geometry, setup, **kw)
    T, n = info.shape[:2]
    P4 = model.exists.shape[1] * 4
    b_all = np.asarray(model.bias).reshape(T, P4)
    ks = [
        (np.asarray(K).reshape(T, P4, -1), sig)
        for K, sig in ((model.k_phase, model.phase_sigma_rad), (model.k_gain, model.gain_sigma_db))
        if K is not None and sig > 0
    ]
    e = np.zeros(n)
    E = [np.zeros((n, K.shape[-1])) for K, _ in ks]
    P = np.diag([sigma_p0**2] * 2 + [sigma_birth**2] * (n - 2))
    out, bias = np.empty(T), np.empty(T)
    for k in range(T):
        Pp = P + Q[k] if k else P
        for s in np.flatnonzero(born[k]):
            v = slice(2 + 2 * s, 4 + 2 * s)
            Pp[v, :] = 0.0
            Pp[:, v] = 0.0
            Pp[v, v] = sigma_birth**2 * np.eye(2)
            e[v] = 0.0
            for Ei in E:
                Ei[v] = 0.0
        J = np.linalg.inv(0.5 * (Pp + Pp.T)) + info[k]
        P = np.linalg.inv(0.5 * (J + J.T))
        P = 0.5 * (P + P.T)
        out[k] = np.sqrt(P[0, 0] + P[1, 1])
        if rows[k] is not None:
            r, H, W = rows[k]
            K = P @ H.T @ W
            A = np.eye(n) - K @ H
            e = A @ e + K @ b_all[k, r]
            E = [A @ Ei + K @ Kc[k, r] for Ei, (Kc, _) in zip(E, ks, strict=True)]
        v = float(e[:2] @ e[:2])
        for Ei, (_, sig) in zip(E, ks, strict=True):
            v += sig**2 * float(np.sum(Ei[:2] ** 2))
        bias[k] = np.sqrt(v)
    return out, bias


def batch_information(info: np.ndarray, Q: np.ndarray, P0: np.ndarray) -> np.ndarray:
    """The information matrix (T n, T n) of all epochs' states at once for ``x_0 ~ N(., P0)``,
    ``x_k = x_{k-1} + w_k`` with ``w_k ~ N(0, Q_k)`` and the per-epoch measurement information
    ``info`` (T, n, n) (no births in between): its inverse's last block is what the recursion of
    :func:`learned_pcrlb` gives at the last epoch."""
    info = finite_array("info", info, ndim=3)
    T, n = info.shape[:2]
    if info.shape[2] != n:
        raise ValueError(f"info: expected (T, n, n), got shape {info.shape}")
    Q = finite_array("Q", Q, shape=info.shape)
    P0 = finite_array("P0", P0, shape=(n, n))
    check_elements("info", (T * n) ** 2)
    J = np.zeros((T * n, T * n))
    J[:n, :n] += np.linalg.inv(P0)
    for k in range(T):
        b = slice(k * n, (k + 1) * n)
        J[b, b] += info[k]
        if k:
            a = slice((k - 1) * n, k * n)
            Qi = np.linalg.inv(Q[k])
            J[a, a] += Qi
            J[b, b] += Qi
            J[a, b] -= Qi
            J[b, a] -= Qi
    return J
